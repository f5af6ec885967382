#pragma once

#include <cstddef>

// Counts heap allocations made through operator new in this test executable
// (allocation_counter.cpp replaces the global operator new).

namespace vrflow::msg::testing {

/// Counts the allocations made while it lives (in this thread and others).
class AllocationCounter {
 public:
  AllocationCounter();
  ~AllocationCounter();
  AllocationCounter(const AllocationCounter&) = delete;
  AllocationCounter& operator=(const AllocationCounter&) = delete;
  /// Allocations so far.
  std::size_t count() const;
  /// The largest single allocation so far, in bytes.
  std::size_t largest() const;
};

}  // namespace vrflow::msg::testing
