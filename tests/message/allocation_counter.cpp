#include "allocation_counter.hpp"

#include <atomic>
#include <cstdlib>
#include <new>

namespace {

std::atomic<int> gActive{0};
std::atomic<std::size_t> gCount{0};
std::atomic<std::size_t> gLargest{0};

void* allocate(std::size_t size) {
  if (gActive.load(std::memory_order_relaxed) > 0) {
    gCount.fetch_add(1, std::memory_order_relaxed);
    std::size_t seen = gLargest.load(std::memory_order_relaxed);
    while (size > seen && !gLargest.compare_exchange_weak(seen, size)) {
    }
  }
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}

}  // namespace

void* operator new(std::size_t size) {
  return allocate(size);
}
void* operator new[](std::size_t size) {
  return allocate(size);
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete[](void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  std::free(p);
}

namespace vrflow::msg::testing {

AllocationCounter::AllocationCounter() {
  gCount = 0;
  gLargest = 0;
  gActive.fetch_add(1);
}
AllocationCounter::~AllocationCounter() {
  gActive.fetch_sub(1);
}
std::size_t AllocationCounter::count() const {
  return gCount.load();
}
std::size_t AllocationCounter::largest() const {
  return gLargest.load();
}

}  // namespace vrflow::msg::testing
