#pragma once
// The delay margin of the uncompensated tracking loop (SPEC §5.2, thesis Fig. 5.6): the NMPC's
// feedback law linearized at hover (the unconstrained N-stage Riccati gain of SPEC §5.2's W,
// W_N on the ERK4 model of one control period, q_w dropped as in TrackingLqr) closed around the
// plant integrated in substeps, with each command acting `delay` substeps after the
// measurement it was computed from. Its spectral radius below 1 means the linearized loop is
// stable at that round-trip time.

namespace mixpilot {

// Spectral radius of the period map of the loop with the command `delay` substeps late
// (`substeps` per control period of `dt` seconds, horizon N).
double delayed_loop_spectral_radius(int delay, int N = 50, double dt = 0.015, int substeps = 15);

// The largest round-trip time [s] up to which every whole number of substeps gives a stable
// linearized loop (searched up to `max_delay` substeps); 0 when even no delay is unstable.
double linearized_delay_margin(int N = 50, double dt = 0.015, int substeps = 15,
                               int max_delay = 60);

}  // namespace mixpilot
