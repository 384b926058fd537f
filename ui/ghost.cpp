#include "ui/ghost.hpp"

#include <cmath>
#include <cstdio>

#include "ui/scene.hpp"

namespace mixpilot::ui {

std::optional<std::size_t> ghost_column(const Ghost& g, double t) {
  if (!(g.dt > 0.0) || g.steps() == 0 || !std::isfinite(t)) return std::nullopt;
  const std::int64_t j = std::llround(t / g.dt) - g.first_step;
  if (j < 0 || j >= g.steps()) return std::nullopt;
  return std::size_t(j);
}

std::optional<GhostGap> ghost_gap(const Ghost& g, const ReferencePath& reference,
                                  const Telemetry& live) {
  if (!reference || live.x.size() < 3) return std::nullopt;
  const std::optional<std::size_t> j = ghost_column(g, live.t);
  if (!j) return std::nullopt;
  const double ghost = g.progress[*j];
  const std::optional<double> tau = reference_progress(reference, live.x.head<3>(), live.t);
  if (!tau || !std::isfinite(ghost)) return std::nullopt;
  return GhostGap{live.t, *tau, ghost, *tau - ghost};
}

std::optional<GhostGap> ghost_gap(const Scene& sc, const Telemetry& live) {
  if (!sc.ghost) return std::nullopt;
  return ghost_gap(*sc.ghost, sc.reference_at, live);
}

std::string ghost_gap_text(const GhostGap& gap) {
  char text[48];
  if (std::abs(gap.ahead) < 0.05)
    std::snprintf(text, sizeof text, "ghost: level with you");
  else
    std::snprintf(text, sizeof text, "ghost: you are %s by %.1f s",
                  gap.ahead > 0 ? "ahead" : "behind", std::abs(gap.ahead));
  return text;
}

std::string ghost_hud_text(const Scene& sc, const Telemetry& live) {
  if (!sc.ghost) return {};
  const Ghost& g = *sc.ghost;
  std::string text;
  char when[48];
  if (const std::optional<GhostGap> gap = ghost_gap(sc, live)) {
    text = ghost_gap_text(*gap);
  } else if (g.steps() > 0 && live.t > g.last_t()) {
    std::snprintf(when, sizeof when, "ghost: ended at %.1f s", g.last_t());
    text = when;
  } else if (g.steps() > 0 && live.t < double(g.first_step) * g.dt) {
    std::snprintf(when, sizeof when, "ghost: flies from %.1f s", double(g.first_step) * g.dt);
    text = when;
  } else {
    text = "ghost: no figure here";  // a non-finite state, or no reference to compare along
  }
  if (!g.label.empty()) text += " · " + g.label;
  return text;
}

}  // namespace mixpilot::ui
