// libFuzzer target: the recording reader (record/src/reader.cpp) and `vrflow inspect`'s summary
// on arbitrary file contents, as a damaged or hostile .vrrec file would hold them. Byte 0 picks
// plain or growing reading; the rest is the file. Beyond "no crash, no sanitizer report", it
// checks what the reader promises: every record it hands out names a connection of the header
// and lies inside its chunk, and a chunk it indexed is read back as records or as one error.
#include <sys/mman.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <string>

#include "vrflow/record/reader.hpp"
#include "vrflow/record/summary.hpp"

namespace {

void check(bool condition) {
  if (!condition) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  // The reader takes a path: the bytes go into a memory file, read through /proc.
  const int fd = memfd_create("vrflow-fuzz-recording", MFD_CLOEXEC);
  if (fd < 0) return 0;
  std::size_t written = 0;
  while (written < size - 1) {
    const ssize_t n = write(fd, data + 1 + written, size - 1 - written);
    if (n <= 0) break;
    written += static_cast<std::size_t>(n);
  }
  const std::string path = "/proc/self/fd/" + std::to_string(fd);
  const bool growing = (data[0] & 1) != 0;
  auto reader = vrflow::record::RecordingReader::open(path, growing);
  if (reader) {
    auto& r = **reader;
    check(r.usedBytes() <= written);
    for (std::size_t c = 0; c < r.chunks().size(); ++c) {
      const auto& chunk = r.chunks()[c];
      check(chunk.offset < written);
      auto records = r.readChunk(c);
      if (!records) continue;
      check(records->size() == chunk.records);
      for (const auto& record : *records) {
        check(record.connection < r.connections().size());
        check(record.message.size() <= chunk.rawBytes);
      }
    }
    if ((data[0] & 2) != 0) {
      if (auto summary = vrflow::record::summarize(r)) {
        (void)vrflow::record::formatSummary(*summary);
        (void)vrflow::record::summaryJson(*summary);
      }
    }
    if (growing) (void)r.refresh();
  }
  close(fd);
  return 0;
}
