#pragma once
// The one guard of every no-heap test (STYLE 5: no heap in an update). no_heap_guard.cpp
// replaces this test binary's allocator: global operator new (every new-expression and every
// standard container) and malloc (Eigen's dynamic matrices, C code) count the allocations made
// while the guard is on. It needs neither EIGEN_RUNTIME_NO_MALLOC nor assertions, so it checks
// in Release and RelWithDebInfo too, and it sees fusion_core as built for the product (linked as
// is, not a recompiled copy). Each binary made by telltale_no_heap_test() (tests/CMakeLists.txt)
// also runs NoHeapGuard.SeesAnAllocation, which proves the guard live in that binary.
#include <cstddef>

namespace telltale::test {

void heap_guard(bool on);        ///< start (true: count from zero) or stop counting
std::size_t heap_allocations();  ///< allocations counted since the guard was turned on

/// The heap allocations made by `f()`.
template <class F>
std::size_t allocations_in(F&& f) {
  heap_guard(true);
  f();
  heap_guard(false);
  return heap_allocations();
}

}  // namespace telltale::test
