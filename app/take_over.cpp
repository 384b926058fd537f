#include "app/take_over.hpp"

#include <chrono>
#include <filesystem>
#include <system_error>

#include "app/flight_rig.hpp"
#include "core/base/content_hash.hpp"

namespace mixpilot::cli {

TakeOver::TakeOver(std::string recording, std::int64_t k)
    : recording_(std::move(recording)), k_(k), worker_([this] { run(); }) {}

TakeOver::~TakeOver() {
  stop_.store(true);
  if (worker_.joinable()) worker_.join();
}

double TakeOver::progress() const {
  if (done()) return 1.0;
  return k_ > 0 ? double(flown_.load(std::memory_order_relaxed)) / double(k_) : 0.0;
}

void TakeOver::run() {
  const auto t0 = std::chrono::steady_clock::now();
  const auto finish = [&] {
    seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    done_.store(true, std::memory_order_release);
  };
  FlyOptions o;
  o.pilot = recording_;
  o.replay = true;
  o.command = "fly from here";
  int status = 0;
  std::unique_ptr<FlightRig> rig = FlightRig::assemble(o, error_, status);
  if (!rig) return finish();
  Mode& mode = rig->mode();
  if (k_ < 0 || k_ >= mode.steps_total()) {
    error_ = recording_ + ": no step " + std::to_string(k_) + " to fly from";
    return finish();
  }
  rig->start();
  while (mode.steps_done() < k_ && !stop_.load(std::memory_order_relaxed)) {
    if (!rig->step()) break;
    flown_.store(mode.steps_done(), std::memory_order_relaxed);
  }
  if (stop_.load()) {
    error_ = "stopped";
    return finish();
  }
  if (mode.steps_done() != k_) {
    error_ = recording_ + ": its replay ended at step " + std::to_string(mode.steps_done()) +
             ", before step " + std::to_string(k_);
    return finish();
  }
  // The new flight must start from the recorded flight itself, not from a replay that went
  // elsewhere.
  if (const std::string d = rig->replay_difference_so_far(); !d.empty()) {
    error_ = "the replay of " + recording_ + " differs from the recording before t = " +
             seconds_text(double(k_) * mode.dt()) + " s (" + d + "): it cannot be flown on from";
    return finish();
  }
  auto moment = std::make_shared<FlyFrom>();
  auto snapshot = std::make_shared<ModeSnapshot>();
  mode.save(*snapshot);
  moment->snapshot = std::move(snapshot);
  std::error_code ec;
  const std::filesystem::path abs = std::filesystem::absolute(recording_, ec);
  moment->parent = (ec ? std::filesystem::path(recording_) : abs).lexically_normal().string();
  const std::optional<std::string> sha = sha256_file(recording_, error_);
  if (!sha) return finish();
  moment->parent_sha256 = *sha;
  moment->step = k_;
  moment->t = double(k_) * mode.dt();
  const Flight& f = rig->flight();
  moment->scenario_text = f.scenario_text;
  moment->scenario_source = f.scenario_source;
  moment->scenario_file = f.scenario_file;
  moment->duration = double(mode.steps_total()) * mode.dt();
  moment->assist = mode.identity().probe ? Assistance::off : Assistance::on;
  moment_ = std::move(moment);
  finish();
}

}  // namespace mixpilot::cli
