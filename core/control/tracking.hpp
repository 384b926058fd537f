#pragma once
// Crazyflie position tracking under a communication round-trip delay (SPEC §5.2, thesis ch. 5):
// the settings of the mode, the helix reference, the delay predictor and the LQR baseline. The
// NMPC is core/control/crazyflie_tracking.hpp; the closed loop is core/modes/tracking_mode.hpp.
//
// Delay model (thesis §5.3.1: only the round-trip time τ_r matters, its split is arbitrary).
// The plant integrates RK4 substeps of h = 1/rate_hz; τ_r = n_r·h is split into a measurement
// delay τ_m = n_m·h (the controller at t_k sees the state of t_k − τ_m) and a command delay
// τ_c = n_c·h (command u_k acts on the rotors over [t_k + τ_c, t_{k+1} + τ_c)), n_m + n_c = n_r.
// The computation time is taken as part of τ_c. Before its first command reaches it the vehicle
// rests in its initial (hover) state.
//
// Delay compensation (SPEC §5.2): the measurement is predicted over τ_r by ERK4 with the inputs
// already sent (DelayPredictor), and the controller starts from the prediction. With the plant's
// substep and model it reproduces the plant exactly.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/control/delay_predictor.hpp"
#include "core/nlp/ocp.hpp"
#include "core/numerics/integrator_erk4.hpp"
#include "core/numerics/setup_result.hpp"
#include "core/numerics/types.hpp"
#include "models/crazyflie.hpp"

namespace mixpilot {

enum class TrackingReferenceKind { smooth_step, helix };
enum class TrackingControllerKind { nmpc, lqr };

// SPEC §5.2 (b): p(t) = (cx + R cos(φ0 + ωt), cy + R sin(φ0 + ωt), z0 + v_z t) for t ≤ length,
// then its last point is held. The centre is (−R cos φ0, −R sin φ0) so the helix starts right
// below the hover point (0, 0, ·): at (0, 0, z0).
struct TrackingHelix {
  double radius = tracking_defaults::kHelixRadius;              // R [m]
  double start_height = tracking_defaults::kHelixStartHeight;   // z0 [m]
  double climb_rate = tracking_defaults::kHelixClimbRate;       // v_z [m/s]
  double angular_rate = tracking_defaults::kHelixAngularRate;   // ω [rad/s]
  double phase = 0.0;                                           // φ0 [rad]
  double length = tracking_defaults::kHelixLength;              // [s]
};

struct TrackingReferenceSettings {
  TrackingReferenceKind kind = TrackingReferenceKind::smooth_step;
  std::string file;       // smooth_step: trajectory CSV (core/nlp/trajectory_io.hpp), as resolved
  TrackingHelix helix{};  // helix
};

struct TrackingControllerSettings {
  TrackingControllerKind kind = TrackingControllerKind::nmpc;
  int N = tracking_defaults::kHorizon;   // NMPC horizon
  double dt = tracking_defaults::kDt;    // control period [s]
  bool compensation = tracking_defaults::kCompensation;  // ERK4 predictor over τ_r
};

struct TrackingPlantSettings {
  double rate_hz = tracking_defaults::kPlantRateHz;  // RK4 substeps per second
  double rtt = tracking_defaults::kRtt;              // τ_r [s], a whole number of substeps
  // τ_m = round(measurement_fraction·n_r)·h, τ_c = τ_r − τ_m.
  double measurement_fraction = tracking_defaults::kMeasurementFraction;
  Eigen::Vector3d start{0.0, 0.0, 0.4};  // initial hover position [m] (SPEC §5.2)
};

// Reference nodes of the helix every dt over its length: position on the helix, hover attitude
// (q = identity) and inputs, body velocity = the derivative (q = identity), ω = 0. The last node
// is the held end point (zero velocity).
OcpTrajectory helix_reference(const TrackingHelix& helix, double dt, const models::Crazyflie& model);

// ⌊a / b⌋ for b > 0: the control period of substep a when b substeps make one period.
inline long floor_div(long a, long b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

// The ERK4 state predictor of SPEC §5.2 on the Crazyflie (core/control/delay_predictor.hpp).
using CrazyflieDelayPredictor = DelayPredictor<models::Crazyflie>;

// Discrete LQR on the 12-state model (SPEC §5.2): the ERK4 map at hover over dt, with qw
// eliminated (∂qw/∂q_v = 0 at hover). State order (p, q_x q_y q_z, v_b, ω), matching
// Q = blkdiag(12.24e3, 10.2e3, 9e5, 0.102·I3, 71.4, 102, 408, 1.02e-3·I2, 1.02e3): it is
// 102·W_ξ of the NMPC with q_w dropped and the z weight raised to 9e5 (the thesis's "detuned
// for z"). Tracking law u = u_ref − K (x12 − x12_ref), clipped to [0, 22] krpm: the thesis's
// u = ū − K ξ around the reference instead of around hover (u_ref = ū on a hover reference and
// along the helix; on the smooth step it is the Ipopt input, a feedforward without which the
// saturated start of the step is lost).
class TrackingLqr {
 public:
  using State = models::Crazyflie::State;
  using Input = models::Crazyflie::Input;
  using Mat12 = Eigen::Matrix<double, 12, 12>;
  using Gain = Eigen::Matrix<double, 4, 12>;

  // Fails when the DARE iteration does not converge.
  SetupResult setup(const models::Crazyflie& model, double dt);
  // Allocates nothing.
  void control(const State& x, const State& x_ref, const Input& u_ref, Input& u) const;

  static Eigen::Matrix<double, 12, 1> q_diagonal();
  static double r_weight() { return tracking_defaults::kLqrR; }
  static Eigen::Matrix<double, 12, 1> reduce(const State& x);  // drops q_w

  const Mat12& A() const { return A_; }
  const Eigen::Matrix<double, 12, 4>& B() const { return B_; }
  const Mat12& P() const { return P_; }
  const Gain& K() const { return K_; }
  double dare_residual() const { return residual_; }  // ‖DARE(P)‖∞ / ‖P‖∞

 private:
  Mat12 A_ = Mat12::Zero();                                          // 12 x 12
  Eigen::Matrix<double, 12, 4> B_ = Eigen::Matrix<double, 12, 4>::Zero();  // 12 x 4
  Mat12 P_ = Mat12::Zero();                                          // 12 x 12
  Gain K_ = Gain::Zero();                                            // 4 x 12
  Input u_hover_ = Input::Zero();
  double u_min_ = 0, u_max_ = 0;
  double residual_ = 0;
};

}  // namespace mixpilot
