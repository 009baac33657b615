// No heap in the update loops of the step detectors and the PDR (STYLE 5).
//
// The guard is this test binary's own allocator: global operator new (every new-expression and
// every standard container) and malloc (Eigen's dynamic matrices, C code) are replaced here and
// count the allocations made while `g_forbid` is set. It needs neither EIGEN_RUNTIME_NO_MALLOC
// nor assertions, so it checks in Release and RelWithDebInfo as well (Eigen's own guard is an
// eigen_assert: NDEBUG turned the previous version of this test off). It sees the library's
// code as built for the product (fusion_core linked as is), not a recompiled copy.
// malloc is interposed through glibc's __libc_malloc (this is a Linux test binary).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "telltale/fusion/pdr.hpp"
#include "telltale/fusion/sim/gait_sim.hpp"
#include "telltale/fusion/steps.hpp"

namespace {
std::atomic<bool> g_forbid{false};
std::atomic<std::size_t> g_allocations{0};
void note() {
  if (g_forbid.load(std::memory_order_relaxed))
    g_allocations.fetch_add(1, std::memory_order_relaxed);
}
}  // namespace

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

namespace telltale::fusion {
namespace {

/// Counts the heap allocations made by `f`.
template <class F>
std::size_t allocations_in(F&& f) {
#ifdef TELLTALE_ASAN
  EXPECT_NE(kHooksInstalled, 0) << "the sanitizer took no allocation hook";
#endif
  g_allocations = 0;
  g_forbid = true;
  f();
  g_forbid = false;
  return g_allocations.load();
}

TEST(NoHeap, TheGuardSeesAnAllocation) {
  // The guard itself: a vector growing inside the guarded region is seen (this is what an
  // allocation put into an update would look like).
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
}

TEST(NoHeap, StepDetectorsAndPdrUpdateWithoutAllocation) {
  for (const char* scenario : {"phone-switch", "foot-mixed"}) {
    const auto run =
        sim::simulate_gait(*sim::make_gait_scenario(scenario, 4), sim::random_person(4), 4);
    const auto mount =
        std::string(scenario).rfind("foot", 0) == 0 ? StepMount::kFoot : StepMount::kBody;
    std::vector<std::unique_ptr<StepDetector>> detectors;
    for (auto name : step_detector_names()) detectors.push_back(make_step_detector(name, mount));
    PdrParams params;
    params.mount = mount;
    auto pdr = std::make_unique<Pdr>(params);
    StepEvent ev;
    std::size_t steps = 0;
    const std::size_t n = allocations_in([&] {
      for (const auto& s : run.samples) {
        for (auto& d : detectors) steps += d->update(s.imu, ev) ? 1u : 0u;
        steps += pdr->update(s.imu, s.mag_uT).step ? 1u : 0u;
      }
    });
    EXPECT_EQ(n, 0u) << scenario << ": heap allocations in the update loops";
    EXPECT_GT(steps, 100u) << scenario;
  }
}

}  // namespace
}  // namespace telltale::fusion
