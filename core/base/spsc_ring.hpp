#pragma once
// A single-producer single-consumer ring of values, sized once: the producer (the control
// thread) never blocks and never allocates (a full ring drops the value and counts it); the
// consumer (the UI) takes what has arrived, oldest first.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace mixpilot {

template <class T>
class SpscRing {
 public:
  // `capacity` slots, each a copy of `prototype` (so copying into them allocates nothing).
  void setup(std::size_t capacity, const T& prototype) {
    slots_.assign(capacity + 1, prototype);
    head_.store(0);
    tail_.store(0);
    dropped_.store(0);
  }
  // Producer: false (and counted) when the ring is full.
  bool push(const T& v) {
    const std::size_t h = head_.load(std::memory_order_relaxed);
    const std::size_t next = (h + 1) % slots_.size();
    if (next == tail_.load(std::memory_order_acquire)) {
      dropped_.fetch_add(1, std::memory_order_relaxed);
      return false;
    }
    slots_[h] = v;
    head_.store(next, std::memory_order_release);
    return true;
  }
  // Consumer: the oldest value into `out`, or false when empty.
  bool pop(T& out) {
    const std::size_t t = tail_.load(std::memory_order_relaxed);
    if (t == head_.load(std::memory_order_acquire)) return false;
    out = slots_[t];
    tail_.store((t + 1) % slots_.size(), std::memory_order_release);
    return true;
  }
  std::int64_t dropped() const { return dropped_.load(std::memory_order_relaxed); }

 private:
  std::vector<T> slots_;
  std::atomic<std::size_t> head_{0};  // next slot the producer writes
  std::atomic<std::size_t> tail_{0};  // next slot the consumer reads
  std::atomic<std::int64_t> dropped_{0};
};

}  // namespace mixpilot
