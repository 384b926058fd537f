#include "core/nlp/trajectory_io.hpp"

#include <charconv>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <vector>

#include "core/base/input_file.hpp"

namespace mixpilot {
namespace {

// Splits a CSV line at commas (no quoting: the format has only numbers and plain names).
std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::size_t from = 0;
  for (std::size_t comma; (comma = line.find(',', from)) != std::string::npos; from = comma + 1)
    cells.emplace_back(line, from, comma - from);
  if (from < line.size() || (!line.empty() && line.back() == ','))
    cells.emplace_back(line, from);  // the last cell, empty after a trailing comma
  return cells;
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

bool parse_number(const std::string& cell, double& value) {
  const std::string s = trim(cell);
  if (s.empty()) return false;
  // std::from_chars and strtod both round correctly, so they agree where both read; strtod
  // reads the rest (a leading '+', hexadecimal) and says what is out of range.
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (ec != std::errc() || ptr != s.data() + s.size()) {
    char* end = nullptr;
    errno = 0;
    value = std::strtod(s.c_str(), &end);
    if (end != s.c_str() + s.size() || errno == ERANGE) return false;
  }
  return std::isfinite(value) && std::abs(value) <= kMaxTrajectoryValue;
}

std::string where(const std::string& path, int line) {
  return path + ":" + std::to_string(line) + ": ";
}

}  // namespace

bool write_trajectory_csv(const std::string& path, const OcpTrajectory& traj, double dt,
                          std::string& error) {
  const int N = int(traj.u.size());
  if (N < 1 || int(traj.x.size()) != N + 1) {
    error = path + ": a trajectory needs N >= 1 inputs and N+1 states";
    return false;
  }
  const int nx = int(traj.x[0].size()), nu = int(traj.u[0].size());
  for (const auto& x : traj.x)
    if (x.size() != nx) {
      error = path + ": states differ in size";
      return false;
    }
  for (const auto& u : traj.u)
    if (u.size() != nu) {
      error = path + ": inputs differ in size";
      return false;
    }
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) {
    error = path + ": cannot open for writing: " + std::strerror(errno);
    return false;
  }
  std::fputs("t", f);
  for (int j = 0; j < nx; ++j) std::fprintf(f, ",x%d", j);
  for (int j = 0; j < nu; ++j) std::fprintf(f, ",u%d", j);
  std::fputc('\n', f);
  for (int i = 0; i <= N; ++i) {
    std::fprintf(f, "%.17g", i * dt);
    for (int j = 0; j < nx; ++j) std::fprintf(f, ",%.17g", traj.x[i](j));
    for (int j = 0; j < nu; ++j) {
      if (i < N)
        std::fprintf(f, ",%.17g", traj.u[i](j));
      else
        std::fputc(',', f);
    }
    std::fputc('\n', f);
  }
  const bool ok = !std::ferror(f);
  if (std::fclose(f) != 0 || !ok) {
    error = path + ": write failed";
    return false;
  }
  return true;
}

std::optional<TrajectoryFile> read_trajectory_csv(const std::string& path, std::string& error) {
  std::string text;
  if (!read_input_file(path, kMaxTrajectoryBytes, text, error)) return std::nullopt;
  // Any editor's or spreadsheet's line ends and byte-order mark read as written.
  std::istringstream in(normalize_text(text));
  text = std::string();
  std::string line;
  int lineno = 1;
  if (!std::getline(in, line)) {
    error = where(path, 1) + "expected a header line \"t,x0,...,u0,...\", found an empty file";
    return std::nullopt;
  }
  // Header: t, x0..x{nx−1}, u0..u{nu−1}.
  const std::vector<std::string> header = split(line);
  int nx = 0, nu = 0;
  if (header.empty() || trim(header[0]) != "t") {
    error = where(path, 1) + "expected the header to start with column \"t\"";
    return std::nullopt;
  }
  if (header.size() > std::size_t(1 + 2 * kMaxTrajectoryColumns)) {
    error = where(path, 1) + "expected at most " + std::to_string(kMaxTrajectoryColumns) +
            " x and " + std::to_string(kMaxTrajectoryColumns) + " u columns, found " +
            std::to_string(header.size()) + " columns";
    return std::nullopt;
  }
  for (size_t c = 1; c < header.size(); ++c) {
    const std::string name = trim(header[c]);
    std::string want_x = "x", want_u = "u";
    want_x += std::to_string(nx);
    want_u += std::to_string(nu);
    if (nu == 0 && name == want_x) {
      ++nx;
    } else if (name == want_u) {
      ++nu;
    } else {
      std::string expected = "\"" + want_u + "\"";
      if (nu == 0) expected = "\"" + want_x + "\" or " + expected;
      error = where(path, 1) + "column " + std::to_string(c + 1) + ": expected " + expected +
              ", found \"" + printable(name) + "\"";
      return std::nullopt;
    }
  }
  if (nx == 0 || nu == 0) {
    error = where(path, 1) + "expected at least one x column and one u column";
    return std::nullopt;
  }
  if (nx > kMaxTrajectoryColumns || nu > kMaxTrajectoryColumns) {
    error = where(path, 1) + "expected at most " + std::to_string(kMaxTrajectoryColumns) +
            " x and " + std::to_string(kMaxTrajectoryColumns) + " u columns, found " +
            std::to_string(nx) + " and " + std::to_string(nu);
    return std::nullopt;
  }
  const int ncols = 1 + nx + nu;

  TrajectoryFile file;
  std::vector<double> t;
  std::vector<int> row_line;  // line number of each row
  bool last_seen = false;  // a row without u has been read: it must be the last
  while (std::getline(in, line)) {
    ++lineno;
    if (trim(line).empty()) continue;
    if (t.size() >= std::size_t(kMaxTrajectoryRows)) {
      error =
          where(path, lineno) + "expected at most " + std::to_string(kMaxTrajectoryRows) + " rows";
      return std::nullopt;
    }
    if (last_seen) {
      error = where(path, lineno - 1) +
              "empty u cells are only allowed on the last row, but more rows follow";
      return std::nullopt;
    }
    const std::vector<std::string> cells = split(line);
    if (int(cells.size()) != ncols) {
      error = where(path, lineno) + "expected " + std::to_string(ncols) + " cells (t, " +
              std::to_string(nx) + " x, " + std::to_string(nu) + " u), found " +
              std::to_string(cells.size());
      return std::nullopt;
    }
    double v = 0.0;
    Eigen::VectorXd x(nx), u(nu);
    for (int c = 0; c < 1 + nx; ++c) {
      if (!parse_number(cells[c], v)) {
        error = where(path, lineno) + "column " + std::to_string(c + 1) + " (" + trim(header[c]) +
                "): expected a number in [-1e6, 1e6], found \"" + printable(trim(cells[c])) + "\"";
        return std::nullopt;
      }
      if (c == 0) {
        t.push_back(v);
        row_line.push_back(lineno);
      } else {
        x(c - 1) = v;
      }
    }
    int empty_u = 0;
    for (int j = 0; j < nu; ++j) empty_u += trim(cells[1 + nx + j]).empty() ? 1 : 0;
    if (empty_u == nu) {
      last_seen = true;
    } else {
      for (int j = 0; j < nu; ++j) {
        const int c = 1 + nx + j;
        if (!parse_number(cells[c], v)) {
          error = where(path, lineno) + "column " + std::to_string(c + 1) + " (" + trim(header[c]) +
                  "): expected a number in [-1e6, 1e6], found \"" + printable(trim(cells[c])) + "\"";
          return std::nullopt;
        }
        u(j) = v;
      }
      file.trajectory.u.push_back(u);
    }
    file.trajectory.x.push_back(x);
  }
  if (!last_seen) {
    error = where(path, lineno) + "expected the last row to have empty u cells (no u_N)";
    return std::nullopt;
  }
  const int N = int(file.trajectory.u.size());
  if (N < 1) {
    error = where(path, lineno) + "expected at least two rows (x_0, u_0 and x_1)";
    return std::nullopt;
  }
  // Equidistant grid from t_0: Δt = t_1 − t_0, |t_i − t_0 − i Δt| small.
  file.dt = t[1] - t[0];
  if (!(file.dt > 0.0)) {
    error = where(path, row_line[1]) + "expected t to increase";
    return std::nullopt;
  }
  for (int i = 0; i <= N; ++i) {
    const double expected = t[0] + i * file.dt;
    if (std::abs(t[i] - expected) > 1e-9 * std::max(1.0, std::abs(expected))) {
      error = where(path, row_line[i]) + "expected t = " + std::to_string(expected) +
              " (equidistant grid of dt = " + std::to_string(file.dt) + ")";
      return std::nullopt;
    }
  }
  return file;
}

}  // namespace mixpilot
