#pragma once
// The vehicle a quadrotor mode simulates when none is linked (SPEC §5.2–§5.4): the plant, RK4
// at the plant rate with the input held over each substep (VehiclePlant, which `mixpilot
// vehicle` integrates on the wall clock too), the delay lines of the command and measurement
// links, and the measurement's position noise with its RNG.
//
// Clock. Substep boundaries j of h on the plant's clock, s substeps per control period; command
// k goes out at boundary k·s and acts over [k·s + n_c, (k+1)·s + n_c) (the command delay line);
// before command 0 acts the vehicle rests, or hovers on the model's hover input. Step k
// measures boundary k·s − n_m (the measurement delay line; the start state before boundary 0),
// its position plus σ·N(0, 1) per axis where σ > 0. The states are kept in a ring: boundaries
// from k·s − n_m − n_x up to those integrated ahead, (k+1)·s + n_c at most, are there.
//
// The instructor (SPEC §10): a gust is a world-frame force on the plant
// (models::WithExternalForce) over substeps [j_g, j_g + n_g) from the first one not yet integrated; the
// extra delay n_x ≤ max_extra_delay substeps is added to the measurement's, so step k measures
// boundary k·s − n_m − n_x. All of the round trip's extra delay is put on the measurement: the
// loop sees the same delay as when it is split over both links, and a command line whose delay
// changed in flight would drop or repeat commands, which no link does. Both are in Data.
//
// Model/Data: setup() sizes Data, the rest allocates nothing; a snapshot copies Data.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "core/modes/vehicle_feed.hpp"
#include "core/numerics/integrator_erk4.hpp"

namespace mixpilot {

// The plant: RK4 substeps with the input held.
template <class Model>
class VehiclePlant {
 public:
  using State = typename Model::State;
  using Input = typename Model::Input;

  VehiclePlant() = default;
  explicit VehiclePlant(const Model& model) : erk4_(model) {}

  // x(t + h) from x(t) with u held over [t, t + h].
  void substep(const State& x, const Input& u, double h, State& x_next) const {
    erk4_.template step<double>(x, u, h, x_next);
  }
  // The same with a world-frame force F on the vehicle (a gust). Allocates nothing.
  void substep(const State& x, const Input& u, double h, const Eigen::Vector3d& force,
               State& x_next) {
    if (forced_.model().force != force)
      forced_ = IntegratorErk4<models::WithExternalForce<Model>>({erk4_.model(), force});
    forced_.template step<double>(x, u, h, x_next);
  }
  // x from t to `to` [ns] with u held, in substeps of h_ns (the last one shorter), stopping at
  // the first state outside `world` or not finite: then x keeps the last state inside, t is
  // the end of the substep that left, and how it left is returned (nullptr: t = to).
  [[nodiscard]] const char* advance(State& x, const Input& u, std::int64_t& t, std::int64_t to,
                                    std::int64_t h_ns, const VehicleWorld& world) const {
    State xn;
    while (t < to) {
      const std::int64_t dt = std::min(h_ns, to - t);
      substep(x, u, 1e-9 * double(dt), xn);
      t += dt;
      const char* outside = xn.allFinite() ? world.outside(xn.template head<3>())
                                           : "its state stopped being finite";
      if (outside) return outside;
      x = xn;
    }
    return nullptr;
  }

 private:
  IntegratorErk4<Model> erk4_{};
  IntegratorErk4<models::WithExternalForce<Model>> forced_{};  // the model with the gust's force
};

// y[0..3) += σ·N(0, 1) per axis, drawn from rng in order. Compiled once
// (core/modes/simulated_vehicle.cpp), not in the template: a copy per translation unit may compile
// the draw (std::normal_distribution's arithmetic) and the multiply-add to different
// instructions, and a replay in another binary must repeat the flight bit for bit.
void add_position_noise(double sigma, std::mt19937_64& rng,
                        std::normal_distribution<double>& noise, double* y);

template <class Model>
class SimulatedVehicle {
 public:
  using State = typename Model::State;
  using Input = typename Model::Input;

  // What the vehicle does before command 0 acts.
  enum class Idle { rests, hovers };

  struct Settings {
    int substeps = 1;            // s per control period
    double h = 0.0;              // substep [s]
    long command_delay = 0;      // n_c [substeps]
    long measurement_delay = 0;  // n_m [substeps]
    Idle idle = Idle::rests;
    double position_noise = 0.0;  // σ [m]
    std::uint64_t seed = 0;       // of the noise
    long max_extra_delay = 0;     // [substeps] the instructor's extra delay at most (the ring)
  };

  // What a flight changes: a snapshot copies it.
  struct Data {
    std::vector<State> states;    // ring: boundary j at j mod size, each nx
    std::vector<Input> commands;  // ring: command k at k mod size, each nu
    long integrated = 0;          // boundaries integrated: states up to here are known
    std::mt19937_64 rng;          // position noise
    std::normal_distribution<double> noise{0.0, 1.0};
    // The instructor's gust: `gust` [N, world frame] over substeps [gust_from, gust_until).
    Eigen::Vector3d gust = Eigen::Vector3d::Zero();
    long gust_from = 0, gust_until = 0;
    long extra_delay = 0;  // n_x [substeps] added to the measurement's delay
  };

  // Sizes the rings; the vehicle starts at x0, no command sent.
  void setup(const Model& model, const Settings& settings, const State& x0) {
    plant_ = VehiclePlant<Model>(model);
    settings_ = settings;
    settings_.substeps = std::max(1, settings.substeps);
    idle_input_ = settings_.idle == Idle::hovers ? model.hover_input() : Input::Zero();
    x0_ = x0;
    const long s = settings_.substeps, n_c = settings_.command_delay;
    // Integrating to (k+1)·s + n_c while k·s − n_m is still read; the substeps integrated in
    // step k act on commands k − ⌈n_c/s⌉ .. k.
    settings_.max_extra_delay = std::max(0L, settings.max_extra_delay);
    data_.states.assign(
        std::size_t(settings_.measurement_delay + settings_.max_extra_delay + n_c + s + 1), x0);
    data_.commands.assign(std::size_t((n_c + s - 1) / s + 2), idle_input_);
    data_.integrated = 0;
    data_.rng.seed(settings_.seed);
    data_.noise.reset();
    data_.gust.setZero();
    data_.gust_from = data_.gust_until = 0;
    data_.extra_delay = 0;
  }

  // A gust of `force` [N, world frame] for `substeps` substeps from the first substep not yet
  // integrated on (replacing one still blowing).
  void gust(const Eigen::Vector3d& force, long substeps) {
    data_.gust = force;
    data_.gust_from = data_.integrated;
    data_.gust_until = data_.integrated + std::max(1L, substeps);
  }
  // The gust's substeps left from boundary j on.
  long gust_left(long j) const {
    return std::max(0L, data_.gust_until - std::max(j, data_.gust_from));
  }
  // The extra measurement delay [substeps], clamped to 0 .. max_extra_delay.
  void set_extra_delay(long substeps) {
    data_.extra_delay = std::clamp(substeps, 0L, settings_.max_extra_delay);
  }
  long extra_delay() const { return data_.extra_delay; }

  // Command k goes out (the step's; once per step, in order).
  void send(std::int64_t k, const Input& u) {
    data_.commands[std::size_t(k % std::int64_t(data_.commands.size()))] = u;
  }
  // Integrates up to boundary `end`, each substep with the command acting on it.
  void integrate_to(long end) {
    while (data_.integrated < end) {
      const long j = data_.integrated;
      const State& x = at(j);
      State& xn = data_.states[ring(j + 1)];
      if (j >= settings_.command_delay || settings_.idle == Idle::hovers) {
        if (j >= data_.gust_from && j < data_.gust_until)
          plant_.substep(x, acting(j), settings_.h, data_.gust, xn);
        else
          plant_.substep(x, acting(j), settings_.h, xn);
      } else {
        xn = x;  // at rest until command 0 acts
      }
      ++data_.integrated;
    }
  }
  // Step k's measurement y: boundary k·s − n_m − n_x, its position with noise.
  void measure(std::int64_t k, State& y) {
    const long b = long(k) * settings_.substeps - settings_.measurement_delay - data_.extra_delay;
    y = b <= 0 ? x0_ : at(b);
    if (settings_.position_noise > 0.0)
      add_position_noise(settings_.position_noise, data_.rng, data_.noise, y.data());
  }

  // The state of boundary j (integrated, and not yet overwritten in the ring).
  const State& at(long j) const { return data_.states[ring(j)]; }
  // The input on the rotors over substep j: the command acting then, or the idle input.
  const Input& acting(long j) const {
    const long m = floor_div(j - settings_.command_delay, settings_.substeps);
    return m < 0 ? idle_input_ : data_.commands[std::size_t(m % long(data_.commands.size()))];
  }
  long integrated() const { return data_.integrated; }
  const Settings& settings() const { return settings_; }

  const Data& data() const { return data_; }
  // A vehicle set up alike (the same ring sizes).
  [[nodiscard]] bool fits(const Data& data) const {
    return data.states.size() == data_.states.size() &&
           data.commands.size() == data_.commands.size();
  }
  // Takes a Data that fits (copies into the sized rings: allocates nothing).
  void restore(const Data& data) { data_ = data; }

 private:
  static long floor_div(long a, long b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }
  std::size_t ring(long j) const { return std::size_t(j % long(data_.states.size())); }

  VehiclePlant<Model> plant_;
  Settings settings_;
  Input idle_input_ = Input::Zero();  // nu: on the rotors before command 0 acts
  State x0_ = State::Zero();          // nx: the start state
  Data data_;
};

}  // namespace mixpilot
