#include "tests/benchmarks/qp_sets.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <mutex>

#include "core/modes/make_mode.hpp"
#include "core/qp/ocp_qp_io.hpp"
#include "core/qp/qp_condensed_dense.hpp"
#include "core/qp/qp_riccati_ipm.hpp"
#include "core/qp/qp_riccati_ipm_pairs.hpp"

namespace mixpilot::bench {

const std::vector<QpSetSpec>& qp_set_specs() {
  static const std::vector<QpSetSpec> specs = {
      {"closed_mi_novice", "mi_helix.toml", "novice"},
      {"closed_mi_reckless", "mi_helix.toml", "reckless"},
      {"closed_obstacles_thrown_balls", "obstacles_thrown_balls.toml", nullptr},
      {"closed_crazyflie_tracking", "tracking_smooth_step.toml", nullptr},
  };
  return specs;
}

namespace {

// Keeps every stride-th QP of the flight, up to `count`.
struct Keeper final : RtiQpObserver {
  std::int64_t stride = 1, seen = 0;
  std::size_t count = 0;
  std::vector<ClosedLoopQp>* out = nullptr;
  void on_qp(const OcpQp& qp, const OcpQpSolution& start, QpWarmStart warm) override {
    const std::int64_t k = seen++;
    if (k % stride != 0 || out->size() >= count) return;
    out->push_back(ClosedLoopQp{qp, start, warm, k});
  }
};

// --- The binary cache: the raw doubles and ints of every QP in a fixed order, sizes from the
// dims written before them. Only the build that wrote a file reads it.
constexpr char kMagic[8] = {'M', 'P', 'Q', 'S', 'E', 'T', '0', '1'};

template <class F>
void each_stage_member(OcpQpStage& s, F&& f) {
  f(s.A), f(s.B), f(s.b), f(s.Q), f(s.S), f(s.R), f(s.q), f(s.r), f(s.idxbu), f(s.lbu), f(s.ubu),
      f(s.idxbx), f(s.lbx), f(s.ubx), f(s.C), f(s.D), f(s.lg), f(s.ug), f(s.idxs), f(s.Zl),
      f(s.Zu), f(s.zl), f(s.zu);
}
template <class F>
void each_solution_member(OcpQpSolution& s, F&& f) {
  for (auto* v : {&s.x, &s.u, &s.pi, &s.lam_l, &s.lam_u, &s.sl, &s.su, &s.lam_sl, &s.lam_su})
    for (Eigen::VectorXd& e : *v) f(e);
  f(s.lam_x0);
}

struct Raw {
  std::FILE* f;
  bool ok = true;
  void put(const void* p, std::size_t n) { ok = ok && std::fwrite(p, 1, n, f) == n; }
  void get(void* p, std::size_t n) { ok = ok && std::fread(p, 1, n, f) == n; }
  template <class T>
  void put(const T& v) { put(&v, sizeof v); }
  template <class T>
  void get(T& v) { get(&v, sizeof v); }
};

bool write_set(const std::string& path, const QpSet& set) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return false;
  Raw w{f};
  w.put(kMagic, sizeof kMagic);
  w.put(std::uint64_t(set.qps.size()));
  for (const ClosedLoopQp& c0 : set.qps) {
    ClosedLoopQp& c = const_cast<ClosedLoopQp&>(c0);  // the visitors take mutable members
    const OcpQpDims& d = c.qp.dims;
    w.put(d.N);
    for (const std::vector<int>* v : {&d.nx, &d.nu, &d.nbx, &d.nbu, &d.ng, &d.ns})
      w.put(v->data(), v->size() * sizeof(int));
    w.put(int(c.warm));
    w.put(c.solve);
    const auto put = [&](auto& m) { w.put(m.data(), std::size_t(m.size()) * sizeof(m(0))); };
    put(c.qp.x0);
    for (OcpQpStage& s : c.qp.stage) each_stage_member(s, put);
    each_solution_member(c.start, put);
  }
  const bool ok = w.ok;
  return std::fclose(f) == 0 && ok;
}

bool read_set(const std::string& path, QpSet& set) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return false;
  Raw r{f};
  char magic[sizeof kMagic] = {};
  r.get(magic, sizeof magic);
  std::uint64_t n = 0;
  r.get(n);
  if (!r.ok || std::memcmp(magic, kMagic, sizeof kMagic) != 0 || n > 100000) {
    std::fclose(f);
    return false;
  }
  set.qps.resize(n);
  for (ClosedLoopQp& c : set.qps) {
    int N = -1;
    r.get(N);
    if (!r.ok || N < 0 || N > 100000) break;
    OcpQpDims d(N);
    for (std::vector<int>* v : {&d.nx, &d.nu, &d.nbx, &d.nbu, &d.ng, &d.ns})
      r.get(v->data(), v->size() * sizeof(int));
    if (!r.ok || !d.valid()) {
      r.ok = false;
      break;
    }
    int warm = 0;
    r.get(warm);
    r.get(c.solve);
    c.warm = QpWarmStart(warm);
    c.qp.resize(d);
    c.start.resize(d);
    const auto get = [&](auto& m) { r.get(m.data(), std::size_t(m.size()) * sizeof(m(0))); };
    get(c.qp.x0);
    for (OcpQpStage& s : c.qp.stage) each_stage_member(s, get);
    each_solution_member(c.start, get);
  }
  std::fclose(f);
  return r.ok;
}

}  // namespace

QpSet closed_loop_set(const QpSetSpec& spec, int count, std::string& error) {
  QpSet set;
  set.name = spec.name;
  ModeRequest request;
  if (spec.pilot) request.pilot_name = spec.pilot;
  auto mode = load_mode(std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/" + spec.scenario,
                        std::move(request), error);
  if (!mode) return set;
  RtiSolver* rti = mode->rti_solver();
  if (!rti) {
    error = std::string(spec.scenario) + " flies no NMPC";
    return set;
  }
  set.rti = rti->settings();
  if (const char* kind = std::getenv("MIXPILOT_QP_SET_SOLVER")) {  // compare the variants
    const std::string k = kind;
    if (k == "riccati_ipm") set.rti.qp_solver = QpSolverKind::riccati_ipm;
    if (k == "riccati_ipm_pairs") set.rti.qp_solver = QpSolverKind::riccati_ipm_pairs;
  }
  const char* dir = std::getenv("MIXPILOT_QP_SETS");
  const std::string cache =
      dir && *dir ? std::string(dir) + "/" + spec.name + ".qps" : std::string();
  if (!cache.empty() && read_set(cache, set)) return set;
  set.qps.clear();

  Keeper keeper;
  keeper.stride = std::max<std::int64_t>(1, mode->steps_total() / count);
  keeper.count = std::size_t(count);
  keeper.out = &set.qps;
  set.qps.reserve(std::size_t(count));
  rti->set_qp_observer(&keeper);
  while (mode->step()) {
  }
  rti->set_qp_observer(nullptr);
  if (set.qps.empty()) {
    error = std::string(spec.scenario) + ": no QP was solved";
    return set;
  }
  if (!cache.empty() && !write_set(cache, set))
    std::fprintf(stderr, "mixpilot-bench: cannot write %s\n", cache.c_str());
  if (const char* dump = std::getenv("MIXPILOT_DUMP_QP"); dump && *dump) {
    std::ofstream out(dump, std::ios::app);
    for (const ClosedLoopQp& c : set.qps)
      write_ocp_qp_json(out, c.qp, set.rti.qp,
                        "BM_QpSolve/" + set.name + "/" + std::to_string(c.solve), &c.start,
                        c.warm);
  }
  return set;
}

const QpSet& cached_closed_loop_set(const QpSetSpec& spec, int count) {
  static std::mutex mutex;
  static std::map<std::string, QpSet> sets;
  const std::lock_guard<std::mutex> lock(mutex);
  auto it = sets.find(spec.name);
  if (it == sets.end()) {
    std::string error;
    it = sets.emplace(spec.name, closed_loop_set(spec, count, error)).first;
    if (!error.empty()) std::fprintf(stderr, "mixpilot-bench: %s\n", error.c_str());
  }
  return it->second;
}

std::unique_ptr<QpSolver> make_qp_solver(const RtiSettings& rti, const OcpQpDims& dims) {
  std::unique_ptr<QpSolver> s;
  switch (rti.qp_solver) {
    case QpSolverKind::riccati_ipm: s = std::make_unique<QpRiccatiIpm>(); break;
    case QpSolverKind::riccati_ipm_pairs:
      s = std::make_unique<QpRiccatiIpmPairs>(rti.qp_pair_levels);
      break;
    default: {
      auto d = std::make_unique<QpCondensedDense>();
      d->set_method(rti.qp_solver == QpSolverKind::condensed_active_set
                        ? CondensedQpMethod::active_set
                        : CondensedQpMethod::ipm);
      s = std::move(d);
    }
  }
  s->setup(dims, rti.qp);
  return s;
}

Percentiles percentiles(std::vector<double>& v) {
  Percentiles p;
  if (v.empty()) return p;
  std::sort(v.begin(), v.end());
  const auto at = [&](double q) { return v[std::size_t(q * double(v.size() - 1) + 0.5)]; };
  p.median = at(0.5);
  p.p90 = at(0.9);
  p.worst = v.back();
  return p;
}

}  // namespace mixpilot::bench
