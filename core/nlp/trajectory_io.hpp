#pragma once
// Trajectory files (reference trajectories, converged baselines): CSV, one row per stage.
//
//   t,x0,x1,...,x{nx−1},u0,...,u{nu−1}       header line (the column names fix nx and nu)
//   0,<x_0>,<u_0>                            row i: t_i = i·Δt, x_i, u_i
//   ...
//   T,<x_N>,,,,                              last row: x_N and nu empty cells (no u_N)
//
// Numbers are written with 17 significant digits, so a file read back gives the same doubles.
// Δt is recovered as t_1 − t_0; the t column must be equidistant. Reading is at the edge of
// the program: it builds error strings (file, line, what was expected) and never throws.
#include <optional>
#include <string>

#include "core/nlp/ocp.hpp"

namespace mixpilot {

// A trajectory file larger than this is refused before it is read (a 10 min trajectory at 1 ms
// with 17 columns is ≈ 100 MiB).
inline constexpr long long kMaxTrajectoryBytes = 256ll << 20;
// Row and column bounds (docs/scenario-format.md, "Reference CSVs"): as many nodes as the
// longest run has control steps, and state/input sizes far above every model's.
inline constexpr int kMaxTrajectoryRows = 2'000'000;
inline constexpr int kMaxTrajectoryColumns = 64;  // each of x and u
// Every cell's magnitude (t, states, inputs): squares and sums of a run stay finite.
inline constexpr double kMaxTrajectoryValue = 1e6;

struct TrajectoryFile {
  OcpTrajectory trajectory;  // x: N+1 x nx, u: N x nu
  double dt = 0.0;           // [s]
};

// Writes `traj` (N ≥ 1 intervals) with t_i = i·dt. Returns false and sets `error` on failure.
bool write_trajectory_csv(const std::string& path, const OcpTrajectory& traj, double dt,
                          std::string& error);

// Reads a file written by write_trajectory_csv. On failure returns nullopt and sets `error`
// to "<path>:<line>: <what was expected>".
std::optional<TrajectoryFile> read_trajectory_csv(const std::string& path, std::string& error);

}  // namespace mixpilot
