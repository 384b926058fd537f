#pragma once
// `--screenshot T:FILE.png`: what the window would show at simulated time T, rendered
// offscreen (app/offscreen.hpp) from the UI code (ui/screen.hpp) during a headless flight.
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/modes/session.hpp"
#include "ui/scene.hpp"
#include "ui/screen.hpp"

namespace mixpilot::cli {

class Offscreen;

struct ScreenshotRequest {
  double t = 0.0;    // [s] simulated time
  std::string path;  // PNG file
};

// "T:FILE.png" with T ≥ 0 seconds; nullopt when malformed.
std::optional<ScreenshotRequest> parse_screenshot(std::string_view text);
// "WxH" within [64, 8192]; false when malformed.
bool parse_size(std::string_view text, int& width, int& height);

// Collects the telemetry and renders each requested time's frame: the step k with
// t_k ≤ T < t_k + Δt, drawn with that step as the newest.
class ScreenshotSink : public TelemetrySink {
 public:
  ScreenshotSink(ui::Scene scene, std::vector<ScreenshotRequest> requests, bool overwrite);
  ~ScreenshotSink() override;

  // Starts the offscreen renderer at the display scale `scale`; false with the reason.
  [[nodiscard]] bool open(int width, int height, std::string& error, float scale = 1.0f);
  void on_sample(const Telemetry& sample) override;

  // After the flight: false with the first failure (a write error, a time never reached).
  [[nodiscard]] bool finish(std::string& error) const;
  const std::vector<std::string>& written() const { return written_; }
  // What the summary adds to each written screenshot's line: with a ghost, the HUD's figure to
  // the millisecond (" (ghost: you are ahead by 0.843 s)"); "" without one.
  const std::vector<std::string>& notes() const { return notes_; }
  // Fallbacks and deadline misses of the steps so far: what the screenshots' HUD shows.
  const ui::RunInfo& counts() const { return counts_; }

 private:
  ui::Scene scene_;
  std::vector<ScreenshotRequest> requests_;  // by time
  std::vector<bool> done_;
  bool overwrite_;
  std::unique_ptr<Offscreen> offscreen_;
  ui::History history_;
  ui::RunInfo counts_;  // fallbacks and deadline misses so far, as the window counts them
  ui::UiState ui_;
  std::vector<std::string> written_, notes_;
  std::string error_;
};

}  // namespace mixpilot::cli
