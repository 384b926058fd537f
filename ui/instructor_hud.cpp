#include "ui/instructor_hud.hpp"

#include <cstdio>

namespace mixpilot::ui {

std::vector<std::string> instructor_banners(const History& h, std::size_t most) {
  std::vector<std::string> out;
  if (h.empty()) return out;
  const double now = h.newest().t;
  for (std::size_t i = h.size(); i-- > 0 && out.size() < most;) {
    const Telemetry& s = h[i];
    if (s.t < now - kInstructorBannerS) break;
    for (int j = s.num_commands; j-- > 0 && out.size() < most;) {
      const InstructorCommand& c = s.commands[std::size_t(j)];
      if (c.kind == InstructorCommandKind::pause) continue;
      out.push_back("instructor: " + describe(c));
    }
  }
  return {out.rbegin(), out.rend()};
}

std::vector<std::string> instructor_in_force(const Telemetry& s) {
  return instructor_in_force(s.instructor);
}

std::vector<std::string> instructor_in_force(const InstructorInForce& f, bool paused) {
  std::vector<std::string> out;
  char buf[64];
  const auto add = [&](const char* text) {
    out.push_back(out.empty() ? std::string("instructor: ") + text : std::string("· ") + text);
  };
  if (paused) add("paused");
  if (f.bounds != AuthorityBounds{}) {
    InstructorCommand b;
    b.kind = InstructorCommandKind::bounds;
    b.bounds = f.bounds;
    add(describe(b).c_str());
  }
  if (f.gust_left > 0.0) {
    std::snprintf(buf, sizeof buf, "gust %.1f N, %.1f s left", f.gust.norm(), f.gust_left);
    add(buf);
  }
  if (f.extra_delay > 0.0) {
    std::snprintf(buf, sizeof buf, "delay +%.3f s", f.extra_delay);
    add(buf);
  }
  if (f.input_loss_left > 0.0) {
    std::snprintf(buf, sizeof buf, "input lost, %.1f s left", f.input_loss_left);
    add(buf);
  }
  return out;
}

}  // namespace mixpilot::ui
