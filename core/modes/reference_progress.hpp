#pragma once
// Progress along a reference (SPEC §10, the ghost's "ahead / behind by X s"): the reference
// time τ whose point η^r(τ) is nearest a vehicle at p, searched near the flight's time t.
// Two flights of one scenario compared at the same t: τ_live − τ_ghost [s] is how far along the
// reference one is ahead of the other, whatever their deviations from it.
#include <functional>
#include <limits>
#include <optional>

#include <Eigen/Core>

namespace mixpilot {

// The reference η^r(τ) [m] at any reference time τ [s].
using ReferencePath = std::function<Eigen::Vector3d(double tau)>;

struct ProgressSearch {
  // [s] W: τ is searched in [t − W, t + W] ∩ [tau_min, tau_max]. It must stay under half the
  // time the reference takes to come back near itself (half a helix turn, π/ω: 15 s and more
  // for the shipped helices), so that the nearest point is that of the pass the vehicle flies,
  // not the coil above or below (mi_helix_endurance's are 0.2 m apart); a vehicle more than W
  // ahead of or behind its reference reads as W.
  double window = 5.0;
  double step = 0.02;  // [s] h: the coarse samples' spacing
  double tolerance = 1e-7;  // [s] the refined bracket's width
  double tau_min = 0.0;  // [s] before the flight's start the reference is not flown
  double tau_max = std::numeric_limits<double>::infinity();
};

// τ* = argmin_{τ ∈ I} f(τ),  f(τ) = ‖η^r(τ) − p‖²,  I = [t − W, t + W] ∩ [tau_min, tau_max].
// Coarse: f at τ_j = τ_lo + j·h (and at τ_hi), j* the least. Refined between samples: the
// minimizer lies in [τ_{j*−1}, τ_{j*+1}], where f is unimodal (over 2h the reference turns
// little: f ≈ f(τ*) + ½ f''(τ*) (τ − τ*)², f'' > 0), and a golden-section search shrinks that
// bracket by 1/φ per evaluation of f down to `tolerance`. An end of I is a valid answer (f
// least there). Searching locally, not globally: a helix passes over the same (x, y) once per
// turn, v_z·2π/ω higher, so a global minimum jumps to a neighbouring turn as soon as the vehicle
// strays half that height vertically. nullopt when p is not finite or I is empty.
[[nodiscard]] std::optional<double> reference_progress(const ReferencePath& reference,
                                                       const Eigen::Vector3d& p, double t,
                                                       const ProgressSearch& search = {});

}  // namespace mixpilot
