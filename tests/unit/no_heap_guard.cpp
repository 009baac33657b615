// The counting allocator of no_heap_guard.hpp, and the test that it is live.
// malloc is interposed through glibc's __libc_malloc (these are Linux test binaries).
#include "no_heap_guard.hpp"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <atomic>
#include <cstdlib>
#include <new>
#include <vector>

namespace {
std::atomic<bool> g_on{false};
std::atomic<std::size_t> g_count{0};
void note() {
  if (g_on.load(std::memory_order_relaxed)) g_count.fetch_add(1, std::memory_order_relaxed);
}
}  // namespace

namespace telltale::test {
void heap_guard(bool on) {
  if (on) g_count = 0;
  g_on = on;
}
std::size_t heap_allocations() { return g_count.load(); }
}  // namespace telltale::test

// Under AddressSanitizer (deploy/test_sanitized.sh) the sanitizer owns malloc and operator new:
// replacing them would hand its free() blocks it never allocated. There the same count comes
// from the sanitizer's own allocation hook, which sees every malloc and new-expression.
#if defined(__SANITIZE_ADDRESS__)
#define TELLTALE_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define TELLTALE_ASAN 1
#endif
#endif

#ifdef TELLTALE_ASAN
// Declared here as the sanitizer runtime exports it (GCC ships no header for it).
extern "C" int __sanitizer_install_malloc_and_free_hooks(void (*malloc_hook)(const volatile void*,
                                                                             std::size_t),
                                                         void (*free_hook)(const volatile void*));
namespace {
void on_malloc(const volatile void*, std::size_t) { note(); }
void on_free(const volatile void*) {}
const int kHooksInstalled = __sanitizer_install_malloc_and_free_hooks(on_malloc, on_free);
}  // namespace
#else
extern "C" void* __libc_malloc(std::size_t);
extern "C" void __libc_free(void*);
extern "C" void* malloc(std::size_t n) {
  note();
  return __libc_malloc(n);
}

void* operator new(std::size_t n) {
  note();
  if (void* p = __libc_malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { __libc_free(p); }
void operator delete[](void* p) noexcept { __libc_free(p); }
void operator delete(void* p, std::size_t) noexcept { __libc_free(p); }
void operator delete[](void* p, std::size_t) noexcept { __libc_free(p); }
#endif

namespace {

// The guard itself: what an allocation put into an update looks like (a container growing, a
// malloc, an Eigen matrix sized at run time) is seen.
TEST(NoHeapGuard, SeesAnAllocation) {
#ifdef TELLTALE_ASAN
  EXPECT_NE(kHooksInstalled, 0) << "the sanitizer took no allocation hook";
#endif
  using telltale::test::allocations_in;
  volatile std::size_t sink = 0;
  EXPECT_GE(allocations_in([&] {
              std::vector<double> v(100, 1.0);
              sink = sink + v.size();
            }),
            1u);
  EXPECT_GE(allocations_in([&] {
              void* p = std::malloc(64);
              sink = sink + (p != nullptr);
              std::free(p);
            }),
            1u);
  EXPECT_GE(allocations_in([&] {
              Eigen::MatrixXd m(16, 16);
              m.setZero();
              sink = sink + static_cast<std::size_t>(m.size());
            }),
            1u);
  EXPECT_EQ(allocations_in([&] { sink = sink + 1; }), 0u);
}

}  // namespace
