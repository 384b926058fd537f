#pragma once
// What both history backends' tests check of a flight read back: every field as written, the
// doubles exact to the bit, a score that was not finite read back as NaN.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>

#include "core/history/history.hpp"

namespace mixpilot::test {

inline void expect_same_flight(const history::FlightRecord& f, const history::StoredFlight& r) {
  EXPECT_GT(r.id, 0);
  EXPECT_EQ(r.trainee, f.trainee);
  EXPECT_EQ(r.station, f.station);
  EXPECT_EQ(r.scenario, f.scenario);
  EXPECT_EQ(r.scenario_hash, f.scenario_hash);
  EXPECT_EQ(r.mode, f.mode);
  EXPECT_EQ(r.pilot, f.pilot);
  EXPECT_EQ(r.input_device, f.input_device);
  EXPECT_EQ(r.input_settings_hash, f.input_settings_hash);
  EXPECT_EQ(r.started_unix_ms, f.started_unix_ms);
  EXPECT_EQ(r.duration_s, f.duration_s);
  EXPECT_EQ(r.ended, f.ended);
  EXPECT_EQ(r.probe, f.probe);
  EXPECT_EQ(r.recording_path, f.recording_path);
  EXPECT_EQ(r.recording_hash, f.recording_hash);
  EXPECT_EQ(r.app_version, f.app_version);
  EXPECT_EQ(r.front_end, f.front_end);
  EXPECT_EQ(r.parent_recording_hash, f.parent_recording_hash);
  EXPECT_EQ(r.parent_step, f.parent_step);
  ASSERT_EQ(r.metrics.size(), f.metrics.size());
  for (std::size_t i = 0; i < f.metrics.size(); ++i) {
    EXPECT_EQ(r.metrics[i].first, f.metrics[i].first);
    if (std::isfinite(f.metrics[i].second))
      EXPECT_EQ(r.metrics[i].second, f.metrics[i].second) << f.metrics[i].first;
    else
      EXPECT_TRUE(std::isnan(r.metrics[i].second)) << f.metrics[i].first;
  }
}

}  // namespace mixpilot::test
