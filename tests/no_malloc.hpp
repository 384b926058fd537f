#pragma once
// "No heap allocation in the control loop": every malloc/calloc/realloc of the process inside
// a NoMalloc scope is counted (Eigen's heap, std::vector growth, operator new, ...). A Debug
// build also arms Eigen's own check (EIGEN_RUNTIME_NO_MALLOC), which aborts at the allocating
// line: the way to find where a counted allocation comes from. Under the sanitizers neither: the
// release suite checks the allocations, the sanitized one runs the same flows for memory
// errors. Include it in exactly one translation unit of a test executable: it defines the
// process's malloc.
#include <atomic>
#include <cstddef>
#include <cstdlib>

#include <Eigen/Core>

// Under AddressSanitizer malloc is the sanitizer's: no counting (g++ and clang ≥ 15 define
// __SANITIZE_ADDRESS__, older clang only answers __has_feature).
#if defined(__SANITIZE_ADDRESS__)
#define MIXPILOT_COUNT_MALLOC 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define MIXPILOT_COUNT_MALLOC 0
#endif
#endif
#ifndef MIXPILOT_COUNT_MALLOC
#define MIXPILOT_COUNT_MALLOC 1
#endif

#if MIXPILOT_COUNT_MALLOC
extern "C" void* __libc_malloc(std::size_t);
extern "C" void* __libc_calloc(std::size_t, std::size_t);
extern "C" void* __libc_realloc(void*, std::size_t);
namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_allocations{0};
std::atomic<long> g_bytes{0};  // requested by the counted allocations
void count_allocation(std::size_t bytes) {
  if (!g_counting.load(std::memory_order_relaxed)) return;
  g_allocations.fetch_add(1);
  g_bytes.fetch_add(long(bytes));
}
}  // namespace
extern "C" void* malloc(std::size_t n) {
  count_allocation(n);
  return __libc_malloc(n);
}
extern "C" void* calloc(std::size_t n, std::size_t m) {
  count_allocation(n * m);
  return __libc_calloc(n, m);
}
extern "C" void* realloc(void* p, std::size_t n) {
  count_allocation(n);
  return __libc_realloc(p, n);
}
#endif

namespace mixpilot {

// Counts the allocations in its scope and the bytes they asked for, forbidding none (what a
// first save into a snapshot allocates, say). 0 under AddressSanitizer.
struct AllocationCount {
  AllocationCount() {
#if MIXPILOT_COUNT_MALLOC
    g_allocations = 0;
    g_bytes = 0;
    g_counting = true;
#endif
  }
  ~AllocationCount() { stop(); }
  void stop() {
#if MIXPILOT_COUNT_MALLOC
    g_counting = false;
#endif
  }
  static long count() {
#if MIXPILOT_COUNT_MALLOC
    return g_allocations.load();
#else
    return 0;
#endif
  }
  static long bytes() {
#if MIXPILOT_COUNT_MALLOC
    return g_bytes.load();
#else
    return 0;
#endif
  }
};

// Whether allocations are counted (not under the sanitizers, which own malloc).
inline constexpr bool kAllocationsCounted = MIXPILOT_COUNT_MALLOC != 0;

// Whether Eigen's heap allocations abort under a NoMalloc guard: Debug builds (CMakeLists.txt).
#ifdef EIGEN_RUNTIME_NO_MALLOC
inline constexpr bool kEigenGuardArmed = true;
#else
inline constexpr bool kEigenGuardArmed = false;
#endif

// RAII guard: all process allocations are counted and, in a Debug build, an Eigen heap
// allocation aborts.
struct NoMalloc : AllocationCount {
#ifdef EIGEN_RUNTIME_NO_MALLOC
  NoMalloc() { Eigen::internal::set_is_malloc_allowed(false); }
  ~NoMalloc() { Eigen::internal::set_is_malloc_allowed(true); }
#endif
};

struct GuardedSteps {
  long allocations = 0;  // in all step() calls together
  long steps = 0;        // step() calls that stepped
};

// Steps `mode` to its end, each step() alone under a NoMalloc guard; `after_step` runs
// unguarded after every step that happened (to read telemetry).
template <class Mode, class AfterStep>
GuardedSteps step_to_end_without_malloc(Mode& mode, AfterStep&& after_step) {
  GuardedSteps r;
  for (;;) {
    bool stepped = false;
    {
      NoMalloc guard;
      stepped = mode.step();
      r.allocations += NoMalloc::count();
    }
    if (!stepped) return r;
    ++r.steps;
    after_step();
  }
}

}  // namespace mixpilot
