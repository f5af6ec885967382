#pragma once

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
