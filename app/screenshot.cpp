#include "app/screenshot.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "app/cli.hpp"
#include "app/offscreen.hpp"

namespace mixpilot::cli {

std::optional<ScreenshotRequest> parse_screenshot(std::string_view text) {
  const auto colon = text.find(':');
  if (colon == std::string_view::npos || colon == 0 || colon + 1 >= text.size()) return std::nullopt;
  const std::string t(text.substr(0, colon));
  char* end = nullptr;
  const double v = std::strtod(t.c_str(), &end);
  if (end != t.c_str() + t.size() || !std::isfinite(v) || v < 0.0) return std::nullopt;
  return ScreenshotRequest{v, std::string(text.substr(colon + 1))};
}

bool parse_size(std::string_view text, int& width, int& height) {
  const auto x = text.find('x');
  if (x == std::string_view::npos) return false;
  int w = 0, h = 0;
  const auto a = std::from_chars(text.data(), text.data() + x, w);
  const auto b = std::from_chars(text.data() + x + 1, text.data() + text.size(), h);
  if (a.ec != std::errc() || a.ptr != text.data() + x || b.ec != std::errc() ||
      b.ptr != text.data() + text.size() || w < 64 || h < 64 || w > 8192 || h > 8192)
    return false;
  width = w;
  height = h;
  return true;
}

ScreenshotSink::ScreenshotSink(ui::Scene scene, std::vector<ScreenshotRequest> requests,
                               bool overwrite)
    : scene_(std::move(scene)), requests_(std::move(requests)), overwrite_(overwrite) {
  std::stable_sort(requests_.begin(), requests_.end(),
                   [](const auto& a, const auto& b) { return a.t < b.t; });
  done_.assign(requests_.size(), false);
}

ScreenshotSink::~ScreenshotSink() = default;

bool ScreenshotSink::open(int width, int height, std::string& error, float scale) {
  offscreen_ = std::make_unique<Offscreen>();
  return offscreen_->open(width, height, error, scale);
}

void ScreenshotSink::on_sample(const Telemetry& s) {
  history_.push(s);
  ui::count_step(s, counts_);
  for (std::size_t i = 0; i < requests_.size(); ++i) {
    if (done_[i] || !(s.t <= requests_[i].t + 1e-12 && requests_[i].t < s.t + scene_.dt)) continue;
    done_[i] = true;
    ui::RunInfo run = counts_;
    run.state = ui::RunState::flying;
    // Two frames: ImGui sizes some items in the first. Nobody asks for anything here.
    ui::Requests none;
    for (int f = 0; f < 2; ++f)
      offscreen_->frame([&] { ui::draw_screen(scene_, history_, run, ui_, none); });
    std::string error;
    if (!write_file(requests_[i].path, offscreen_->png(), overwrite_, error)) {
      if (error_.empty()) error_ = error;
      continue;
    }
    written_.push_back(requests_[i].path);
    std::string note;
    if (const std::optional<ui::GhostGap> gap = ui::ghost_gap(scene_, s)) {
      char text[64];
      std::snprintf(text, sizeof text, " (ghost: you are %s by %.3f s)",
                    gap->ahead >= 0 ? "ahead" : "behind", std::abs(gap->ahead));
      note = text;
    }
    notes_.push_back(std::move(note));
  }
}

bool ScreenshotSink::finish(std::string& error) const {
  if (!error_.empty()) {
    error = error_;
    return false;
  }
  for (std::size_t i = 0; i < requests_.size(); ++i) {
    if (done_[i]) continue;
    error = "--screenshot " + requests_[i].path + ": the flight never reached t = " +
            std::to_string(requests_[i].t) + " s";
    return false;
  }
  return true;
}

}  // namespace mixpilot::cli
