#pragma once
// A short text of fixed capacity (a debrief marker's, an instructor's command's): an event or a
// command holds it without allocating. Its own header so that core/modes/instructor.hpp, which
// the telemetry of core/modes/mode.hpp carries, need not include the debrief.
#include <array>
#include <cstddef>
#include <string_view>

namespace mixpilot {

class DebriefNote {
 public:
  static constexpr std::size_t kCapacity = 95;  // bytes; a longer text is cut at a character
  void assign(std::string_view text);           // core/modes/debrief.cpp
  std::string_view view() const { return {text_.data(), size_}; }
  bool operator==(const DebriefNote& o) const { return view() == o.view(); }

 private:
  std::array<char, kCapacity + 1> text_{};
  std::size_t size_ = 0;
};

}  // namespace mixpilot
