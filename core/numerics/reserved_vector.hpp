#pragma once
// A log reserved for a whole flight (per-step timings, the score's samples) that a snapshot of
// the flight copies (core/modes/mode.hpp: Mode::save). A std::vector's copy is sized to the
// elements it holds, so a snapshot taken early and saved into again later would grow, and a
// restored log would lose the capacity that keeps push_back() from allocating in step(). A
// ReservedVector's copy keeps the capacity of the original: copying a log into a snapshot
// allocates once, the first time, and never again for that flight; copying it back into a
// mode set up for the same flight allocates nothing.
#include <vector>

namespace mixpilot {

template <class T>
class ReservedVector : public std::vector<T> {
 public:
  using std::vector<T>::vector;
  ReservedVector() = default;
  ReservedVector(const ReservedVector& other) : std::vector<T>() { assign_from(other); }
  ReservedVector(ReservedVector&&) noexcept = default;
  ReservedVector& operator=(const ReservedVector& other) {
    if (this != &other) assign_from(other);
    return *this;
  }
  ReservedVector& operator=(ReservedVector&&) noexcept = default;
  ~ReservedVector() = default;

 private:
  void assign_from(const ReservedVector& other) {
    if (this->capacity() < other.capacity()) {
      this->clear();
      this->reserve(other.capacity());
    }
    this->assign(other.begin(), other.end());
  }
};

}  // namespace mixpilot
