#include "app/replay_tape.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>

#include "app/cli.hpp"
#include "core/modes/session.hpp"

namespace mixpilot::cli {

namespace {

// Predicted paths take most of a step's telemetry: past this many bytes of them, a tape keeps
// every k-th step's only (the playhead shows no predicted path in between).
constexpr std::size_t kPredictedBudget = std::size_t(256) << 20;

class TapeSink final : public TelemetrySink {
 public:
  TapeSink(std::vector<Telemetry>& tape, std::atomic<std::size_t>& ready, std::size_t stride)
      : tape_(&tape), ready_(&ready), stride_(stride) {}
  void on_sample(const Telemetry& s) override {
    const auto k = std::size_t(s.step);
    if (k >= tape_->size()) return;
    Telemetry& slot = (*tape_)[k];
    slot = s;
    if (stride_ > 1 && k % stride_ != 0) {
      slot.predicted.resize(3, 0);
      slot.predicted_reference.resize(3, 0);
    }
    ready_->store(k + 1, std::memory_order_release);
  }

 private:
  std::vector<Telemetry>* tape_;
  std::atomic<std::size_t>* ready_;
  std::size_t stride_;
};

}  // namespace

ReplayTape::ReplayTape(std::unique_ptr<FlightRig> rig, std::string path)
    : rig_(std::move(rig)), path_(std::move(path)) {
  const Mode& mode = rig_->mode();
  dt_ = mode.dt();
  // "replay of FILE · flown by WHO": the recorded trainee, else the recorded pilot source (a
  // replay's own pilot source is the recording, which the title already names).
  std::string who;
  if (const auto& rec = rig_->flight().recording) {
    for (const char* key : {"trainee", "pilot"}) {
      const auto it = rec->metadata.find(key);
      if (it != rec->metadata.end() && !it->second.empty()) {
        who = it->second;
        break;
      }
    }
  }
  const std::string file = std::filesystem::path(path_).filename().string();
  scene_ = ui::scene_of(mode, who.empty() ? "replay of " + file
                                          : "replay of " + file + " \u00b7 flown by " + who);
  debrief_ = debrief_settings(mode);
  tape_.assign(std::size_t(std::max<std::int64_t>(mode.steps_total(), 0)), mode.telemetry());
}

ReplayTape::~ReplayTape() { stop(); }

void ReplayTape::start() {
  if (!loader_.joinable() && !done()) loader_ = std::thread([this] { load(); });
}

void ReplayTape::fly() {
  if (done()) return;
  Progress progress("replay " + path_, std::int64_t(tape_.size()));
  start();
  while (!done()) {
    progress.update(std::int64_t(ready()));
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    if (interrupted()) stop();
  }
  stop();
}

void ReplayTape::stop() {
  stop_.store(true);
  if (loader_.joinable()) loader_.join();
}

void ReplayTape::load() {
  const Mode& mode = rig_->mode();
  const auto& p = tape_.empty() ? Eigen::Matrix3Xd() : tape_.front().predicted;
  const std::size_t bytes = tape_.size() * std::size_t(p.size()) * 2 * sizeof(double);
  const std::size_t stride = std::max<std::size_t>(1, (bytes + kPredictedBudget - 1) / kPredictedBudget);
  TapeSink sink(tape_, ready_, stride);
  rig_->watch(sink);
  rig_->start();
  while (!stop_.load(std::memory_order_relaxed) && rig_->step()) {
  }
  if (!mode.finished() && stop_.load()) {
    mismatch_ = "interrupted";
  } else {
    mismatch_ = rig_->replay_difference();
    metrics_ = rig_->metrics();
  }
  done_.store(true, std::memory_order_release);
}

std::size_t tape_index(const ReplayTape& tape, double t) {
  const std::size_t n = tape.ready();
  if (n == 0) return 0;
  const double k = std::floor(t / tape.dt() + 1e-9);
  return std::size_t(std::clamp(k, 0.0, double(n - 1)));
}

}  // namespace mixpilot::cli
