#pragma once
// Sessions to and from recordings (core/recording/recording.hpp): a telemetry sink that records every
// control step, and a pilot source that replays a recording's pilot commands into a fresh
// session. With the same scenario and build, a replay reproduces the original telemetry exactly.
#include <string>
#include <vector>

#include "core/control/pilot.hpp"
#include "core/recording/recording.hpp"
#include "core/modes/session.hpp"

namespace mixpilot {

class RecordingSink final : public TelemetrySink {
 public:
  // Opens `path` (written as "<path>.tmp" until close()) for a session of `scenario`.
  bool open(const std::string& path, const Scenario& scenario, const std::string& pilot_name,
            std::string& error);
  void on_sample(const TelemetrySample& sample) override;
  // Completes the file; false with a message if anything failed on the way.
  bool close(std::string& error);

 private:
  SessionRecorder recorder_;
  std::string pilot_name_;
  PilotCommandMsg pilot_;
  VehicleStateMsg state_;
  AppliedCommandMsg applied_;
  SolverStatsMsg solver_;
  PredictionMsg prediction_;
  JoyMsg joy_;
};

class ReplayPilot final : public PilotSource {
 public:
  ReplayPilot(std::vector<PilotCommandMsg> commands, std::string name)
      : commands_(std::move(commands)), name_(std::move(name)) {}
  std::string name() const override { return name_; }
  // The recorded command of this step; false past the end of the recording.
  bool command(std::int64_t step, double t, const Eigen::VectorXd& x, PilotCommand& out) override;

 private:
  std::vector<PilotCommandMsg> commands_;
  std::string name_;
};

}  // namespace mixpilot
