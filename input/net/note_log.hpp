#pragma once
// The notes of one checker (why a sample or command was refused): counts per kind and the
// newest note, written by one thread and read by any. A sequence lock over atomics: a reader
// never waits, and retries a torn copy.
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>

namespace mixpilot::net {

// Note: { Kind why; const char* format; double a, b, c; } with Kind an 8-bit enum whose 0 is
// "none"; Kinds: the number of its values.
template <class Note, int Kinds>
class NoteLog {
 public:
  using Kind = decltype(Note::why);

  // Writer only.
  void add(const Note& note) {
    counts_[std::size_t(note.why)].fetch_add(1, std::memory_order_relaxed);
    const std::uint32_t s = seq_.load(std::memory_order_relaxed);
    seq_.store(s + 1, std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_release);
    why_.store(std::uint8_t(note.why), std::memory_order_relaxed);
    format_.store(note.format, std::memory_order_relaxed);
    a_.store(note.a, std::memory_order_relaxed);
    b_.store(note.b, std::memory_order_relaxed);
    c_.store(note.c, std::memory_order_relaxed);
    seq_.store(s + 2, std::memory_order_release);
  }
  std::uint64_t count(Kind k) const { return counts_[std::size_t(k)].load(std::memory_order_relaxed); }
  // Every note but "none".
  std::uint64_t total() const {
    std::uint64_t n = 0;
    for (int k = 1; k < Kinds; ++k) n += count(Kind(k));
    return n;
  }
  // A consistent copy of the newest note; false before the first, or while a writer floods
  // faster than a copy.
  bool last(Note& out) const {
    for (int attempt = 0; attempt < 64; ++attempt) {
      const std::uint32_t s = seq_.load(std::memory_order_acquire);
      if (s == 0) return false;
      if (s & 1u) continue;
      Note n{Kind(why_.load(std::memory_order_relaxed)), format_.load(std::memory_order_relaxed),
             a_.load(std::memory_order_relaxed), b_.load(std::memory_order_relaxed),
             c_.load(std::memory_order_relaxed)};
      std::atomic_thread_fence(std::memory_order_acquire);
      if (seq_.load(std::memory_order_relaxed) == s) {
        out = n;
        return true;
      }
    }
    return false;
  }

 private:
  std::array<std::atomic<std::uint64_t>, Kinds> counts_{};
  std::atomic<std::uint32_t> seq_{0};
  std::atomic<std::uint8_t> why_{0};
  std::atomic<const char*> format_{""};
  std::atomic<double> a_{0}, b_{0}, c_{0};
};

}  // namespace mixpilot::net
