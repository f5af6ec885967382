#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <span>

#include "vrflow/base/result.hpp"
#include "vrflow/ipc/doorbell.hpp"

namespace vrflow::ipc {

/// Messages are carved from power-of-two blocks; block class k holds 2^k bytes, header included.
inline constexpr int kMinBlockClass = 7;   // 128 B
inline constexpr int kMaxBlockClass = 30;  // 1 GiB
inline constexpr int kBlockClasses = kMaxBlockClass - kMinBlockClass + 1;
inline constexpr uint32_t kSegmentMagic = 0x53465256;  // "VRFS"
inline constexpr uint32_t kSegmentVersion = 3;

/// The header in front of every message block (one cache line).
struct alignas(64) BlockHeader {
  std::atomic<uint32_t> refs{0};  ///< holders of this block across all processes
  uint32_t blockClass = 0;        ///< log2 of the block size
  uint64_t used = 0;              ///< payload bytes written
  std::atomic<uint64_t> next{0};  ///< next free block while on a free list
};
static_assert(sizeof(BlockHeader) == 64);

/// The first bytes of a segment.
struct alignas(64) SegmentHeader {
  uint32_t magic = kSegmentMagic;
  uint32_t version = kSegmentVersion;
  uint64_t size = 0;
  std::atomic<uint32_t> stopRequested{0};
  Doorbell daemonBell;                  ///< modules ring it after pushing or popping
  std::atomic<uint64_t> bump{0};        ///< first never-used byte
  std::atomic<uint64_t> inUseBytes{0};  ///< bytes of blocks currently held
  std::atomic<uint64_t> peakInUseBytes{0};
  std::atomic<uint64_t> failedAllocations{0};  ///< allocate() calls that found no room
  uint64_t controlOffset = 0;                  ///< where the run's control table starts (0: none)
  /// Busy wait before sleeping on a doorbell, ns (VRFLOW_SPIN_US; 0: none). Set by the daemon
  /// before any module starts.
  int64_t spinNs = 0;
  std::atomic<uint64_t> freeHeads[kBlockClasses];  ///< Treiber stacks, tagged against ABA
};

/// A shared-memory segment owned by a host's daemon and mapped by its modules. It is created
/// with memfd_create, so it has no name in /dev/shm and vanishes with its last holder, even
/// after kill -9. Children inherit its descriptor.
class Segment {
 public:
  /// Creates a segment of `bytes` (sparse: pages are committed when touched).
  static Result<Segment> create(std::size_t bytes);
  /// Maps an existing segment from an inherited descriptor.
  static Result<Segment> attach(int fd);

  Segment() = default;
  Segment(Segment&& other) noexcept;
  Segment& operator=(Segment&& other) noexcept;
  Segment(const Segment&) = delete;
  Segment& operator=(const Segment&) = delete;
  ~Segment();

  /// The descriptor, for handing the segment to a child process.
  int fd() const { return fd_; }
  SegmentHeader& header() const { return *header_; }
  std::byte* base() const { return base_; }
  std::size_t size() const { return size_; }

  /// Pointer to an offset inside the segment.
  template <typename T>
  T* at(uint64_t offset) const {
    return reinterpret_cast<T*>(base_ + offset);
  }
  /// True when [offset, offset + bytes) lies inside the segment.
  bool contains(uint64_t offset, uint64_t bytes) const {
    return offset <= size_ && bytes <= size_ - offset;
  }

  /// Reserves never-freed bytes for control structures (rings, tables); 0 when exhausted.
  uint64_t reserve(std::size_t bytes, std::size_t alignment = 64);

  /// Allocates a block with room for `payloadBytes`; returns its handle with one reference,
  /// or 0 when the segment is exhausted.
  uint64_t allocate(std::size_t payloadBytes);
  /// Adds a reference to a block.
  void retain(uint64_t handle) const;
  /// Drops a reference; the last one returns the block to its free list.
  void release(uint64_t handle);
  /// Says that this thread hands a reference to another process (pushes it on a ring): what
  /// it did with the block happens before that process drops it. Only ThreadSanitizer needs
  /// telling (it cannot see another process's atomics, so a block freed there and allocated
  /// again here would look like a race); otherwise this does nothing.
  void handOver(uint64_t handle) const;

  BlockHeader& block(uint64_t handle) const { return *at<BlockHeader>(handle); }
  std::byte* payload(uint64_t handle) const { return base_ + handle + sizeof(BlockHeader); }
  std::size_t payloadCapacity(uint64_t handle) const {
    return (std::size_t{1} << block(handle).blockClass) - sizeof(BlockHeader);
  }
  /// The written part of a block's payload.
  std::span<const std::byte> bytes(uint64_t handle) const {
    return {payload(handle), block(handle).used};
  }
  /// True when `handle` looks like a block this segment handed out (bounds and class checked).
  bool validHandle(uint64_t handle) const;

 private:
  Segment(int fd, std::byte* base, std::size_t size);
  int fd_ = -1;
  std::byte* base_ = nullptr;
  std::size_t size_ = 0;
  SegmentHeader* header_ = nullptr;
};

}  // namespace vrflow::ipc
