// Counts heap allocations made through operator new (the replaced global operators in
// alloc_counter.cpp, linked into the growbench binary, the tests and the benchmarks). Allocations by C
// libraries through malloc (Embree's aligned buffers, TBB's internal pools) are not counted.
#pragma once

#include <cstdint>

namespace growbench {

struct AllocStats {
  std::uint64_t count = 0;  // operator new calls
  std::uint64_t bytes = 0;  // bytes requested
};

// Totals since the process started. Thread-safe (relaxed atomics).
AllocStats alloc_stats();
// Whether the counting operators are linked into this binary.
bool alloc_counting_enabled();

}  // namespace growbench
