#pragma once
// The newest value from one writer thread to one reader thread, wait-free on both sides: a
// triple buffer. The writer fills its back slot and swaps it with the middle one; the reader
// swaps its front slot with the middle one when the writer has published since. Neither ever
// waits for the other, so a device thread can hand samples to the control thread.
#include <atomic>
#include <cstdint>

namespace mixpilot {

template <class T>
class Latest {
 public:
  // Writer thread only.
  void publish(const T& v) {
    slots_[back_] = v;
    const std::uint8_t old = middle_.exchange(std::uint8_t(back_ | kFresh), std::memory_order_acq_rel);
    back_ = old & kIndex;
  }
  // Reader thread only: the newest value published (a default T before the first).
  const T& read() {
    if (middle_.load(std::memory_order_relaxed) & kFresh) {
      const std::uint8_t old = middle_.exchange(std::uint8_t(front_), std::memory_order_acq_rel);
      front_ = old & kIndex;
    }
    return slots_[front_];
  }

 private:
  static constexpr std::uint8_t kIndex = 3, kFresh = 4;
  T slots_[3]{};
  std::atomic<std::uint8_t> middle_{1};
  std::uint8_t back_ = 0;   // the writer's
  std::uint8_t front_ = 2;  // the reader's
};

}  // namespace mixpilot
