// The recording format (record/): what is written is read back whole; a file being written is
// readable; a file not closed is indexed by scanning; a truncated, a corrupted and a foreign-
// version file are each one error naming the byte.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "process_helpers.hpp"
#include "vrflow/message/builder.hpp"
#include "vrflow/message/digest.hpp"
#include "vrflow/message/reader.hpp"
#include "vrflow/record/connections_param.hpp"
#include "vrflow/record/reader.hpp"
#include "vrflow/record/summary.hpp"
#include "vrflow/record/writer.hpp"

namespace {

using vrflow::record::RecordedConnection;
using vrflow::record::RecordingReader;
using vrflow::record::RecordingWriter;
using vrflow::testing::TempDir;

// A message from `source` at `iteration` carrying one raw resource of `size` counting bytes.
std::vector<std::byte> message(const std::string& source, std::uint64_t iteration,
                               std::size_t size = 100) {
  vrflow::msg::VectorSink sink;
  vrflow::msg::MessageBuilder builder(sink);
  builder.setSource(source);
  builder.setIteration(iteration);
  builder.setSimTime(0.01 * static_cast<double>(iteration));
  builder.setTimeStep(0.01);
  builder.addInt64Stamp("frame", static_cast<std::int64_t>(iteration));
  std::vector<std::byte> payload(size);
  for (std::size_t i = 0; i < size; ++i)
    payload[i] = std::byte(static_cast<unsigned char>(i + iteration));
  builder.addRawResource(7, true, payload);
  const std::size_t used = builder.finish();
  return {builder.bytes().begin(), builder.bytes().begin() + static_cast<long>(used)};
}

const std::vector<RecordedConnection> kConnections = {{"chain", "objects", "objects"},
                                                      {"springs", "forces", "events"}};

std::vector<std::byte> readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::vector<char> text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<std::byte> bytes(text.size());
  std::memcpy(bytes.data(), text.data(), text.size());
  return bytes;
}

void writeBytes(const std::string& path, const std::vector<std::byte>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
}

// Writes 3 chunks of 10 records (5 per connection) and closes the file.
void writeSample(const std::string& path) {
  auto writer = RecordingWriter::create(path, kConnections, {.level = 3, .chunkBytes = 1 << 30});
  ASSERT_TRUE(writer) << writer.error().message;
  for (std::uint64_t it = 0; it < 15; ++it) {
    ASSERT_TRUE((*writer)->add(0, it, 1000 + 10 * it, message("chain", it)));
    ASSERT_TRUE((*writer)->add(1, it, 1005 + 10 * it, message("springs", it, 40)));
    if (it % 5 == 4) {
      ASSERT_TRUE((*writer)->flush());
    }
  }
  ASSERT_TRUE((*writer)->close());
}

// Every record of every chunk.
std::vector<std::pair<vrflow::record::RecordView, std::vector<std::byte>>> allRecords(
    RecordingReader& reader) {
  std::vector<std::pair<vrflow::record::RecordView, std::vector<std::byte>>> all;
  for (std::size_t c = 0; c < reader.chunks().size(); ++c) {
    auto records = reader.readChunk(c);
    EXPECT_TRUE(records) << records.error().message;
    if (!records) return all;
    for (const auto& r : *records) all.push_back({r, {r.message.begin(), r.message.end()}});
  }
  return all;
}

TEST(RecordingFormat, WhatIsWrittenIsReadBackByteForByteWithStampsAndArrivals) {
  TempDir dir;
  const std::string path = dir.file("sample.vrrec");
  writeSample(path);
  auto reader = RecordingReader::open(path);
  ASSERT_TRUE(reader) << reader.error().message;
  EXPECT_TRUE((*reader)->closed());
  EXPECT_EQ((*reader)->connections(), kConnections);
  EXPECT_EQ((*reader)->chunks().size(), 3u);
  const auto records = allRecords(**reader);
  ASSERT_EQ(records.size(), 30u);
  for (std::size_t i = 0; i < records.size(); ++i) {
    const std::uint64_t it = i / 2;
    const bool chain = i % 2 == 0;
    EXPECT_EQ(records[i].first.connection, chain ? 0u : 1u);
    EXPECT_EQ(records[i].first.iteration, it);
    EXPECT_EQ(records[i].first.arrivalNs, (chain ? 1000 : 1005) + 10 * it);
    EXPECT_EQ(records[i].second, message(chain ? "chain" : "springs", it, chain ? 100 : 40));
  }
  auto summary = vrflow::record::summarize(**reader);
  ASSERT_TRUE(summary);
  EXPECT_EQ(summary->messages, 30u);
  EXPECT_EQ(summary->connections[0].messages, 15u);
  EXPECT_EQ(summary->connections[1].lastIteration, 14u);
  // 15 messages 10 ns apart: 14 intervals over 140 ns.
  EXPECT_DOUBLE_EQ(summary->connections[0].rateHz(), 1e8);
  EXPECT_DOUBLE_EQ(summary->durationSeconds(), 145e-9);
}

TEST(RecordingFormat, AFileBeingWrittenIsReadableChunkByChunk) {
  TempDir dir;
  const std::string path = dir.file("growing.vrrec");
  auto writer = RecordingWriter::create(path, kConnections);
  ASSERT_TRUE(writer);
  ASSERT_TRUE((*writer)->add(0, 0, 10, message("chain", 0)));
  ASSERT_TRUE((*writer)->flush());
  ASSERT_TRUE((*writer)->add(0, 1, 20, message("chain", 1)));  // still in memory
  auto reader = RecordingReader::open(path, /*growing=*/true);
  ASSERT_TRUE(reader) << reader.error().message;
  EXPECT_FALSE((*reader)->closed());
  ASSERT_EQ((*reader)->chunks().size(), 1u);
  EXPECT_EQ(allRecords(**reader).size(), 1u);
  // Half a chunk on disk (as a reader may see mid-write): left for later, not an error.
  ASSERT_TRUE((*writer)->flush());
  const auto whole = readBytes(path);
  const auto& chunk = (*reader)->chunks()[0];
  const std::size_t secondAt =
      chunk.offset + vrflow::record::kChunkHeaderBytes + chunk.compressedBytes;
  const std::string copy = dir.file("copy.vrrec");
  writeBytes(copy, {whole.begin(), whole.begin() + static_cast<long>(secondAt + 20)});
  auto partial = RecordingReader::open(copy, /*growing=*/true);
  ASSERT_TRUE(partial) << partial.error().message;
  EXPECT_EQ((*partial)->chunks().size(), 1u);
  ASSERT_TRUE((*reader)->refresh());
  EXPECT_EQ((*reader)->chunks().size(), 2u);
  ASSERT_TRUE((*writer)->close());
  ASSERT_TRUE((*reader)->refresh());
  EXPECT_TRUE((*reader)->closed());
  const auto records = allRecords(**reader);
  ASSERT_EQ(records.size(), 2u);
  EXPECT_EQ(records[1].first.iteration, 1u);
}

TEST(RecordingFormat, AFileThatWasNotClosedIsIndexedByScanning) {
  TempDir dir;
  const std::string path = dir.file("sample.vrrec");
  writeSample(path);
  // Cut the index and trailer off, as a recorder killed after its last chunk leaves it.
  auto reader = RecordingReader::open(path);
  ASSERT_TRUE(reader);
  const auto& last = (*reader)->chunks().back();
  auto bytes = readBytes(path);
  bytes.resize(last.offset + vrflow::record::kChunkHeaderBytes + last.compressedBytes);
  writeBytes(path, bytes);
  auto scanned = RecordingReader::open(path);
  ASSERT_TRUE(scanned) << scanned.error().message;
  EXPECT_FALSE((*scanned)->closed());
  EXPECT_EQ((*scanned)->chunks().size(), 3u);
  EXPECT_EQ(allRecords(**scanned).size(), 30u);
}

TEST(RecordingFormat, ATruncatedFileIsOneErrorNamingTheByteWhereItEnds) {
  TempDir dir;
  const std::string path = dir.file("sample.vrrec");
  writeSample(path);
  auto reader = RecordingReader::open(path);
  ASSERT_TRUE(reader);
  const auto second = (*reader)->chunks()[1];
  auto bytes = readBytes(path);
  bytes.resize(second.offset + 100);
  writeBytes(path, bytes);
  auto truncated = RecordingReader::open(path);
  ASSERT_FALSE(truncated);
  EXPECT_EQ(truncated.error().message,
            path + ": byte " + std::to_string(second.offset) + ": the chunk claims " +
                std::to_string(vrflow::record::kChunkHeaderBytes + second.compressedBytes) +
                " bytes, the file holds 100 from here (truncated)");
  // A file cut inside its header.
  bytes.resize(30);
  writeBytes(path, bytes);
  auto cut = RecordingReader::open(path);
  ASSERT_FALSE(cut);
  EXPECT_NE(cut.error().message.find(path + ": byte "), std::string::npos) << cut.error().message;
  EXPECT_NE(cut.error().message.find("truncated"), std::string::npos) << cut.error().message;
}

TEST(RecordingFormat, ACorruptedChunkIsOneErrorNamingItsByte) {
  TempDir dir;
  const std::string path = dir.file("sample.vrrec");
  writeSample(path);
  auto reader = RecordingReader::open(path);
  ASSERT_TRUE(reader);
  const auto chunk = (*reader)->chunks()[1];
  auto bytes = readBytes(path);
  // A flipped byte in the middle of the compressed frame: zstd's checksum (or its decoder)
  // refuses it.
  bytes[chunk.offset + vrflow::record::kChunkHeaderBytes + chunk.compressedBytes / 2] ^=
      std::byte{0x5a};
  writeBytes(path, bytes);
  auto corrupted = RecordingReader::open(path);
  ASSERT_TRUE(corrupted) << "the index is intact: " << corrupted.error().message;
  EXPECT_TRUE((*corrupted)->readChunk(0));
  auto records = (*corrupted)->readChunk(1);
  ASSERT_FALSE(records);
  EXPECT_EQ(
      records.error().message.rfind(
          path + ": byte " + std::to_string(chunk.offset + vrflow::record::kChunkHeaderBytes) +
              ": the chunk does not decompress (corrupted)",
          0),
      0u)
      << records.error().message;
  EXPECT_FALSE(vrflow::record::summarize(**corrupted));
  // A chunk header whose length was overwritten.
  writeSample(path);
  bytes = readBytes(path);
  vrflow::record::putU64(bytes.data() + chunk.offset + 8, std::uint64_t{1} << 40);
  writeBytes(path, bytes);
  auto reopened = RecordingReader::open(path);
  ASSERT_TRUE(reopened);  // the index is read, not the chunk
  auto bad = (*reopened)->readChunk(1);
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().message, path + ": byte " + std::to_string(chunk.offset) +
                                     ": the chunk header does not match the index (corrupted)");
}

// A chunk whose header, and whose zstd frame header, claim 2 GiB while the frame decodes to 32
// bytes, and a chunk claiming 4 billion records in 32 bytes (what the fuzzer found): each is one
// error naming its byte, and the reader's memory follows what the frame decodes to, not the
// claims (before, the first allocated and zeroed the 2 GiB, the second threw bad_alloc).
TEST(RecordingFormat, SizesAChunkOnlyClaimsCostNoMemoryAndAreOneError) {
  TempDir dir;
  const std::string path = dir.file("claims.vrrec");
  writeSample(path);
  std::uint64_t chunkAt = 0;
  {
    auto reader = RecordingReader::open(path);
    ASSERT_TRUE(reader);
    chunkAt = (*reader)->chunks()[0].offset;
  }
  const auto header = readBytes(path);
  // A chunk after the sample's connection table, with no index (the reader scans for it).
  const auto writeChunk = [&](std::uint32_t records, std::uint64_t claimedRaw,
                              std::uint8_t rleBytes) {
    std::vector<std::byte> frame(4 + 1 + 8 + 3 + 1);
    vrflow::record::putU32(frame.data(), 0xFD2FB528);  // zstd frame magic
    frame[4] = std::byte{0xE0};                        // single segment, 8-byte content size
    vrflow::record::putU64(frame.data() + 5, claimedRaw);
    const std::uint32_t block = (std::uint32_t{rleBytes} << 3) | (1u << 1) | 1u;  // last, RLE
    frame[13] = std::byte(block & 0xff);
    frame[14] = std::byte((block >> 8) & 0xff);
    frame[15] = std::byte((block >> 16) & 0xff);
    std::vector<std::byte> bytes(header.begin(), header.begin() + static_cast<long>(chunkAt));
    std::vector<std::byte> chunk(vrflow::record::kChunkHeaderBytes);
    vrflow::record::putU32(chunk.data(), vrflow::record::kChunkMagic);
    vrflow::record::putU32(chunk.data() + 4, records);
    vrflow::record::putU64(chunk.data() + 8, frame.size());
    vrflow::record::putU64(chunk.data() + 16, claimedRaw);
    bytes.insert(bytes.end(), chunk.begin(), chunk.end());
    bytes.insert(bytes.end(), frame.begin(), frame.end());
    writeBytes(path, bytes);
  };
  rusage before{};
  getrusage(RUSAGE_SELF, &before);
  writeChunk(1, std::uint64_t{2} << 30, 32);
  auto reader = RecordingReader::open(path);
  ASSERT_TRUE(reader) << reader.error().message;
  ASSERT_EQ((*reader)->chunks().size(), 1u);
  auto records = (*reader)->readChunk(0);
  ASSERT_FALSE(records);
  EXPECT_EQ(records.error().message,
            path + ": byte " + std::to_string(chunkAt + vrflow::record::kChunkHeaderBytes) +
                ": the zstd frame's blocks decode to at most 32 bytes, not the chunk's 2147483648 "
                "(corrupted)");
  rusage after{};
  getrusage(RUSAGE_SELF, &after);
  EXPECT_LT(after.ru_maxrss - before.ru_maxrss, 512 << 10) << "KiB more at its peak";

  writeChunk(0xFFFFFFFF, 32, 32);
  reader = RecordingReader::open(path);
  ASSERT_TRUE(reader) << reader.error().message;
  records = (*reader)->readChunk(0);
  ASSERT_FALSE(records);
  EXPECT_EQ(records.error().message, path + ": byte " + std::to_string(chunkAt) +
                                         ": the chunk claims 4294967295 records in 32 bytes "
                                         "(corrupted)");
}

// Chunks stored uncompressed (what the writer does while its compression thread is busy):
// zstd frames of raw blocks (128 KiB each, so several per chunk here) that the same reader
// decodes and checks; a flipped byte in a stored block fails the frame's checksum.
TEST(RecordingFormat, StoredChunksAreReadBackByteForByteAndChecked) {
  TempDir dir;
  const std::string path = dir.file("stored.vrrec");
  auto writer =
      RecordingWriter::create(path, kConnections, {.chunkBytes = 300 << 10, .compress = false});
  ASSERT_TRUE(writer);
  for (std::uint64_t it = 0; it < 400; ++it)
    ASSERT_TRUE((*writer)->add(0, it, 1000 + it, message("chain", it, 2000)));
  ASSERT_TRUE((*writer)->close());
  EXPECT_EQ((*writer)->storedChunks(), (*writer)->chunksWritten());
  auto reader = RecordingReader::open(path);
  ASSERT_TRUE(reader) << reader.error().message;
  ASSERT_GE((*reader)->chunks().size(), 2u);
  for (const auto& chunk : (*reader)->chunks()) EXPECT_GT(chunk.compressedBytes, chunk.rawBytes);
  const auto records = allRecords(**reader);
  ASSERT_EQ(records.size(), 400u);
  for (std::uint64_t it = 0; it < 400; ++it) {
    EXPECT_EQ(records[it].first.arrivalNs, 1000 + it);
    EXPECT_EQ(records[it].second, message("chain", it, 2000)) << it;
  }
  const auto chunk = (*reader)->chunks()[1];
  auto bytes = readBytes(path);
  bytes[chunk.offset + vrflow::record::kChunkHeaderBytes + chunk.compressedBytes / 2] ^=
      std::byte{0x01};
  writeBytes(path, bytes);
  auto corrupted = RecordingReader::open(path);
  ASSERT_TRUE(corrupted);
  auto bad = (*corrupted)->readChunk(1);
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("(corrupted)"), std::string::npos) << bad.error().message;
}

// With the compression thread on, a chunk is compressed by it or stored when it is busy: any
// mix reads back the same, in order.
TEST(RecordingFormat, CompressedAndStoredChunksMixedReadBackInOrder) {
  TempDir dir;
  const std::string path = dir.file("mixed.vrrec");
  auto writer = RecordingWriter::create(path, kConnections, {.level = 19, .chunkBytes = 64 << 10});
  ASSERT_TRUE(writer);
  for (std::uint64_t it = 0; it < 2000; ++it)
    ASSERT_TRUE((*writer)->add(it % 2 == 0 ? 0 : 1, it, it, message("chain", it, 1000)));
  ASSERT_TRUE((*writer)->close());
  auto reader = RecordingReader::open(path);
  ASSERT_TRUE(reader) << reader.error().message;
  EXPECT_EQ((*reader)->chunks().size(), (*writer)->chunksWritten());
  const auto records = allRecords(**reader);
  ASSERT_EQ(records.size(), 2000u);
  for (std::uint64_t it = 0; it < 2000; ++it) {
    EXPECT_EQ(records[it].first.iteration, it);
    EXPECT_EQ(records[it].first.connection, it % 2);
    EXPECT_EQ(records[it].second, message("chain", it, 1000)) << it;
  }
}

// `vrflow inspect` on a recording that a writer has open reads what is there: its whole
// chunks, the chunk in progress at its end left out. The same bytes with no writer behind them
// are a truncated file.
TEST(RecordingFormat, InspectReadsAFileBeingWrittenUpToItsLastWholeChunk) {
  TempDir dir;
  const std::string path = dir.file("live.vrrec");
  auto writer = RecordingWriter::create(path, kConnections);
  ASSERT_TRUE(writer);
  for (std::uint64_t it = 0; it < 6; ++it) {
    ASSERT_TRUE((*writer)->add(0, it, 1000 + it, message("chain", it)));
    if (it % 3 == 2) {
      ASSERT_TRUE((*writer)->flush());
    }
  }
  EXPECT_TRUE(RecordingReader::beingWritten(path));
  // The first bytes of a third chunk, as a reader may find them while the writer writes it
  // (a copy of the first chunk's first 20 bytes).
  const auto whole = readBytes(path);
  const auto first = (*RecordingReader::open(path))->chunks().at(0).offset;
  auto growing = whole;
  growing.insert(growing.end(), whole.begin() + static_cast<long>(first),
                 whole.begin() + static_cast<long>(first) + 20);
  {
    std::ofstream out(path, std::ios::binary | std::ios::app);  // the writer's lock stays
    out.write(reinterpret_cast<const char*>(growing.data() + whole.size()), 20);
  }
  const auto inspect = [&](const std::string& file) {
    return vrflow::testing::runCommand({vrflow::testing::binDir() + "/vrflow", "inspect", file},
                                       30);
  };
  const auto live = inspect(path);
  ASSERT_EQ(live.exitCode, 0) << live.err;
  EXPECT_NE(live.out.find("none yet: the file is being written"), std::string::npos) << live.out;
  EXPECT_NE(live.out.find("Messages:       6\n"), std::string::npos) << live.out;
  EXPECT_NE(live.out.find("Chunks:         2\n"), std::string::npos) << live.out;
  const std::string copy = dir.file("copy.vrrec");  // no writer has it open
  writeBytes(copy, growing);
  EXPECT_FALSE(RecordingReader::beingWritten(copy));
  const auto truncated = inspect(copy);
  EXPECT_EQ(truncated.exitCode, 2);
  EXPECT_NE(truncated.err.find("(truncated)"), std::string::npos) << truncated.err;
}

// Found by fuzz_recording_reader: a connection name that is not UTF-8 made `inspect --json`
// throw out of nlohmann::json (the program aborted); its bad bytes are now replaced.
TEST(RecordingFormat, InspectJsonOfANameThatIsNotUtf8ReplacesItsBadBytes) {
  TempDir dir;
  const std::string path = dir.file("latin1.vrrec");
  auto writer = RecordingWriter::create(path, {{"gr\xfc\xdf", "out", "events"}});
  ASSERT_TRUE(writer);
  ASSERT_TRUE((*writer)->add(0, 0, 10, message("x", 0)));
  ASSERT_TRUE((*writer)->close());
  auto reader = RecordingReader::open(path);
  ASSERT_TRUE(reader);
  auto summary = vrflow::record::summarize(**reader);
  ASSERT_TRUE(summary);
  std::string text;
  ASSERT_NO_THROW(text = vrflow::record::summaryJson(*summary));
  const auto json = nlohmann::json::parse(text);
  EXPECT_EQ(json["connections"][0]["module"], "gr\xef\xbf\xbd\xef\xbf\xbd");
}

TEST(RecordingFormat, AnotherFormatVersionIsRefusedNamingBothVersions) {
  TempDir dir;
  const std::string path = dir.file("sample.vrrec");
  writeSample(path);
  auto bytes = readBytes(path);
  for (const std::uint32_t version : {0u, 2u}) {
    vrflow::record::putU32(bytes.data() + 8, version);
    writeBytes(path, bytes);
    auto reader = RecordingReader::open(path);
    ASSERT_FALSE(reader);
    EXPECT_EQ(reader.error().message.rfind(path + ": byte 8: recording format version " +
                                               std::to_string(version) +
                                               "; this vrflow reads version 1 only",
                                           0),
              0u)
        << reader.error().message;
  }
}

TEST(RecordingFormat, NotARecordingIsRefused) {
  TempDir dir;
  const std::string path = dir.write("pipeline.xml", "<application name=\"x\" version=\"1\"/>\n");
  auto reader = RecordingReader::open(path);
  ASSERT_FALSE(reader);
  EXPECT_EQ(reader.error().message,
            path + ": byte 0: not a vrflow recording (no 'VRFLOWRC' magic)");
  auto missing = RecordingReader::open(dir.file("none.vrrec"));
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().message,
            "cannot read '" + dir.file("none.vrrec") + "': No such file or directory");
}

TEST(RecordingConnectionsParam, RoundTripsAndRefusesMalformedEntries) {
  const auto text = vrflow::record::connectionsParam(kConnections);
  EXPECT_EQ(text, "chain.objects:objects springs.forces:events");
  auto parsed = vrflow::record::parseConnectionsParam(text);
  ASSERT_TRUE(parsed);
  EXPECT_EQ(*parsed, kConnections);
  EXPECT_FALSE(vrflow::record::parseConnectionsParam(""));
  EXPECT_FALSE(vrflow::record::parseConnectionsParam("chain:objects"));
  EXPECT_FALSE(vrflow::record::parseConnectionsParam("chain.objects"));
  EXPECT_FALSE(
      vrflow::record::parseConnectionsParam("chain.objects:objects chain.objects:objects"));
}

}  // namespace
