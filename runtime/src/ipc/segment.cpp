#include "vrflow/ipc/segment.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <bit>
#include <cerrno>
#include <cstring>
#include <new>
#include <string>
#include <utility>

#if defined(__SANITIZE_THREAD__)
#include <sanitizer/tsan_interface.h>
#endif

namespace vrflow::ipc {
namespace {

// Blocks go from process to process through the rings, and their last reference may be dropped
// in another process than the one that allocates the block again. The atomics that order this
// live in the shared mapping, but ThreadSanitizer sees only its own process's, so each hand-over
// is a release on the block's reference count and each reuse an acquire of it.
void tsanRelease([[maybe_unused]] void* address) {
#if defined(__SANITIZE_THREAD__)
  __tsan_release(address);
#endif
}
void tsanAcquire([[maybe_unused]] void* address) {
#if defined(__SANITIZE_THREAD__)
  __tsan_acquire(address);
#endif
}

// A free-list head packs a 32-bit tag (bumped on every change, against ABA) with the block
// offset divided by 64 (blocks are 64-byte aligned), so a segment may be up to 256 GiB.
constexpr uint64_t pack(uint64_t tag, uint64_t offset) {
  return (tag << 32) | (offset >> 6);
}
constexpr uint64_t offsetOf(uint64_t packed) {
  return (packed & 0xffffffffULL) << 6;
}
constexpr uint64_t tagOf(uint64_t packed) {
  return packed >> 32;
}

std::string errnoText(const char* what) {
  return std::string(what) + ": " + std::strerror(errno);
}

int classFor(std::size_t payloadBytes) {
  const std::size_t total = payloadBytes + sizeof(BlockHeader);
  const int k = static_cast<int>(std::bit_width(total - 1));
  return k < kMinBlockClass ? kMinBlockClass : k;
}

}  // namespace

Segment::Segment(int fd, std::byte* base, std::size_t size)
    : fd_(fd), base_(base), size_(size), header_(reinterpret_cast<SegmentHeader*>(base)) {}

Segment::Segment(Segment&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)),
      base_(std::exchange(other.base_, nullptr)),
      size_(std::exchange(other.size_, 0)),
      header_(std::exchange(other.header_, nullptr)) {}

Segment& Segment::operator=(Segment&& other) noexcept {
  if (this != &other) {
    this->~Segment();
    new (this) Segment(std::move(other));
  }
  return *this;
}

Segment::~Segment() {
  if (base_ != nullptr) munmap(base_, size_);
  if (fd_ >= 0) close(fd_);
}

Result<Segment> Segment::create(std::size_t bytes) {
  if (bytes < 1 << 20) return makeError("shared-memory segment must be at least 1 MiB");
  const int fd = memfd_create("vrflow-segment", MFD_CLOEXEC);
  if (fd < 0) return makeError(errnoText("cannot create the shared-memory segment"));
  if (ftruncate(fd, static_cast<off_t>(bytes)) != 0) {
    close(fd);
    return makeError(errnoText("cannot size the shared-memory segment"));
  }
  void* base = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  if (base == MAP_FAILED) {
    close(fd);
    return makeError(errnoText("cannot map the shared-memory segment"));
  }
  Segment segment(fd, static_cast<std::byte*>(base), bytes);
  auto* header = new (base) SegmentHeader();
  header->size = bytes;
  header->bump.store((sizeof(SegmentHeader) + 63) & ~uint64_t{63});
  for (auto& head : header->freeHeads) head.store(0);
  return segment;
}

Result<Segment> Segment::attach(int fd) {
  struct stat st {};
  if (fstat(fd, &st) != 0) return makeError(errnoText("cannot inspect the shared-memory segment"));
  const auto bytes = static_cast<std::size_t>(st.st_size);
  if (bytes < sizeof(SegmentHeader)) return makeError("shared-memory segment is too small");
  void* base = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  if (base == MAP_FAILED) return makeError(errnoText("cannot map the shared-memory segment"));
  Segment segment(fd, static_cast<std::byte*>(base), bytes);
  if (segment.header().magic != kSegmentMagic || segment.header().version != kSegmentVersion ||
      segment.header().size != bytes) {
    segment.fd_ = -1;  // not ours to close
    return makeError("descriptor is not a vrflow segment of this version");
  }
  return segment;
}

uint64_t Segment::reserve(std::size_t bytes, std::size_t alignment) {
  auto& bump = header_->bump;
  uint64_t current = bump.load(std::memory_order_relaxed);
  for (;;) {
    const uint64_t start = (current + alignment - 1) & ~(uint64_t{alignment} - 1);
    if (start + bytes > size_) return 0;
    if (bump.compare_exchange_weak(current, start + bytes, std::memory_order_acq_rel)) return start;
  }
}

uint64_t Segment::allocate(std::size_t payloadBytes) {
  const int k = classFor(payloadBytes);
  if (k > kMaxBlockClass) return 0;
  auto& head = header_->freeHeads[k - kMinBlockClass];
  uint64_t packed = head.load(std::memory_order_acquire);
  uint64_t handle = 0;
  while (offsetOf(packed) != 0) {
    const uint64_t candidate = offsetOf(packed);
    // `next` may be stale if another process popped the block meanwhile; the tag makes that
    // CAS fail, and the read itself is always inside the mapping.
    const uint64_t next = block(candidate).next.load(std::memory_order_relaxed);
    if (head.compare_exchange_weak(packed, pack(tagOf(packed) + 1, next),
                                   std::memory_order_acq_rel)) {
      handle = candidate;
      break;
    }
  }
  BlockHeader* header = nullptr;
  if (handle == 0) {
    handle = reserve(std::size_t{1} << k, 64);
    if (handle == 0) {
      header_->failedAllocations.fetch_add(1, std::memory_order_relaxed);
      return 0;
    }
    header = new (base_ + handle) BlockHeader();  // never seen by anyone before
  } else {
    // A popper that lost the race may still read `next` of this block: only atomic stores.
    header = &block(handle);
    tsanAcquire(&header->refs);
    header->next.store(0, std::memory_order_relaxed);
    header->used = 0;
  }
  header->blockClass = static_cast<uint32_t>(k);
  header->refs.store(1, std::memory_order_relaxed);
  const uint64_t inUse =
      header_->inUseBytes.fetch_add(uint64_t{1} << k, std::memory_order_relaxed) +
      (uint64_t{1} << k);
  uint64_t peak = header_->peakInUseBytes.load(std::memory_order_relaxed);
  while (inUse > peak &&
         !header_->peakInUseBytes.compare_exchange_weak(peak, inUse, std::memory_order_relaxed)) {
  }
  return handle;
}

void Segment::retain(uint64_t handle) const {
  block(handle).refs.fetch_add(1, std::memory_order_relaxed);
}

void Segment::handOver(uint64_t handle) const {
  tsanRelease(&block(handle).refs);
}

void Segment::release(uint64_t handle) {
  BlockHeader& header = block(handle);
  if (header.refs.fetch_sub(1, std::memory_order_acq_rel) != 1) return;
  const int k = static_cast<int>(header.blockClass);
  header_->inUseBytes.fetch_sub(uint64_t{1} << k, std::memory_order_relaxed);
  auto& head = header_->freeHeads[k - kMinBlockClass];
  uint64_t packed = head.load(std::memory_order_acquire);
  do {
    header.next.store(offsetOf(packed), std::memory_order_relaxed);
  } while (!head.compare_exchange_weak(packed, pack(tagOf(packed) + 1, handle),
                                       std::memory_order_acq_rel));
}

bool Segment::validHandle(uint64_t handle) const {
  if (handle == 0 || (handle & 63) != 0 || !contains(handle, sizeof(BlockHeader))) return false;
  const uint32_t k = block(handle).blockClass;
  if (k < kMinBlockClass || k > kMaxBlockClass) return false;
  if (!contains(handle, uint64_t{1} << k)) return false;
  return block(handle).used <= payloadCapacity(handle);
}

}  // namespace vrflow::ipc
