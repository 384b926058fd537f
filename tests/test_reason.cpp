// Why λ fell (SPEC §10, read from §5.4): each mixed-initiative step says what decided its λ.
// The recorded d_res and node reproduce λ by §5.4's formula from the previous step's recorded
// prediction; a scripted unplug and a probe show their caps; the reason is recorded, read back
// by a replay bit for bit, and absent (not an error) in recordings older than its topic; the
// HUD says it in words and the arena draws the prediction that caused it.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <imgui.h>
#include <imgui_internal.h>

#include "app/cli.hpp"
#include "app/offscreen.hpp"
#include "core/control/ph_index.hpp"
#include "core/modes/make_mode.hpp"
#include "core/modes/mi_mode.hpp"
#include "core/modes/session.hpp"
#include "core/recording/mcap.hpp"
#include "core/recording/recording.hpp"
#include "core/recording/replay.hpp"
#include "core/recording/session_recording.hpp"
#include "core/scenario/scenario_toml.hpp"
#include "input/device_pilot.hpp"
#include "models/mikrokopter.hpp"
#include "ui/panels.hpp"
#include "ui/reason.hpp"
#include "ui/scene.hpp"
#include "ui/screen.hpp"
#include "ui/theme.hpp"

#include "scripted_pad.hpp"
#include "temp_files.hpp"
#include "ui_layout.hpp"

namespace mixpilot {
namespace {

namespace fs = std::filesystem;
const std::string kHelix = std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/mi_helix.toml";

struct Keep : TelemetrySink {
  std::vector<Telemetry> steps;
  void on_sample(const Telemetry& s) override { steps.push_back(s); }
};

// A flight of mi_helix, recorded to `file` and kept step by step.
struct Recorded {
  std::unique_ptr<Mode> mode;
  std::vector<Telemetry> steps;
  std::string path;
  const MiMode& mi() const { return static_cast<const MiMode&>(*mode); }
};

Recorded record(const std::string& file, ModeRequest request) {
  Recorded r;
  std::string error;
  r.mode = load_mode(kHelix, std::move(request), error);
  EXPECT_TRUE(r.mode) << error;
  if (!r.mode) return r;
  r.path = test::fresh_path("reason", file).string();
  RecordingSink sink;
  SessionInfo info{"mixed_initiative", "", kHelix, 1, r.mode->identity().pilot};
  EXPECT_TRUE(read_text_file(kHelix, info.scenario, error)) << error;
  info.assist = r.mode->identity().probe ? "off" : "on";
  EXPECT_TRUE(sink.open(r.path, *r.mode, info, error)) << error;
  Keep keep;
  Session session(*r.mode);
  session.add_sink(&sink);
  session.add_sink(&keep);
  session.run();
  EXPECT_TRUE(sink.close(error)) << error;
  r.steps = std::move(keep.steps);
  return r;
}

ModeRequest pilot(const char* name, Assistance assist = Assistance::on,
                  std::optional<double> duration = {}) {
  ModeRequest request;
  request.pilot_name = name;
  request.assist = assist;
  request.duration = duration;
  return request;
}

// The novice's whole flight of mi_helix, recorded once for the tests that read it.
const Recorded& novice() {
  static const Recorded r = record("novice.mcap", pilot("novice"));
  return r;
}

RecordingContents read(const std::string& path) {
  std::string error;
  auto rec = read_recording(path, error);
  EXPECT_TRUE(rec) << error;
  return rec ? std::move(*rec) : RecordingContents{};
}

double norm_at(const PredictionMsg& p, int i) {
  const auto j = std::size_t(3 * i);
  return (Eigen::Vector3d(p.position[j], p.position[j + 1], p.position[j + 2]) -
          Eigen::Vector3d(p.reference[j], p.reference[j + 1], p.reference[j + 2]))
      .norm();
}

// (a) Every step of the novice's flight: λ_k = ph_lambda(d_res) (SPEC §5.4), d_res the norm
// at node i* of step k − 1's recorded prediction (λ_k is computed from the previous solution's
// prediction, MiController::step), the largest over nodes 0..N_b and first reached at i*; the
// direction the unit gap there; nothing capped.
TEST(Reason, EveryStepOfANoviceFlightReproducesLambdaFromTheRecordedPrediction) {
  const Recorded& f = novice();
  ASSERT_TRUE(f.mode);
  const RecordingContents rec = read(f.path);
  const PhIndexSettings& ph = f.mi().scenario().controller.ph;
  const double dt = f.mode->dt();
  ASSERT_EQ(rec.reasons.size(), rec.states.size());
  ASSERT_EQ(rec.reasons.size(), std::size_t(f.mode->steps_total()));
  ASSERT_EQ(rec.predictions.size(), rec.states.size());
  // The first step: no prediction yet, λ initial.
  EXPECT_EQ(rec.reasons[0].node, -1);
  EXPECT_EQ(rec.reasons[0].lambda, ph.initial_lambda);
  EXPECT_EQ(rec.reasons[0].cap, std::uint8_t(LambdaCap::none));
  int low = 0;
  for (std::size_t k = 1; k < rec.reasons.size(); ++k) {
    const LambdaReasonMsg& r = rec.reasons[k];
    ASSERT_EQ(r.step, k);
    ASSERT_EQ(r.cap, std::uint8_t(LambdaCap::none)) << k;
    ASSERT_EQ(r.lambda, rec.lambda[k].lambda) << k;
    ASSERT_NEAR(ph_lambda(r.d_res, ph), r.lambda, 1e-12) << k;
    ASSERT_EQ(r.ph_index, r.lambda) << k;
    const PredictionMsg& before = rec.predictions[k - 1];
    ASSERT_EQ(before.step, k - 1);
    ASSERT_GE(r.node, 0);
    ASSERT_LE(r.node, ph.N_b);
    ASSERT_EQ(r.d_res, norm_at(before, r.node)) << k;
    for (int i = 0; i <= ph.N_b; ++i) {
      if (i < r.node) {
        ASSERT_LT(norm_at(before, i), r.d_res) << k << " node " << i;
      } else {
        ASSERT_LE(norm_at(before, i), r.d_res) << k << " node " << i;
      }
    }
    ASSERT_EQ(r.ahead, r.node * dt);
    const auto j = std::size_t(3 * r.node);
    for (std::size_t c = 0; c < 3; ++c)
      ASSERT_NEAR(r.direction[c] * r.d_res, before.position[j + c] - before.reference[j + c], 1e-15);
    low += r.lambda < ui::kReasonLambda;
  }
  // The novice does lose authority (SPEC §5.4): the reasons above explain real takeovers.
  EXPECT_GT(low, 100);
  // The telemetry the recording was made from says the same.
  for (std::size_t k = 0; k < f.steps.size(); ++k) {
    const LambdaReason& t = f.steps[k].reason;
    ASSERT_EQ(t.d_res, rec.reasons[k].d_res);
    ASSERT_EQ(t.node, rec.reasons[k].node);
  }
}

using test::ScriptedPad;

// (b) The gamepad unplugged at step 100 and plugged back at 300, sticks centred: from the unplug
// the cap is the input's (λ = 0: the planner flies), until the authority has returned above the
// PH index; the recording says so too.
TEST(Reason, AScriptedUnplugShowsTheInputLostCap) {
  ScriptedPad pad;
  pad.r.alive_ns = input::steady_ns() + 3'600'000'000'000;  // alive throughout
  pad.from = 100;
  pad.to = 300;
  input::InputSettings settings;
  ModeRequest request = pilot("", Assistance::on, 7.5);
  request.pilot_source = std::make_unique<input::DevicePilot>(
      pad, settings, 0.015, models::MikroKopter().hover_speed());
  const Recorded f = record("unplug.mcap", std::move(request));
  ASSERT_TRUE(f.mode);
  ASSERT_EQ(f.steps.size(), 500u);
  const RecordingContents rec = read(f.path);
  ASSERT_EQ(rec.reasons.size(), f.steps.size());
  for (std::size_t k = 1; k < 100; ++k) EXPECT_EQ(f.steps[k].reason.cap, LambdaCap::none) << k;
  for (std::size_t k = 100; k < 300; ++k) {
    const Telemetry& s = f.steps[k];
    ASSERT_EQ(s.pilot.input, InputState::lost) << k;
    ASSERT_EQ(s.lambda, 0.0) << k;
    ASSERT_EQ(s.reason.cap, LambdaCap::input_lost) << k;
    // The PH index is still read from the prediction: what λ would have been.
    ASSERT_GE(s.reason.node, 0);
    ASSERT_EQ(s.reason.ph_index, ph_lambda(s.reason.d_res, f.mi().scenario().controller.ph));
    ASSERT_EQ(rec.reasons[k].cap, std::uint8_t(LambdaCap::input_lost)) << k;
    ASSERT_EQ(rec.reasons[k].lambda, 0.0);
    ASSERT_EQ(ui::reason_text(s, 0.175), "input lost: the planner flies");
    ASSERT_TRUE(ui::reason_matters(s));
  }
  // Back: re-centred (already), the authority returns; the cap binds while it is below the PH
  // index, then the index decides again.
  std::size_t k = 300;
  while (k < f.steps.size() && f.steps[k].reason.cap == LambdaCap::input_lost) {
    EXPECT_LT(f.steps[k].pilot.authority, f.steps[k].reason.ph_index) << k;
    EXPECT_EQ(f.steps[k].lambda, f.steps[k].pilot.authority) << k;
    ++k;
  }
  ASSERT_LT(k, f.steps.size()) << "the authority never came back";
  EXPECT_GT(k, 300u + std::size_t(input::kRecentreHoldS / 0.015));
  for (; k < f.steps.size(); ++k) {
    ASSERT_EQ(f.steps[k].reason.cap, LambdaCap::none) << k;
    ASSERT_EQ(f.steps[k].lambda, f.steps[k].reason.ph_index) << k;
  }
}

// (c) A probe (SPEC §10): every step's λ is the cap (1), said as the probe's; the PH index is
// still computed from each prediction, and not applied.
TEST(Reason, AProbeShowsTheProbeCap) {
  const Recorded f = record("probe.mcap", pilot("novice", Assistance::off, 6.0));
  ASSERT_TRUE(f.mode);
  const PhIndexSettings& ph = f.mi().scenario().controller.ph;
  int below = 0;
  for (const Telemetry& s : f.steps) {
    ASSERT_EQ(s.lambda, 1.0);
    ASSERT_EQ(s.reason.cap, LambdaCap::probe) << s.step;
    if (s.step > 0) {
      ASSERT_EQ(s.reason.ph_index, ph_lambda(s.reason.d_res, ph));
    }
    below += s.reason.ph_index < ui::kReasonLambda;
    ASSERT_TRUE(ui::reason_matters(s));
    ASSERT_EQ(ui::reason_text(s, ph.r), "probe flight: you fly alone");
  }
  EXPECT_GT(below, 0) << "assisted, the planner would have taken over somewhere";
  const RecordingContents rec = read(f.path);
  ASSERT_EQ(rec.reasons.size(), f.steps.size());
  for (const LambdaReasonMsg& r : rec.reasons) ASSERT_EQ(r.cap, std::uint8_t(LambdaCap::probe));
}

// A replay of `path` flown through a session with its check; the replay's telemetry.
struct Replayed {
  std::vector<Telemetry> steps;
  bool matches = false;
  std::string difference;
};

Replayed replay(const std::string& path) {
  Replayed out;
  std::string error, text;
  auto rec = read_recording(path, error);
  EXPECT_TRUE(rec) << error;
  if (!rec) return out;
  const std::string* scenario = embedded_scenario(*rec, path, error);
  EXPECT_TRUE(scenario) << error;
  if (!scenario) return out;
  auto mode = replay_mode(*rec, path, *scenario, kHelix, std::nullopt, error);
  EXPECT_TRUE(mode) << error;
  if (!mode) return out;
  ReplayCheck check(*rec);
  Keep keep;
  Session session(*mode);
  session.add_sink(&check);
  session.add_sink(&keep);
  session.run();
  out.steps = std::move(keep.steps);
  out.matches = check.matches(mode->steps_done());
  out.difference = check.first_difference(mode->steps_done());
  return out;
}

// `in` without the /controller/lambda_reason topic: a recording made before it existed.
void drop_reason_topic(const std::string& in, const std::string& out) {
  std::string error;
  const auto file = read_mcap(in, error);
  ASSERT_TRUE(file) << error;
  McapWriter w;
  ASSERT_TRUE(w.open(out, error)) << error;
  std::map<std::uint16_t, std::uint16_t> channel;  // old id → new id
  for (const auto& [id, ch] : file->channels) {
    if (ch.topic == "/controller/lambda_reason") continue;
    const McapSchema& s = file->schemas.at(ch.schema_id);
    channel[id] = w.add_channel(w.add_schema(s.name, s.encoding, s.data), ch.topic,
                                ch.message_encoding, ch.metadata);
  }
  for (const McapMetadata& m : file->metadata)
    if (m.name == "mixpilot") w.write_metadata(m.name, m.metadata);
  for (const McapMessage& m : file->messages) {
    const auto it = channel.find(m.channel_id);
    if (it != channel.end()) {
      ASSERT_TRUE(w.write_message(it->second, m.sequence, m.log_time, m.publish_time, file->data(m)));
    }
  }
  for (const McapMetadata& m : file->metadata)
    if (m.name != "mixpilot") w.write_metadata(m.name, m.metadata);
  ASSERT_TRUE(w.close(error)) << error;
}

// (d) Recorded, replayed: the replay's telemetry carries the recorded reason bit for bit, and
// its check compares it. A recording without the topic (older than it) still replays, its
// reasons absent from what was read; the replay computes the same ones afresh.
TEST(Reason, SurvivesRecordAndReplay) {
  const Recorded f = record("replayed.mcap", pilot("novice", Assistance::on, 10.0));
  ASSERT_TRUE(f.mode);
  const RecordingContents rec = read(f.path);
  const Replayed r = replay(f.path);
  EXPECT_TRUE(r.matches) << r.difference;
  ASSERT_EQ(r.steps.size(), rec.reasons.size());
  for (std::size_t k = 0; k < r.steps.size(); ++k) {
    const LambdaReason& t = r.steps[k].reason;
    const LambdaReasonMsg& m = rec.reasons[k];
    ASSERT_EQ(t.d_res, m.d_res) << k;
    ASSERT_EQ(t.node, m.node) << k;
    ASSERT_EQ(t.ph_index, m.ph_index) << k;
    ASSERT_EQ(t.ahead, m.ahead) << k;
    ASSERT_EQ(std::uint8_t(t.cap), m.cap) << k;
    for (int c = 0; c < 3; ++c) ASSERT_EQ(t.direction(c), m.direction[std::size_t(c)]) << k;
    ASSERT_EQ(t, f.steps[k].reason) << k;
  }

  // A recording whose reason differs is caught by the check.
  {
    RecordingContents edited = read(f.path);
    edited.reasons[200].node += 1;
    ReplayCheck check(edited);
    for (const Telemetry& s : r.steps) check.on_sample(s);
    EXPECT_FALSE(check.matches(std::int64_t(r.steps.size())));
    EXPECT_EQ(check.first_difference(std::int64_t(r.steps.size())),
              "the lambda reason of step 200 differs from the recorded one");
  }

  const std::string old = test::fresh_path("reason", "old.mcap").string();
  drop_reason_topic(f.path, old);
  const RecordingContents without = read(old);
  EXPECT_TRUE(without.reasons.empty());
  EXPECT_EQ(without.message_counts.count("/controller/lambda_reason"), 0u);
  EXPECT_EQ(without.states.size(), rec.states.size());
  const Replayed again = replay(old);
  EXPECT_TRUE(again.matches) << again.difference;
  ASSERT_EQ(again.steps.size(), r.steps.size());
  for (std::size_t k = 0; k < r.steps.size(); ++k) ASSERT_EQ(again.steps[k].reason, r.steps[k].reason);
}

// (e) The HUD's words, for each kind of reason.
TEST(Reason, TheHudSaysItInWords) {
  Telemetry s;
  s.mode = ModeKind::mixed_initiative;
  s.solved = true;
  s.t = 3.0;
  s.lambda = 0.28;
  s.reason.node = 8;
  s.reason.ahead = 0.12;
  s.reason.d_res = 0.235;
  s.reason.direction = Eigen::Vector3d(0.6, 0.8, 0.0);
  const double r = 0.175;
  EXPECT_EQ(ui::reason_text(s, r), "planner 72 %: you would leave the ball by 0.06 m in 0.12 s");
  s.reason.direction = Eigen::Vector3d(0.0, 0.6, -0.8);
  EXPECT_EQ(ui::reason_text(s, r),
            "planner 72 %: you would leave the ball by 0.06 m in 0.12 s (too low)");
  s.reason.node = 0;
  s.reason.ahead = 0.0;
  EXPECT_EQ(ui::reason_text(s, r), "planner 72 %: you are out of the ball by 0.06 m (too low)");
  // On the edge, to the centimetre: no "by 0.00 m".
  s.reason.node = 10;
  s.reason.ahead = 0.15;
  s.reason.d_res = 0.178;
  s.reason.direction = Eigen::Vector3d(1.0, 0.0, 0.0);
  EXPECT_EQ(ui::reason_text(s, r), "planner 72 %: you would reach the ball's edge in 0.15 s");
  // Inside the ball: how far from the reference.
  s.lambda = 0.65;
  s.reason.node = 5;
  s.reason.ahead = 0.075;
  s.reason.d_res = 0.0912;
  s.reason.direction = Eigen::Vector3d(0.0, 0.0, 1.0);
  EXPECT_EQ(ui::reason_text(s, r),
            "planner 35 %: you would be 0.09 m off the reference in 0.075 s (too high)");
  s.reason.direction = Eigen::Vector3d(1.0, 0.0, 0.0);
  s.reason.d_res = 0.0791;
  EXPECT_EQ(ui::reason_text(s, r), "planner 35 %: you would be 0.08 m off the reference in 0.075 s");
  s.reason.node = 0;
  EXPECT_EQ(ui::reason_text(s, r), "planner 35 %: you are 0.08 m off the reference");
  s.reason.node = 5;
  EXPECT_TRUE(ui::reason_matters(s));
  s.lambda = 0.95;
  EXPECT_FALSE(ui::reason_matters(s));  // the pilot flies: nothing to explain

  // The caps.
  s.lambda = 0.0;
  s.reason.cap = LambdaCap::input_lost;
  s.pilot.input = InputState::lost;
  EXPECT_EQ(ui::reason_text(s, r), "input lost: the planner flies");
  s.pilot.input = InputState::recentre;
  EXPECT_EQ(ui::reason_text(s, r), "input back: centre the sticks to fly");
  s.pilot.input = InputState::returning;
  s.lambda = 0.4;
  EXPECT_EQ(ui::reason_text(s, r), "input back: control returning, planner 60 %");
  s.reason.cap = LambdaCap::probe;
  s.lambda = 1.0;
  EXPECT_EQ(ui::reason_text(s, r), "probe flight: you fly alone");
  EXPECT_TRUE(ui::reason_matters(s));
  s.reason.cap = LambdaCap::safe_hold;
  s.lambda = 0.0;
  EXPECT_EQ(ui::reason_text(s, r), "safe hold: the safe controller flies");
  // Before any prediction the initial λ = 0.5 explains nothing.
  s.reason = LambdaReason{};
  s.lambda = 0.5;
  EXPECT_FALSE(ui::reason_matters(s));
}

// The words stay kReasonHoldS after they stop mattering (no flicker), then go; the path drawn
// is the previous step's prediction, when the history has it.
TEST(Reason, TheWordsAreHeldHalfASecond) {
  ui::History h(64);
  Telemetry s;
  s.mode = ModeKind::mixed_initiative;
  s.solved = true;
  s.reason.node = 3;
  s.predicted.setZero(3, 4);
  const double dt = 0.015;
  for (int k = 0; k < 40; ++k) {
    s.step = k;
    s.t = k * dt;
    s.lambda = k == 10 ? 0.5 : 0.97;  // one step matters
    h.push(s);
    const std::optional<std::size_t> shown = ui::shown_reason(h);
    const bool held = k >= 10 && s.t - 10 * dt < ui::kReasonHoldS;
    ASSERT_EQ(shown.has_value(), held) << k;
    if (held) {
      EXPECT_EQ(h[*shown].step, 10);
      ASSERT_NE(ui::reason_prediction(h, *shown), nullptr);
      EXPECT_EQ(ui::reason_prediction(h, *shown)->step, 9);
    }
  }
  // A gap in a live flight's history: no prediction to draw rather than the wrong one.
  ui::History gap(8);
  s.step = 5;
  gap.push(s);
  s.step = 7;
  gap.push(s);
  EXPECT_EQ(ui::reason_prediction(gap, 1), nullptr);
}

std::string without_spaces(std::string s) {
  std::erase(s, ' ');
  return s;
}

// The text the window `name` drew in the last frame, read back from its draw list: each glyph
// is a quad whose texture corners are that glyph's in the font atlas (spaces draw nothing, so
// they are missing).
std::string drawn_text(const char* name) {
  const ImGuiWindow* w = ImGui::FindWindowByName(name);
  if (!w) return "";
  std::map<std::array<float, 4>, unsigned> glyphs;
  for (const ImFont* f : ImGui::GetIO().Fonts->Fonts)
    for (const ImFontGlyph& g : f->Glyphs)
      if (g.Visible) glyphs[{g.U0, g.V0, g.U1, g.V1}] = g.Codepoint;
  const ImVector<ImDrawVert>& v = w->DrawList->VtxBuffer;
  std::string out;
  for (int i = 0; i + 3 < v.Size;) {
    const auto it = glyphs.find({v[i].uv.x, v[i].uv.y, v[i + 2].uv.x, v[i + 2].uv.y});
    if (it == glyphs.end()) {
      ++i;
      continue;
    }
    out += it->second < 0x80 ? char(it->second) : '?';
    i += 4;
  }
  return out;
}

// (e) The HUD rendered headless (EGL), as the window draws it: a reckless flight at a moment the
// planner has taken over says why in the HUD, in the planner's colour, and the arena draws the
// gap η_{i*} − η^r_{i*} of the prediction λ came from; at 150 % nothing is cut.
class ReasonScreen : public testing::TestWithParam<float> {};

TEST_P(ReasonScreen, TheHudSaysWhyAndTheArenaDrawsTheGap) {
  const float scale = GetParam();
  const int W = 1280, H = 720;
  cli::Offscreen screen;
  std::string error;
  if (!screen.open(W, H, error, scale)) GTEST_SKIP() << "no EGL device: " << error;
  auto mode = load_mode(kHelix, pilot("reckless", Assistance::on, 8.0), error);
  ASSERT_TRUE(mode) << error;
  const ui::Scene scene = ui::scene_of(*mode, "reckless");
  ui::History h;
  // Fly to a step the planner has taken over at, the ball about to be left.
  while (mode->step()) {
    h.push(mode->telemetry());
    const Telemetry& s = mode->telemetry();
    if (s.t > 2.0 && s.reason.cap == LambdaCap::none && s.lambda < 0.5 && s.reason.node > 0 &&
        s.reason.d_res > scene.ball_radius + 0.006)
      break;
  }
  ASSERT_FALSE(mode->finished()) << "the reckless pilot never lost the authority";
  const Telemetry& now = h.newest();
  const std::string expected = ui::reason_text(now, scene.ball_radius);
  EXPECT_NE(expected.find("planner"), std::string::npos) << expected;

  ui::UiState st;
  ui::RunInfo run;
  run.state = ui::RunState::flying;
  for (int f = 0; f < 2; ++f)
    screen.frame([&] {
      ui::Requests ignored;
      ui::draw_screen(scene, h, run, st, ignored);
    });
  const std::string hud_text = drawn_text("##hud");
  EXPECT_NE(hud_text.find(without_spaces(expected)), std::string::npos) << hud_text;
  // The arena labels node i* with the gap and how far ahead it lies.
  char ahead[64];
  std::snprintf(ahead, sizeof ahead, "%.2fmoffthereferencein%.3gs", now.reason.d_res,
                now.reason.ahead);
  EXPECT_NE(drawn_text("##view").find(ahead), std::string::npos) << ahead;
  EXPECT_TRUE(test::layout_problems().empty()) << test::layout_problems().front();
  const std::vector<std::uint8_t> px = screen.pixels();

  // The words in the planner's colour inside the HUD.
  const ImGuiWindow* hud = ImGui::FindWindowByName("##hud");
  ASSERT_TRUE(hud);
  const auto near = [&](int x, int y, ImU32 c, int tol) {
    if (x < 0 || y < 0 || x >= W || y >= H) return false;
    const std::uint8_t* p = &px[(std::size_t(y) * W + std::size_t(x)) * 4];
    return std::abs(p[0] - int(c & 0xFF)) <= tol && std::abs(p[1] - int((c >> 8) & 0xFF)) <= tol &&
           std::abs(p[2] - int((c >> 16) & 0xFF)) <= tol;
  };
  int words = 0;
  // Below the authority bar and the shares' names under it (the planner's share is that colour
  // too, ui/screen.cpp) down to the HUD's bottom.
  const float text_top = hud->Pos.y + ImGui::GetStyle().WindowPadding.y +
                         2.0f * ImGui::GetFontSize() + ui::scaled(4) + ImGui::GetTextLineHeight();
  for (int y = int(text_top); y < int(hud->Pos.y + hud->Size.y); ++y)
    for (int x = int(hud->Pos.x); x < int(hud->Pos.x + hud->Size.x); ++x)
      words += near(x, y, ui::colour::kPlanner, 40);
  EXPECT_GT(words, 60) << "no words in the planner's colour under the authority bar";

  // The gap: the critical colour along the segment between η^r_{i*} and η_{i*} of the previous
  // step's prediction, where the arena projects it.
  const std::size_t i = *ui::shown_reason(h);
  const Telemetry* before = ui::reason_prediction(h, i);
  ASSERT_NE(before, nullptr);
  const int node = h[i].reason.node;
  ImVec2 fmin, fmax;
  ui::view_rect(ImVec2(float(W), float(H)), run, fmin, fmax);
  ImVec2 a, b;
  ASSERT_TRUE(ui::project_in_arena(scene, now, st, fmin, fmax, before->predicted_reference.col(node), a));
  ASSERT_TRUE(ui::project_in_arena(scene, now, st, fmin, fmax, before->predicted.col(node), b));
  int on_gap = 0, samples = 0;
  for (float u = 0.2f; u <= 0.8f; u += 0.05f) {
    const int x = int(a.x + u * (b.x - a.x)), y = int(a.y + u * (b.y - a.y));
    bool hit = false;
    for (int dy = -2; dy <= 2 && !hit; ++dy)
      for (int dx = -2; dx <= 2 && !hit; ++dx) hit = near(x + dx, y + dy, ui::colour::kCritical, 30);
    on_gap += hit;
    ++samples;
  }
  EXPECT_GE(on_gap, samples - 3) << "the gap segment from (" << a.x << ", " << a.y << ") to (" << b.x
                                 << ", " << b.y << ")";
  if (const char* dir = std::getenv("MIXPILOT_SHOT_DIR"))
    (void)cli::write_file(std::string(dir) + "/reason_" + std::to_string(int(scale * 100)) + ".png",
                          screen.png(), true, error);
}

INSTANTIATE_TEST_SUITE_P(Scales, ReasonScreen, testing::Values(1.0f, 1.5f));

}  // namespace
}  // namespace mixpilot
