#pragma once
// A flight flown headless to its end and recorded, as `mixpilot fly --headless --record FILE`
// flies it (the flight assembled by FlightRig, one step at a time), for the tests that need a
// recording to replay, compare or remember.
#include <gtest/gtest.h>

#include <string>

#include "app/flight_rig.hpp"

namespace mixpilot::test {

// Flies `o` into the recording `path` (which must not exist); failures are reported to
// GoogleTest. Returns whether the recording was written whole.
inline bool record_flight(const cli::FlyOptions& o, const std::string& path) {
  std::string error;
  int status = 0;
  const auto rig = cli::FlightRig::assemble(o, error, status);
  EXPECT_TRUE(rig) << error;
  if (!rig) return false;
  const bool recording = rig->record(path, "", {}, false, error);
  EXPECT_TRUE(recording) << error;
  rig->start();
  while (rig->step()) {
  }
  const cli::FlightRig::Closed closed = rig->close(false);
  EXPECT_EQ(closed.error, "");
  return recording && closed.error.empty() && closed.recorded == path;
}

}  // namespace mixpilot::test
