#pragma once
// Internal to vrflow: not part of the module or filter SDK; it may change without notice
// (docs/architecture.md, "The ABI of what outside code links").

#include <atomic>
#include <cstdint>

namespace vrflow::ipc {

/// A single-producer single-consumer ring of 64-bit handles in shared memory. Lock-free and
/// wait-free, so a process that dies in the middle of push() or pop() never blocks the other.
struct Ring {
  alignas(64) std::atomic<uint64_t> head{0};  ///< next slot to read (consumer owns)
  alignas(64) std::atomic<uint64_t> tail{0};  ///< next slot to write (producer owns)
  alignas(64) uint32_t capacity = 0;          ///< a power of two
  uint32_t mask = 0;
  // uint64_t slots[capacity] follow the header.

  static constexpr std::size_t bytesFor(uint32_t capacity) {
    return sizeof(Ring) + sizeof(uint64_t) * capacity;
  }
  void init(uint32_t cap) {
    capacity = cap;
    mask = cap - 1;
    head.store(0);
    tail.store(0);
  }
  uint64_t* slots() { return reinterpret_cast<uint64_t*>(this + 1); }

  /// Appends a handle; false when full.
  bool push(uint64_t value) {
    const uint64_t t = tail.load(std::memory_order_relaxed);
    if (t - head.load(std::memory_order_acquire) >= capacity) return false;
    slots()[t & mask] = value;
    tail.store(t + 1, std::memory_order_release);
    return true;
  }
  /// Takes the oldest handle; false when empty.
  bool pop(uint64_t& value) {
    const uint64_t h = head.load(std::memory_order_relaxed);
    if (h == tail.load(std::memory_order_acquire)) return false;
    value = slots()[h & mask];
    head.store(h + 1, std::memory_order_release);
    return true;
  }
  uint64_t size() const {
    return tail.load(std::memory_order_acquire) - head.load(std::memory_order_acquire);
  }
  bool empty() const { return size() == 0; }
  bool full() const { return size() >= capacity; }
};

}  // namespace vrflow::ipc

namespace vrflow::ipc {

/// The daemon's view of a ring in memory that modules can write: capacity and mask are kept
/// privately (set when the ring was made), so a module scribbling over the ring's header can
/// lose its own messages but never make the daemon read or write outside the ring.
class RingRef {
 public:
  RingRef() = default;
  explicit RingRef(Ring* ring)
      : ring_(ring), capacity_(ring->capacity), mask_(ring->capacity - 1) {}

  bool push(uint64_t value) const {
    const uint64_t t = ring_->tail.load(std::memory_order_relaxed);
    const uint64_t h = ring_->head.load(std::memory_order_acquire);
    if (t - h >= capacity_) return false;
    ring_->slots()[t & mask_] = value;
    ring_->tail.store(t + 1, std::memory_order_release);
    return true;
  }
  /// False when empty, or when the indexes are inconsistent (then nothing is read).
  bool pop(uint64_t& value) const {
    const uint64_t h = ring_->head.load(std::memory_order_relaxed);
    const uint64_t t = ring_->tail.load(std::memory_order_acquire);
    if (h == t || t - h > capacity_) return false;
    value = ring_->slots()[h & mask_];
    ring_->head.store(h + 1, std::memory_order_release);
    return true;
  }
  uint64_t size() const {
    const uint64_t n =
        ring_->tail.load(std::memory_order_acquire) - ring_->head.load(std::memory_order_acquire);
    return n > capacity_ ? capacity_ : n;
  }
  bool empty() const { return size() == 0; }
  bool full() const { return size() >= capacity_; }
  bool valid() const { return ring_ != nullptr; }

 private:
  Ring* ring_ = nullptr;
  uint32_t capacity_ = 0;
  uint32_t mask_ = 0;
};

}  // namespace vrflow::ipc
