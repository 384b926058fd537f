#pragma once
// What a linked vehicle (core/modes/linked_vehicle.hpp) does with the states of the vehicle
// behind a link (core/modes/vehicle_link.hpp) each step: take the newest state, turn each new
// one into a round-trip sample (core/control/rtt_estimator.hpp), give the horizon over which
// the state is to be predicted (SPEC §5.2, §9), and judge whether the vehicle is still worth
// flying.
//
// A vehicle is lost (Reading::lost, lost_reason()) when it
//  - says its flight has ended;
//  - went silent: no state taken for the link's timeout (the reason says whether states
//    arrived and were rejected, and the newest rejection);
//  - stops acknowledging: the first command sent after the newest one its states echo (command 0
//    before any) left more than the timeout plus kMaxRtt ago — a pause that sends nothing asks
//    for nothing;
//  - does not move: its state stays the same (every value to kStateChange, relative) for the
//    timeout while the commands acting on it changed (by kCommandChange, relative) — for the
//    models flown remotely, a change of that size moves some state value by orders of
//    magnitude more within one period, so only a vehicle that ignores its commands stays put;
//  - jumps: its position moves faster than kMaxSpeed between two states (plus kJumpSlack);
//  - echoes a command never sent, or claims one acted longer than since it left (which
//    input/net's link rejects already; here for any link).
// Where its world ends is the mode's to say (a VehicleWorld, which LinkedVehicle judges).
//
// setup() sizes; read() and send() allocate nothing.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <vector>

#include <Eigen/Core>

#include "core/control/rtt_estimator.hpp"
#include "core/modes/vehicle_link.hpp"
#include "core/numerics/stats.hpp"

namespace mixpilot {

// Where a remote vehicle may be: a ball around its start (the tracking mode's world), above a
// floor where one is set (the vehicle's own judgement: the ground z = 0, SPEC §2's z up, less
// kGroundMargin), or a box (the mixed-initiative arena grown by its margin, floor included).
// The boundary is outside: a vehicle that sits on it is not flying in the world.
struct VehicleWorld {
  // How far below the ground a vehicle may be before it has gone through it [m] (the margin
  // the mixed-initiative mode allows outside its arena).
  static constexpr double kGroundMargin = 1.0;

  static VehicleWorld ball(const Eigen::Vector3d& center, double radius,
                           double floor_z = -std::numeric_limits<double>::infinity()) {
    VehicleWorld w;
    w.center = center;
    w.radius = radius;
    w.floor_z = floor_z;
    return w;
  }
  static VehicleWorld box(const Eigen::Vector3d& min, const Eigen::Vector3d& max, double margin) {
    VehicleWorld w;
    w.box_min = min.array() - margin;
    w.box_max = max.array() + margin;
    return w;
  }
  // nullptr inside; else how the position left it.
  const char* outside(const Eigen::Vector3d& p) const {
    if (!p.allFinite()) return "its position is not finite";
    if (!(p.z() > floor_z) || !(p.z() > box_min.z())) return "it fell below the floor";
    if (!((p - center).norm() < radius)) return "it left the world";
    if (!(p.array() > box_min.array()).all() || !(p.array() < box_max.array()).all())
      return "it left the arena";
    return nullptr;
  }

  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double radius = std::numeric_limits<double>::infinity();
  double floor_z = -std::numeric_limits<double>::infinity();
  Eigen::Vector3d box_min = Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity());
  Eigen::Vector3d box_max = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
};

class VehicleFeed {
 public:
  // The longest round-trip time a prediction covers [s].
  static constexpr double kMaxRtt = 0.5;
  // Faster than any quadrotor: a position that moves more between two states jumped [m/s, m].
  static constexpr double kMaxSpeed = 300.0;
  static constexpr double kJumpSlack = 1.0;
  // A command that changes by more than this (relative to max(1, |u_i|)) must move the state
  // by more than kStateChange (relative to max(1, |x_i|)).
  static constexpr double kCommandChange = 1e-6;
  static constexpr double kStateChange = 1e-9;
  static constexpr int kMaxInputs = 8;
  // An age may exceed the time since its command left by this much (the two clocks' rates) [s].
  static constexpr double kClockTolerance = 1e-3;

  // What step k learns.
  struct Reading {
    const VehicleSample* sample = nullptr;  // the state read (the link's, valid for this step)
    bool heard = false;      // a state of the right size has arrived (else: the start state)
    bool fresh = false;      // it is new since the last step, and it echoes a command
    double sigma = 0.0;      // fresh: when it was measured on the controller's clock, t_j + a [s]
    double silent_s = 0.0;   // since the newest state arrived (since command 0 before any) [s]
    int horizon_substeps = 0;  // the prediction horizon
    bool lost = false;         // the vehicle is lost: lost_reason() says why
  };

  // dt: control period; h: the predictor's substep; `samples`: round-trip samples kept for
  // the median (more are counted in the estimate, not kept).
  void setup(int nx, double dt, double h, int max_substeps, std::size_t samples) {
    nx_ = nx;
    dt_ = dt;
    h_ = h;
    max_substeps_ = max_substeps;
    rtt_.reset();
    samples_.clear();
    samples_.reserve(samples);
    last_serial_ = 0;
    t0_ns_ = 0;
    reason_[0] = '\0';
    rejected_at_take_ = 0;
    acked_ = false;
    has_position_ = false;
    run_valid_ = false;
    last_u_valid_ = false;
    changed_.fill(false);
    sent_stamps_.fill(0);
    sent_ = 0;
  }

  // Step k at `now` (link.now_ns()); substeps_per_period: of the predictor.
  Reading read(VehicleLink& link, std::int64_t k, std::int64_t now, int substeps_per_period) {
    if (k == 0) t0_ns_ = now;
    // Read once: the link may hand over a newer state at any call.
    const VehicleSample& v = link.latest();
    Reading r;
    r.sample = &v;
    r.heard = v.serial != 0 && v.x.size() == nx_;
    if (r.heard && v.serial != last_serial_) {
      last_serial_ = v.serial;
      rejected_at_take_ = link.rejected();
      if (v.command >= 0) {
        // τ = t_recv − T_j − a (core/control/rtt_estimator.hpp)
        const double tau = 1e-9 * double(v.received_ns - v.command_stamp_ns) - v.command_age_s;
        if (rtt_.add(tau) && samples_.size() < samples_.capacity()) samples_.push_back(tau);
        r.fresh = true;
        // Never later than now, whatever age a link lets through.
        r.sigma = std::min(double(v.command) * dt_ + v.command_age_s, double(k) * dt_);
      }
      judge_new(v, link.timeout_s(), r);
    }
    r.silent_s = 1e-9 * double(now - (r.heard ? std::max(v.received_ns, t0_ns_) : t0_ns_));
    if (!r.lost) judge_time(link, v, r.heard, k, now, r);
    // A vehicle that has applied no command yet rests until command 0 acts (σ = 0): the whole
    // history is predicted. Else the estimate plus the time the state waited here.
    if (!r.heard || v.command < 0) {
      r.horizon_substeps = int(std::min<std::int64_t>(k * substeps_per_period, max_substeps_));
    } else {
      const double wait = 1e-9 * double(now - v.received_ns);
      r.horizon_substeps =
          std::clamp(int(std::lround((rtt_.estimate() + wait) / h_)), 0, max_substeps_);
    }
    horizon_substeps_ = r.horizon_substeps;
    return r;
  }

  // Command k leaves through the link now (the feed notes whether it changed).
  void send(VehicleLink& link, std::int64_t k, std::int64_t now, const double* u, int nu) {
    nu = std::clamp(nu, 0, kMaxInputs);
    bool changed = false;
    for (int i = 0; i < nu; ++i) {
      const double tol = kCommandChange * std::max(1.0, std::abs(last_u_[std::size_t(i)]));
      changed = changed || !(std::abs(u[i] - last_u_[std::size_t(i)]) <= tol);
      last_u_[std::size_t(i)] = u[i];
    }
    changed_[std::size_t(k % kChangeRing)] = last_u_valid_ && changed;
    sent_stamps_[std::size_t(k % kChangeRing)] = now;
    sent_ = k + 1;
    last_u_valid_ = true;
    link.send(k, now, u, nu);
  }

  // Why the vehicle was lost ("" while it is not).
  const char* lost_reason() const { return reason_; }

  const RttEstimator& rtt() const { return rtt_; }
  // The median of the samples kept [s] (0 without any). Allocates: not for the loop.
  double measured_median() const { return percentile(samples_, 0.5); }
  std::size_t sample_count() const { return samples_.size(); }
  double horizon_s() const { return double(horizon_substeps_) * h_; }

 private:
  static constexpr int kChangeRing = 128;  // steps whose command change and stamp are remembered
  using StateVector = VehicleSample::StateVector;

  template <class... Args>
  void lose(Reading& r, const char* format, Args... args) {
    r.lost = true;
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wformat-nonliteral"
#pragma GCC diagnostic ignored "-Wformat-security"
    std::snprintf(reason_, sizeof reason_, format, args...);
#pragma GCC diagnostic pop
  }

  // A new state: ended, jumped, or still for too long.
  void judge_new(const VehicleSample& v, double timeout, Reading& r) {
    if (v.ended) return lose(r, "it ended its flight (status 2) before the controller did");
    if (v.command >= sent_)
      return lose(r, "it echoes step %lld, which was never sent (%lld sent)",
                  static_cast<long long>(v.command), static_cast<long long>(sent_));
    if (v.command >= 0) {
      const double since_sent = 1e-9 * double(v.received_ns - v.command_stamp_ns);
      if (!(v.command_age_s <= since_sent + kClockTolerance))
        return lose(r, "its state claims step %lld had acted %.3g s, but that command left "
                       "only %.3g s before the state arrived",
                    static_cast<long long>(v.command), v.command_age_s, since_sent);
    }
    // Positions at the controller's times T_j + a (before any command: at rest, t0).
    const double t = v.command >= 0 ? 1e-9 * double(v.command_stamp_ns - t0_ns_) + v.command_age_s
                                    : 0.0;
    const Eigen::Vector3d p = v.x.head<3>();
    if (has_position_) {
      const double moved = (p - position_).norm(), in = std::max(0.0, t - position_t_);
      if (!(moved <= kMaxSpeed * in + kJumpSlack))
        return lose(r, "its position jumped %.3g m in %.3g s: faster than %.3g m/s, no vehicle "
                       "moves so",
                    moved, in, kMaxSpeed);
    }
    has_position_ = true;
    position_ = p;
    position_t_ = t;
    if (v.command < 0) return;
    // Still: the same state as at the start of the run, while the commands acting changed.
    bool same = run_valid_;
    for (int i = 0; same && i < nx_; ++i)
      same = std::abs(v.x(i) - run_x_(i)) <= kStateChange * std::max(1.0, std::abs(run_x_(i)));
    if (!same) {
      run_valid_ = true;
      run_x_ = v.x;
      run_since_ns_ = v.received_ns;
      run_step_ = run_checked_ = v.command;
      run_commands_changed_ = false;
      return;
    }
    // Commands run_step_+1 .. v.command−1 acted wholly within the run.
    for (std::int64_t c = std::max(run_checked_ + 1, v.command - kChangeRing + 1); c < v.command;
         ++c)
      run_commands_changed_ = run_commands_changed_ || changed_[std::size_t(c % kChangeRing)];
    run_checked_ = std::max(run_checked_, v.command - 1);
    const double still = 1e-9 * double(v.received_ns - run_since_ns_);
    if (run_commands_changed_ && still > timeout)
      return lose(r, "it does not move: its state has stayed the same for %.2f s while the "
                     "commands it acknowledged changed",
                  still);
  }

  // Silence and acknowledgements, against the controller's clock.
  void judge_time(const VehicleLink& link, const VehicleSample& v, bool heard, std::int64_t k,
                  std::int64_t now, Reading& r) {
    const double timeout = link.timeout_s();
    if (r.silent_s > timeout) {
      const std::uint64_t rejected = link.rejected() - (heard ? rejected_at_take_ : 0);
      if (rejected == 0)
        return lose(r, "it went silent (no state for %.2f s)", r.silent_s);
      char why[192];
      link.describe_rejection(why, sizeof why);
      return lose(r, "no state taken for %.2f s: %llu arrived and were rejected (the newest as %s)",
                  r.silent_s, static_cast<unsigned long long>(rejected), why);
    }
    if (k == 0 || !heard) return;
    if (v.command >= 0) acked_ = true;
    // The first command it has not acknowledged, if one was sent (beyond the ring: long ago).
    if (v.command >= sent_ - 1) return;
    const std::int64_t next = std::max<std::int64_t>(v.command + 1, 0);
    const double unacked =
        sent_ - next > kChangeRing
            ? std::numeric_limits<double>::infinity()
            : 1e-9 * double(now - sent_stamps_[std::size_t(next % kChangeRing)]);
    if (unacked <= timeout + kMaxRtt) return;
    if (!acked_)
      return lose(r, "it never acknowledged a command: %.2f s after command 0 left, its states "
                     "still echo none",
                  unacked);
    if (unacked > 1e3)
      return lose(r, "it stopped acknowledging commands: step %lld, the first after the newest "
                     "it echoes, left more than %d steps ago",
                  static_cast<long long>(next), kChangeRing);
    lose(r, "it stopped acknowledging commands: step %lld, the first after the newest it echoes, "
            "left %.2f s ago",
         static_cast<long long>(next), unacked);
  }

  int nx_ = 0;
  double dt_ = 0.0, h_ = 0.0;
  int max_substeps_ = 0;
  RttEstimator rtt_;
  std::vector<double> samples_;  // round-trip samples [s], reserved
  std::uint64_t last_serial_ = 0;
  std::int64_t t0_ns_ = 0;        // the stamp of command 0
  int horizon_substeps_ = 0;

  char reason_[384] = "";
  std::uint64_t rejected_at_take_ = 0;  // the link's rejections when the newest state was taken
  bool acked_ = false;                  // some state has echoed a command
  bool has_position_ = false;           // the newest state's position and its time [s]
  Eigen::Vector3d position_ = Eigen::Vector3d::Zero();
  double position_t_ = 0.0;
  // The run of states equal to run_x_ since run_since_ns_, from the one echoing run_step_.
  bool run_valid_ = false;
  StateVector run_x_;
  std::int64_t run_since_ns_ = 0, run_step_ = 0, run_checked_ = 0;
  bool run_commands_changed_ = false;
  std::array<double, kMaxInputs> last_u_{};
  bool last_u_valid_ = false;
  std::array<bool, kChangeRing> changed_{};  // command k differed from k − 1, at k mod ring
  std::array<std::int64_t, kChangeRing> sent_stamps_{};  // command k's stamp, at k mod ring
  std::int64_t sent_ = 0;                                // commands sent
};

}  // namespace mixpilot
