// The fuzz corpus seeds in tests/fuzz/corpus/message/ are built here. The test fails when the
// builder's output and a seed differ (the layout changed); regenerate them with
//   VRFLOW_REGENERATE_CORPUS=1 ./vrflow_message_tests --gtest_filter='MessageCorpus.*'
// VRFLOW_MESSAGE_CORPUS_DIR is set by tests/message/CMakeLists.txt.

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include "sample_messages.hpp"
#include "vrflow/message/empty_message.hpp"

namespace vrflow::msg {
namespace {

using testing::finished;
using testing::sampleMessage;
using testing::sampleStamps;

std::vector<std::pair<std::string, std::vector<std::byte>>> seeds() {
  std::vector<std::pair<std::string, std::vector<std::byte>>> all;
  all.emplace_back("every_chunk_kind.bin", sampleMessage());
  all.emplace_back("empty.bin", makeEmptyMessage());
  all.emplace_back("stamps_only.bin", makeEmptyMessage(sampleStamps(), EmptyKind::StampsOnly));

  VectorSink sink;
  MessageBuilder builder(sink);
  builder.setSource("point-animator");
  builder.setIteration(3);
  builder.setSimTime(0.03);
  builder.setTimeStep(0.01);
  builder.addObject(makeId(0x7F000001u, 1), pointType(), ObjectOp::Add)
      .set(PointParam::kPosition, Vec3{0, 1, 0})
      .set(PointParam::kVelocity, Vec3{0, 0, 0})
      .set(PointParam::kMass, 1.0);
  builder.addForce(makeId(0x7F000001u, 1), ForceEvent{{0, -9.81, 0}, {}, {0, 1, 0}, 0.01});
  all.emplace_back("point_and_force.bin", finished(builder));

  const auto sample = sampleMessage();
  const auto sampleView = MessageView::parse(sample);
  builder.reset();
  builder.setSource("merge");
  builder.appendChunks(*sampleView);
  builder.appendChunks(*sampleView);
  all.emplace_back("merged.bin", finished(builder));
  return all;
}

#ifndef VRFLOW_MESSAGE_CORPUS_DIR
#define VRFLOW_MESSAGE_CORPUS_DIR ""
#endif

std::filesystem::path corpusDir() {
  return VRFLOW_MESSAGE_CORPUS_DIR;
}

TEST(MessageCorpus, SeedsAreValidMessages) {
  for (const auto& [name, bytes] : seeds()) {
    const auto view = MessageView::parse(bytes);
    EXPECT_TRUE(view.ok()) << name << ": " << view.error().message;
  }
}

TEST(MessageCorpus, SeedFilesMatchTheBuilder) {
  const auto dir = corpusDir();
  if (dir.empty()) GTEST_SKIP() << "built without VRFLOW_MESSAGE_CORPUS_DIR";
  const bool regenerate = std::getenv("VRFLOW_REGENERATE_CORPUS") != nullptr;
  for (const auto& [name, bytes] : seeds()) {
    const auto path = dir / name;
    if (regenerate) {
      std::filesystem::create_directories(dir);
      std::ofstream out(path, std::ios::binary);
      out.write(reinterpret_cast<const char*>(bytes.data()),
                static_cast<std::streamsize>(bytes.size()));
      ASSERT_TRUE(out.good()) << path;
      continue;
    }
    std::ifstream in(path, std::ios::binary);
    ASSERT_TRUE(in.good()) << path << " is missing; regenerate the corpus (see corpus_test.cpp)";
    std::vector<char> text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::vector<std::byte> stored(text.size());
    std::memcpy(stored.data(), text.data(), text.size());
    EXPECT_EQ(stored, bytes) << path << " differs from the builder's output; regenerate it";
  }
}

}  // namespace
}  // namespace vrflow::msg
