#pragma once
// A session drives one mode (core/modes/mode.hpp) step by step and hands each step's telemetry
// to its sinks (recorder, replay check, later the UI's hand-over buffer). The same code serves
// as-fast-as-possible runs (run(): deterministic, no clock involved) and real-time runs, whose
// runner calls step() once per control period.
#include <vector>

#include "core/modes/mode.hpp"

namespace mixpilot {

class TelemetrySink {
 public:
  virtual ~TelemetrySink() = default;
  // Called on the stepping thread right after each step; must not block it for long.
  virtual void on_sample(const Telemetry& sample) = 0;
};

class Session {
 public:
  explicit Session(Mode& mode) : mode_(&mode) {}

  void add_sink(TelemetrySink* sink) { sinks_.push_back(sink); }

  // One control step of the mode, then every sink sees its telemetry. false once the run is
  // over (nothing happened then). Allocates nothing beyond what the mode and sinks do.
  bool step() {
    if (!mode_->step()) return false;
    for (TelemetrySink* sink : sinks_) sink->on_sample(mode_->telemetry());
    return true;
  }
  // Steps until the run is over.
  void run() {
    while (step()) {
    }
  }

  Mode& mode() { return *mode_; }
  const Mode& mode() const { return *mode_; }

 private:
  Mode* mode_;
  std::vector<TelemetrySink*> sinks_;
};

}  // namespace mixpilot
