#include "core/qp/ocp_qp_io.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ostream>
#include <utility>
#include <vector>

namespace mixpilot {

namespace {

constexpr double kDumpInf = 1e30;

void num(std::ostream& o, double v) {
  if (std::isinf(v)) v = v > 0 ? kDumpInf : -kDumpInf;
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  o << buf;
}

void vec(std::ostream& o, const Eigen::VectorXd& v) {
  o << '[';
  for (Eigen::Index k = 0; k < v.size(); ++k) {
    if (k) o << ',';
    num(o, v[k]);
  }
  o << ']';
}

void ivec(std::ostream& o, const Eigen::VectorXi& v) {
  o << '[';
  for (Eigen::Index k = 0; k < v.size(); ++k) o << (k ? "," : "") << v[k];
  o << ']';
}

void mat(std::ostream& o, const Eigen::MatrixXd& m) {
  o << '[';
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    if (r) o << ',';
    vec(o, m.row(r).transpose());
  }
  o << ']';
}

// --- Minimal JSON reader for the subset the writer produces. ---
// Object members are a struct declared inside Json: std::vector accepts an incomplete element
// type, std::pair<std::string, Json> (incomplete Json) is ill-formed and clang rejects it.
struct Json {
  struct Member;
  enum Type { null, number, string, array, object } type = null;
  double x = 0.0;
  std::string s;
  std::vector<Json> a;
  std::vector<Member> o;
  const Json* get(const std::string& key) const;
};
struct Json::Member {
  std::string key;
  Json value;
};
const Json* Json::get(const std::string& key) const {
  for (const auto& [k, v] : o)
    if (k == key) return &v;
  return nullptr;
}

struct Parser {
  const std::string& t;
  std::size_t p = 0;
  std::string err;
  void ws() {
    while (p < t.size() && (t[p] == ' ' || t[p] == '\n' || t[p] == '\r' || t[p] == '\t')) ++p;
  }
  bool fail(const char* m) {
    if (err.empty()) err = std::string(m) + " at offset " + std::to_string(p);
    return false;
  }
  bool str(std::string& out) {
    if (p >= t.size() || t[p] != '"') return fail("expected string");
    ++p;
    out.clear();
    while (p < t.size() && t[p] != '"') {
      if (t[p] == '\\' && p + 1 < t.size()) ++p;
      out += t[p++];
    }
    if (p >= t.size()) return fail("unterminated string");
    ++p;
    return true;
  }
  bool value(Json& v) {
    ws();
    if (p >= t.size()) return fail("unexpected end");
    const char c = t[p];
    if (c == '{') {
      v.type = Json::object;
      ++p;
      ws();
      if (p < t.size() && t[p] == '}') return ++p, true;
      for (;;) {
        ws();
        std::string key;
        if (!str(key)) return false;
        ws();
        if (p >= t.size() || t[p] != ':') return fail("expected ':'");
        ++p;
        Json child;
        if (!value(child)) return false;
        v.o.push_back({std::move(key), std::move(child)});
        ws();
        if (p < t.size() && t[p] == ',') {
          ++p;
          continue;
        }
        if (p < t.size() && t[p] == '}') return ++p, true;
        return fail("expected ',' or '}'");
      }
    }
    if (c == '[') {
      v.type = Json::array;
      ++p;
      ws();
      if (p < t.size() && t[p] == ']') return ++p, true;
      for (;;) {
        Json child;
        if (!value(child)) return false;
        v.a.push_back(std::move(child));
        ws();
        if (p < t.size() && t[p] == ',') {
          ++p;
          continue;
        }
        if (p < t.size() && t[p] == ']') return ++p, true;
        return fail("expected ',' or ']'");
      }
    }
    if (c == '"') {
      v.type = Json::string;
      return str(v.s);
    }
    if (t.compare(p, 4, "null") == 0) {
      p += 4;
      return true;
    }
    char* end = nullptr;
    v.type = Json::number;
    v.x = std::strtod(t.c_str() + p, &end);
    if (end == t.c_str() + p) return fail("expected a value");
    p = static_cast<std::size_t>(end - t.c_str());
    return true;
  }
};

struct Reader {
  std::string err;
  bool fail(const std::string& m) {
    if (err.empty()) err = m;
    return false;
  }
  bool number(const Json& j, const char* key, double& out) {
    const Json* v = j.get(key);
    if (!v || v->type != Json::number) return fail(std::string("missing number ") + key);
    out = v->x;
    return true;
  }
  bool integer(const Json& j, const char* key, int& out) {
    double x;
    if (!number(j, key, x)) return false;
    out = static_cast<int>(x);
    return true;
  }
  static double unbound(double x) {
    return std::abs(x) >= kDumpInf ? std::copysign(INFINITY, x) : x;
  }
  bool vec(const Json& j, const char* key, Eigen::VectorXd& out, bool bounds = false) {
    const Json* v = j.get(key);
    if (!v || v->type != Json::array || static_cast<Eigen::Index>(v->a.size()) != out.size())
      return fail(std::string("bad vector ") + key);
    for (std::size_t k = 0; k < v->a.size(); ++k) {
      if (v->a[k].type != Json::number) return fail(std::string("bad entry in ") + key);
      out[static_cast<Eigen::Index>(k)] = bounds ? unbound(v->a[k].x) : v->a[k].x;
    }
    return true;
  }
  bool ivec(const Json& j, const char* key, Eigen::VectorXi& out) {
    Eigen::VectorXd tmp(out.size());
    if (!vec(j, key, tmp)) return false;
    out = tmp.cast<int>();
    return true;
  }
  bool mat(const Json& j, const char* key, Eigen::MatrixXd& out) {
    const Json* v = j.get(key);
    if (!v || v->type != Json::array || static_cast<Eigen::Index>(v->a.size()) != out.rows())
      return fail(std::string("bad matrix ") + key);
    for (Eigen::Index r = 0; r < out.rows(); ++r) {
      const Json& row = v->a[static_cast<std::size_t>(r)];
      if (row.type != Json::array || static_cast<Eigen::Index>(row.a.size()) != out.cols())
        return fail(std::string("bad matrix row in ") + key);
      for (Eigen::Index c = 0; c < out.cols(); ++c) {
        const Json& e = row.a[static_cast<std::size_t>(c)];
        if (e.type != Json::number) return fail(std::string("bad entry in ") + key);
        out(r, c) = e.x;
      }
    }
    return true;
  }
};

const char* warm_name(QpWarmStart warm) {
  switch (warm) {
    case QpWarmStart::primal: return "primal";
    case QpWarmStart::primal_dual: return "primal_dual";
    default: return "cold";
  }
}

// The per-stage vectors of a solution written as warm start, in this order.
constexpr const char* kStartFields[] = {"x",  "u",  "pi",     "lam_l", "lam_u",
                                        "sl", "su", "lam_sl", "lam_su"};
template <class Solution>  // OcpQpSolution, const or not
auto start_field(Solution& s, int k) -> decltype(&s.x) {
  decltype(&s.x) f[] = {&s.x, &s.u, &s.pi, &s.lam_l, &s.lam_u, &s.sl, &s.su, &s.lam_sl, &s.lam_su};
  return f[k];
}

}  // namespace

void write_ocp_qp_json(std::ostream& o, const OcpQp& qp, const QpRiccatiIpmSettings& st,
                       const std::string& name, const OcpQpSolution* start, QpWarmStart warm) {
  const OcpQpDims& d = qp.dims;
  o << "{\"format\":\"mixpilot-ocp-qp\",\"version\":2,\"name\":\"" << name << "\",\"N\":" << d.N;
  o << ",\"settings\":{\"max_iterations\":" << st.max_iterations;
  const std::pair<const char*, double> tols[] = {
      {"tol_stat", st.tol_stat}, {"tol_eq", st.tol_eq}, {"tol_ineq", st.tol_ineq},
      {"tol_comp", st.tol_comp}, {"step_fraction", st.step_fraction}, {"min_step", st.min_step},
      {"init_slack", st.init_slack}, {"init_mu", st.init_mu},
      {"warm_start_floor", st.warm_start_floor},
      {"warm_start_slack_floor", st.warm_start_slack_floor},
      {"warm_start_violated", st.warm_start_violated}, {"psd_tol", st.psd_tol},
      {"refine_ratio", st.refine_ratio}, {"inf_bound", st.inf_bound}};
  for (const auto& [k, v] : tols) {
    o << ",\"" << k << "\":";
    num(o, v);
  }
  o << ",\"refinement_steps\":" << st.refinement_steps << "}";
  if (start) {
    o << ",\"warm\":\"" << warm_name(warm) << '"';
    if (warm != QpWarmStart::cold) {
      o << ",\"start\":{";
      for (int k = 0; k < 9; ++k) {
        o << (k ? "," : "") << '"' << kStartFields[k] << "\":[";
        const std::vector<Eigen::VectorXd>& f = *start_field(*start, k);
        for (std::size_t i = 0; i < f.size(); ++i) {
          if (i) o << ',';
          vec(o, f[i]);
        }
        o << ']';
      }
      o << '}';
    }
  }
  o << ",\"x0\":";
  vec(o, qp.x0);
  o << ",\"stages\":[";
  for (int i = 0; i <= d.N; ++i) {
    const OcpQpStage& s = qp.stage[i];
    o << (i ? "," : "") << "{\"nx\":" << d.nx[i] << ",\"nu\":" << d.nu[i] << ",\"nbx\":" << d.nbx[i]
      << ",\"nbu\":" << d.nbu[i] << ",\"ng\":" << d.ng[i] << ",\"ns\":" << d.ns[i];
    o << ",\"A\":", mat(o, s.A);
    o << ",\"B\":", mat(o, s.B);
    o << ",\"b\":", vec(o, s.b);
    o << ",\"Q\":", mat(o, s.Q);
    o << ",\"S\":", mat(o, s.S);
    o << ",\"R\":", mat(o, s.R);
    o << ",\"q\":", vec(o, s.q);
    o << ",\"r\":", vec(o, s.r);
    o << ",\"idxbu\":", ivec(o, s.idxbu);
    o << ",\"lbu\":", vec(o, s.lbu);
    o << ",\"ubu\":", vec(o, s.ubu);
    o << ",\"idxbx\":", ivec(o, s.idxbx);
    o << ",\"lbx\":", vec(o, s.lbx);
    o << ",\"ubx\":", vec(o, s.ubx);
    o << ",\"C\":", mat(o, s.C);
    o << ",\"D\":", mat(o, s.D);
    o << ",\"lg\":", vec(o, s.lg);
    o << ",\"ug\":", vec(o, s.ug);
    o << ",\"idxs\":", ivec(o, s.idxs);
    o << ",\"Zl\":", vec(o, s.Zl);
    o << ",\"Zu\":", vec(o, s.Zu);
    o << ",\"zl\":", vec(o, s.zl);
    o << ",\"zu\":", vec(o, s.zu);
    o << '}';
  }
  o << "]}\n";
}

bool read_ocp_qp_json(const std::string& line, OcpQp& qp, QpRiccatiIpmSettings& st,
                      std::string& name, std::string& error, OcpQpSolution* start,
                      QpWarmStart* warm) {
  Json root;
  Parser parser{line, 0, {}};
  if (!parser.value(root) || root.type != Json::object) {
    error = parser.err.empty() ? "not a JSON object" : parser.err;
    return false;
  }
  Reader r;
  const Json* fmt = root.get("format");
  if (!fmt || fmt->s != "mixpilot-ocp-qp") {
    error = "not a mixpilot-ocp-qp record";
    return false;
  }
  if (const Json* n = root.get("name")) name = n->s;
  int N = 0;
  const Json* stages = root.get("stages");
  const Json* settings = root.get("settings");
  if (!r.integer(root, "N", N) || N < 0 || !stages || stages->type != Json::array ||
      static_cast<int>(stages->a.size()) != N + 1 || !settings) {
    error = r.err.empty() ? "bad N, stages or settings" : r.err;
    return false;
  }
  OcpQpDims d(N);
  for (int i = 0; i <= N; ++i) {
    const Json& s = stages->a[static_cast<std::size_t>(i)];
    if (!(r.integer(s, "nx", d.nx[i]) && r.integer(s, "nu", d.nu[i]) &&
          r.integer(s, "nbx", d.nbx[i]) && r.integer(s, "nbu", d.nbu[i]) &&
          r.integer(s, "ng", d.ng[i]) && r.integer(s, "ns", d.ns[i]))) {
      error = r.err;
      return false;
    }
  }
  if (!d.valid()) {
    error = "inconsistent dimensions";
    return false;
  }
  qp.resize(d);
  bool ok = r.vec(root, "x0", qp.x0);
  for (int i = 0; ok && i <= N; ++i) {
    const Json& j = stages->a[static_cast<std::size_t>(i)];
    OcpQpStage& s = qp.stage[i];
    ok = r.mat(j, "A", s.A) && r.mat(j, "B", s.B) && r.vec(j, "b", s.b) && r.mat(j, "Q", s.Q) &&
         r.mat(j, "S", s.S) && r.mat(j, "R", s.R) && r.vec(j, "q", s.q) && r.vec(j, "r", s.r) &&
         r.ivec(j, "idxbu", s.idxbu) && r.vec(j, "lbu", s.lbu, true) &&
         r.vec(j, "ubu", s.ubu, true) && r.ivec(j, "idxbx", s.idxbx) &&
         r.vec(j, "lbx", s.lbx, true) && r.vec(j, "ubx", s.ubx, true) && r.mat(j, "C", s.C) &&
         r.mat(j, "D", s.D) && r.vec(j, "lg", s.lg, true) && r.vec(j, "ug", s.ug, true) &&
         r.ivec(j, "idxs", s.idxs) && r.vec(j, "Zl", s.Zl) && r.vec(j, "Zu", s.Zu) &&
         r.vec(j, "zl", s.zl) && r.vec(j, "zu", s.zu);
  }
  double mi = 0, rs = 0;
  ok = ok && r.number(*settings, "max_iterations", mi) &&
       r.number(*settings, "refinement_steps", rs) && r.number(*settings, "tol_stat", st.tol_stat) &&
       r.number(*settings, "tol_eq", st.tol_eq) && r.number(*settings, "tol_ineq", st.tol_ineq) &&
       r.number(*settings, "tol_comp", st.tol_comp) &&
       r.number(*settings, "step_fraction", st.step_fraction) &&
       r.number(*settings, "min_step", st.min_step) &&
       r.number(*settings, "init_slack", st.init_slack) &&
       r.number(*settings, "init_mu", st.init_mu) &&
       r.number(*settings, "warm_start_floor", st.warm_start_floor) &&
       r.number(*settings, "psd_tol", st.psd_tol) &&
       r.number(*settings, "refine_ratio", st.refine_ratio) &&
       r.number(*settings, "inf_bound", st.inf_bound);
  if (!ok) {
    error = r.err;
    return false;
  }
  // Written since version 2 (older dumps: the defaults).
  if (settings->get("warm_start_slack_floor"))
    ok = r.number(*settings, "warm_start_slack_floor", st.warm_start_slack_floor);
  if (ok && settings->get("warm_start_violated"))
    ok = r.number(*settings, "warm_start_violated", st.warm_start_violated);
  if (!ok) {
    error = r.err;
    return false;
  }
  st.max_iterations = static_cast<int>(mi);
  st.refinement_steps = static_cast<int>(rs);
  if (start == nullptr || warm == nullptr) return true;
  start->resize(d);
  *warm = QpWarmStart::cold;
  if (const Json* w = root.get("warm")) {
    if (w->type != Json::string || (w->s != "cold" && w->s != "primal" && w->s != "primal_dual")) {
      error = "warm: expected \"cold\", \"primal\" or \"primal_dual\"";
      return false;
    }
    *warm = w->s == "primal"        ? QpWarmStart::primal
            : w->s == "primal_dual" ? QpWarmStart::primal_dual
                                    : QpWarmStart::cold;
  }
  if (*warm == QpWarmStart::cold) return true;
  const Json* sj = root.get("start");
  if (!sj || sj->type != Json::object) {
    error = "a warm record without its start";
    return false;
  }
  for (int k = 0; k < 9; ++k) {
    std::vector<Eigen::VectorXd>& f = *start_field(*start, k);
    const Json* a = sj->get(kStartFields[k]);
    if (!a || a->type != Json::array || a->a.size() != f.size()) {
      error = std::string("start: bad ") + kStartFields[k];
      return false;
    }
    for (std::size_t i = 0; i < f.size(); ++i) {
      Json holder;
      holder.type = Json::object;
      holder.o.push_back({kStartFields[k], a->a[i]});
      if (!r.vec(holder, kStartFields[k], f[i])) {
        error = "start: " + r.err;
        return false;
      }
    }
  }
  return true;
}

}  // namespace mixpilot
