#include "app/instructor_app.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include <imgui.h>

#include "app/cli.hpp"
#include "app/offscreen.hpp"
#include "app/window.hpp"
#include "core/modes/make_mode.hpp"
#include "core/scenario/data_files.hpp"
#include "input/net/instructor_client.hpp"

namespace mixpilot::cli {

namespace {

namespace fs = std::filesystem;

constexpr double kKeptS = 12.0;  // [s] of telemetry kept per station: the trail, strip and plots

double steady_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// Whether a station's announced scenario name can name a shipped file: a peer's string never
// becomes a path of its choosing.
bool plain_name(const std::string& s) {
  if (s.empty() || s.size() > 100 || s.front() == '.') return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
  });
}

// What the station's tile plots: what the network carries (λ at the control rate, the
// deviation as announced) against the ball's radius.
std::vector<PlotSpec> tile_plots() {
  using R = SeriesRole;
  return {{"authority λ", {{"lambda", R::pilot}}},
          {"deviation against r [m]", {{"deviation", R::applied}, {"ball radius r", R::soft_limit}}}};
}

// The outcome of a station's result, in words: the reason, with the station's sentence when
// its newest refusal is of that reason.
std::string refusal_words(net::CommandRefusal r, const net::StationView& v) {
  const std::string reason = net::to_string(r);
  if (v.last_refusal.rfind(reason, 0) == 0) return v.last_refusal;
  return reason;
}

}  // namespace

InstructorApp::InstructorApp(InstructorAppOptions o) : options_(std::move(o)) {
  ui_.selected = options_.select;
  ui_.large = !options_.select.empty();
  auto v = std::make_shared<ui::InstructorView>();
  v->domain = options_.domain;
  v->issuer = options_.issuer;
  view_ = std::move(v);
}

InstructorApp::~InstructorApp() {
  running_ = false;
  if (thread_.joinable()) thread_.join();
}

bool InstructorApp::open(std::string& error) {
  client_ = std::make_unique<net::InstructorClient>();
  if (!client_->open({options_.domain, options_.issuer, nullptr, true}, error)) {
    // Perhaps this identity may not command: watch only, and say so.
    watch_only_ = error;
    client_ = std::make_unique<net::InstructorClient>();
    if (!client_->open({options_.domain, options_.issuer, nullptr, false}, error)) return false;
  }
  error.clear();
  {
    std::lock_guard lock(view_mutex_);
    view_ = make_view(steady_seconds());
  }
  running_ = true;
  thread_ = std::thread([this] { run(); });
  return true;
}

std::shared_ptr<const ui::InstructorView> InstructorApp::view() const {
  std::lock_guard lock(view_mutex_);
  return view_;
}

void InstructorApp::build_frame(double) {
  ImGui::GetIO().ConfigFlags |= ImGuiConfigFlags_NavEnableKeyboard;  // Tab and arrows reach every control
  const std::shared_ptr<const ui::InstructorView> v = view();
  requests_.clear();
  ui::draw_instructor(*v, ui_, requests_);
  if (requests_.empty()) return;
  asked_ += requests_.size();
  std::lock_guard lock(inbox_mutex_);
  inbox_.insert(inbox_.end(), requests_.begin(), requests_.end());
}

// --- The network thread ---------------------------------------------------------------------------

void InstructorApp::run() {
  using clock = std::chrono::steady_clock;
  auto next = clock::now();
  const auto period = std::chrono::duration_cast<clock::duration>(
      std::chrono::duration<double>(options_.period_s));
  while (running_) {
    round();
    next += period;
    const auto now = clock::now();
    if (next < now) next = now;
    // Waiting for DDS up to the next round; a round that finds nothing new is cheap.
    client_->poll(std::chrono::duration<double>(next - now).count());
    std::this_thread::sleep_until(next);
  }
}

void InstructorApp::round() {
  const double now = steady_seconds();
  client_->poll(0.0);
  take_requests();
  // Each station's telemetry since the last round: one sample at the station's time now.
  const std::int64_t system_now = net::system_ns();
  for (const net::StationView& v : client_->stations()) {
    Station& s = stations_[v.station];
    const bool fresh = v.poses != s.poses || v.lambdas != s.lambdas;
    s.poses = v.poses;
    s.lambdas = v.lambdas;
    if (!fresh) continue;
    // The announcement's time, moved on by the time since it was heard while flying.
    double t = v.t;
    if (v.state == net::StationState::flying) {
      t += std::max(0.0, double(system_now - v.heard_ns) * 1e-9);
      if (v.duration > 0) t = std::min(t, v.duration);
    }
    if (!s.samples.empty() && t < s.samples.back().t - 1.0) s.samples.clear();  // a new flight
    if (!s.samples.empty()) t = std::max(t, s.samples.back().t + 1e-6);
    Sample x;
    x.t = t;
    for (int i = 0; i < 3; ++i) x.p[i] = v.position[i];
    x.q[0] = v.orientation.w();
    x.q[1] = v.orientation.x();
    x.q[2] = v.orientation.y();
    x.q[3] = v.orientation.z();
    x.lambda = v.lambdas > 0 ? v.telemetry_lambda : v.lambda;
    x.deviation = v.deviation;
    x.bounds = v.in_force.bounds;
    s.samples.push_back(x);
    const auto old = std::find_if(s.samples.begin(), s.samples.end(),
                                  [&](const Sample& a) { return a.t >= t - kKeptS; });
    s.samples.erase(s.samples.begin(), old);
    s.changed = true;
  }
  track_commands(now);
  auto v = make_view(now);
  std::lock_guard lock(view_mutex_);
  view_ = std::move(v);
}

void InstructorApp::take_requests() {
  std::vector<ui::InstructorRequest> asked;
  {
    std::lock_guard lock(inbox_mutex_);
    asked.swap(inbox_);
  }
  const double now = steady_seconds();
  for (const ui::InstructorRequest& r : asked) {
    Command c;
    c.command = r.command;
    c.what = net::describe(r.command);
    c.asked = now;
    stations_[r.station].commands.push_back(std::move(c));
  }
}

void InstructorApp::track_commands(double now) {
  for (auto& [name, s] : stations_) {
    for (Command& c : s.commands) {
      if (c.outcome == ui::CommandOutcome::waiting_for_station) {
        if (!watch_only_.empty()) {
          c.outcome = ui::CommandOutcome::failed;
          c.why = "this window watches only: " + watch_only_;
        } else if (client_->matched(name)) {
          // Numbered above anything this issuer sent before (the CLI's numbering).
          c.sequence = client_->next_sequence();
          std::string error;
          if (client_->send(name, c.command, c.sequence, error)) {
            c.outcome = ui::CommandOutcome::sent;
            c.issued_ns = client_->last_issued_ns();
            c.sent = now;
          } else {
            c.outcome = ui::CommandOutcome::failed;
            c.why = error;
          }
        } else if (now - c.asked > options_.answer_s) {
          c.outcome = ui::CommandOutcome::failed;
          c.why = client_->station(name)
                      ? "the station's command reader never matched this window's writer "
                        "(DDS Security may refuse one of them)"
                      : "the station was not heard";
        }
      }
      if (c.outcome == ui::CommandOutcome::sent) {
        if (const auto r = client_->result(name, c.sequence, c.issued_ns)) {
          if (*r == net::CommandRefusal::none) {
            c.outcome = ui::CommandOutcome::accepted;
          } else {
            c.outcome = ui::CommandOutcome::refused;
            c.why = refusal_words(*r, *client_->station(name));
          }
        } else if (now - c.sent > options_.answer_s) {
          c.outcome = ui::CommandOutcome::no_answer;
          char why[96];
          std::snprintf(why, sizeof why, "the station did not announce a result within %g s",
                        options_.answer_s);
          c.why = why;
        }
      }
    }
    // The newest 32 are enough to show.
    if (s.commands.size() > 32) s.commands.erase(s.commands.begin(), s.commands.end() - 32);
  }
}

const InstructorApp::SceneEntry& InstructorApp::scene_for(const std::string& scenario) {
  if (const auto it = scenes_.find(scenario); it != scenes_.end()) return it->second;
  SceneEntry& e = scenes_[scenario];
  std::string path;
  if (plain_name(scenario)) {
    for (const char* folder : {"scenarios/", "scenarios/lessons/"}) {
      const std::string p = data_file(folder + scenario + ".toml");
      std::error_code ec;
      if (!p.empty() && fs::is_regular_file(p, ec)) {
        path = p;
        break;
      }
    }
  }
  if (path.empty()) {
    e.note = "scenario " + scenario + " is not a shipped one: no reference or obstacles";
    return e;
  }
  std::string error;
  const std::unique_ptr<Mode> mode = load_mode(path, ModeRequest{}, error);
  if (!mode || mode->scenario_name() != scenario || mode->view().view != ViewKind::arena_3d) {
    e.note = "scenario " + scenario + " could not be shown here" + (error.empty() ? "" : ": " + error);
    return e;
  }
  auto scene = std::make_shared<ui::Scene>(ui::scene_of(*mode, ""));
  scene->plots = tile_plots();
  e.scene = std::move(scene);
  return e;
}

std::shared_ptr<const ui::InstructorView> InstructorApp::make_view(double now) {
  auto out = std::make_shared<ui::InstructorView>();
  out->domain = options_.domain;
  out->issuer = options_.issuer;
  out->security = options_.security.empty() ? "no DDS Security" : "DDS Security (" + options_.security + ")";
  out->can_command = watch_only_.empty();
  if (!watch_only_.empty()) {
    out->status = "watching only: " + watch_only_;
    out->status_is_error = true;
  }
  if (!client_) return out;
  const std::int64_t system_now = net::system_ns();
  for (const net::StationView& v : client_->stations()) {
    Station& s = stations_[v.station];
    ui::StationTile t;
    t.name = v.station;
    t.trainee = v.trainee;
    t.scenario = v.scenario;
    t.mode = v.mode;
    t.state = net::to_string(v.state);
    t.accepts_instructor = v.accepts_instructor;
    t.security = net::to_string(v.security);
    t.t = v.t;
    t.duration = v.duration;
    t.lambda = v.lambda;
    t.deviation = v.deviation;
    t.time_in_ball = v.time_in_ball;
    t.mean_lambda = v.mean_lambda;
    // What is in force, its times run down since the announcement while the station flies (an
    // announcement comes twice a second, and at once when something starts or ends).
    t.in_force = v.in_force;
    if (v.state == net::StationState::flying) {
      const double since = std::max(0.0, double(system_now - v.heard_ns) * 1e-9);
      t.in_force.gust_left = std::max(0.0, t.in_force.gust_left - since);
      t.in_force.input_loss_left = std::max(0.0, t.in_force.input_loss_left - since);
    }
    t.accepted = v.accepted;
    t.refused = v.refused_total();
    t.last_refusal = v.last_refusal;
    t.heard_ago = std::max(0.0, double(system_now - v.heard_ns) * 1e-9);
    t.telemetry = v.poses > 0;
    const SceneEntry& scene = scene_for(v.scenario);
    t.scene = scene.scene;
    t.scene_note = scene.note;
    if (s.changed || !s.history) {
      // The samples as the app's screen draws telemetry: the position and attitude as a
      // Crazyflie-like state (p, q), the reference point at the station's time, λ, and the
      // channels the tile plots.
      auto h = std::make_shared<ui::History>(std::max<std::size_t>(1, s.samples.size()));
      const double r = t.scene ? t.scene->ball_radius : 0.0;
      std::int64_t step = 0;
      for (const Sample& a : s.samples) {
        Telemetry x;
        x.mode = ModeKind::mixed_initiative;
        x.step = step++;
        x.t = a.t;
        x.x = Eigen::VectorXd::Zero(13);
        x.x << a.p[0], a.p[1], a.p[2], a.q[0], a.q[1], a.q[2], a.q[3], 0, 0, 0, 0, 0, 0;
        if (t.scene && t.scene->reference_at) {
          // Element by element: GCC 12 takes Eigen's vectorized 3 → X copy for an overread.
          const Eigen::Vector3d ref = t.scene->reference_at(a.t);
          x.reference.resize(3);
          x.reference << ref(0), ref(1), ref(2);
        }
        x.lambda = a.lambda;
        x.instructor.bounds = a.bounds;
        x.set_channel(0, "lambda", "", a.lambda);
        x.set_channel(1, "deviation", "m", a.deviation);
        x.set_channel(2, "ball radius r", "m", r);
        h->push(x);
      }
      s.history = std::move(h);
      s.changed = false;
    }
    t.history = s.history;
    for (const Command& c : s.commands)
      t.commands.push_back({c.command.kind, c.what, c.outcome, c.why, now - c.asked});
    for (const net::CommandResultView& r : v.recent)
      t.announced.push_back({r.issuer, r.sequence, r.result == net::CommandRefusal::none,
                             net::to_string(r.result)});
    out->stations.push_back(std::move(t));
  }
  // Commands to stations not (or no longer) announced still show what became of them.
  for (const auto& [name, s] : stations_) {
    if (s.commands.empty() || client_->station(name)) continue;
    ui::StationTile t;
    t.name = name;
    t.state = "not heard";
    for (const Command& c : s.commands)
      t.commands.push_back({c.command.kind, c.what, c.outcome, c.why, now - c.asked});
    out->stations.push_back(std::move(t));
  }
  std::sort(out->stations.begin(), out->stations.end(),
            [](const ui::StationTile& a, const ui::StationTile& b) { return a.name < b.name; });
  return out;
}

// --- The window, or its screenshots headless ------------------------------------------------------

int run_instruct_window(const InstructWindowOptions& o, std::string& error) {
  InstructorApp app(o.app);
  if (!app.open(error)) return kExitError;
  const double opened = steady_seconds();
  if (!o.headless) {
    WindowOptions wo;
    wo.width = o.width;
    wo.height = o.height;
    wo.scale = o.scale;
    wo.overwrite = o.overwrite;
    wo.title = "mixpilot instruct";
    for (const InstructWindowOptions::Shot& s : o.screenshots) wo.screenshots.push_back({s.t, s.path});
    WindowContent c;
    c.build_frame = [&app](double dt) { app.build_frame(dt); };
    c.shown_time = [opened] { return steady_seconds() - opened; };
    std::vector<std::string> shots;
    if (!run_window(c, wo, shots, error)) return kExitError;
    for (const std::string& p : shots) std::printf("  screenshot %s\n", p.c_str());
    return kExitOk;
  }
  Offscreen screen;
  if (!screen.open(o.width, o.height, error, o.scale > 0 ? o.scale : 1.0f)) return kExitError;
  // The clock starts once `count` stations are heard with their telemetry.
  double start = opened;
  if (o.count > 0) {
    for (;;) {
      int heard = 0;
      for (const ui::StationTile& t : app.view()->stations) heard += t.telemetry ? 1 : 0;
      if (heard >= o.count) break;
      if (steady_seconds() - opened > o.wait_s || interrupted()) {
        char buf[160];
        std::snprintf(buf, sizeof buf, "%d of %d stations heard within %g s on domain %u", heard,
                      o.count, o.wait_s, unsigned(o.app.domain));
        error = buf;
        return 5;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    start = steady_seconds();
  }
  std::vector<InstructWindowOptions::Shot> shots = o.screenshots;
  std::sort(shots.begin(), shots.end(), [](const auto& a, const auto& b) { return a.t < b.t; });
  for (const InstructWindowOptions::Shot& s : shots) {
    // Layout frames (nothing rendered) until the shot's time, then its frame rendered.
    while (steady_seconds() - start < s.t && !interrupted()) {
      screen.layout([&] { app.build_frame(0.1); }, 0.1f);
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    if (interrupted()) {
      error = "interrupted";
      return kExitError;
    }
    screen.frame([&] { app.build_frame(0.0); });
    screen.frame([&] { app.build_frame(0.0); });  // auto-sized windows settle in a frame
    if (!write_file(s.path, screen.png(), o.overwrite, error)) return kExitError;
    std::printf("  screenshot %s\n", s.path.c_str());
  }
  return kExitOk;
}

}  // namespace mixpilot::cli
