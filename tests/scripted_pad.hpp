#pragma once
// A stick source a test scripts: sticks centred, unplugged over the steps [from, to) (one
// reading per control step), for input loss without SDL.
#include <cstdint>
#include <string>

#include "input/source.hpp"

namespace mixpilot::test {

struct ScriptedPad : input::StickSource {
  input::StickReading r;
  std::int64_t step = 0, from = 0, to = 0;
  std::string name() const override { return "gamepad"; }
  const input::StickReading& latest() override {
    r.connected = step < from || step >= to;
    ++step;
    return r;
  }
};

}  // namespace mixpilot::test
