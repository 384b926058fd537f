#pragma once
// The instructor's commands on the HUD (SPEC §10): a short banner for each command as it takes
// effect, for kInstructorBannerS of flight time, and a line while bounds, a gust, an extra
// delay or an input loss are in force. Functions of the telemetry alone (Telemetry::commands,
// Telemetry::instructor), so a live flight, its replay and a headless screenshot show the same.
#include <string>
#include <vector>

#include "ui/scene.hpp"

namespace mixpilot::ui {

// [s] how long a command's banner stays after the step it took effect at.
inline constexpr double kInstructorBannerS = 3.0;
// "instructor: gust 2.0 N for 0.50 s" for each command of the last kInstructorBannerS (the
// newest `most`, oldest first). Pause is left out: a paused flight says so while
// it is paused (RunInfo::instructor_paused), and its record reaches the step after the resume.
std::vector<std::string> instructor_banners(const History& h, std::size_t most);

// What is in force during step `s`, item by item (the HUD wraps between them), the first one
// saying whose: {"instructor: ceiling 0.30", "· gust 2.0 N, 0.3 s left", "· delay +0.030 s",
// "· input lost, 0.6 s left"}; empty when nothing is.
std::vector<std::string> instructor_in_force(const Telemetry& s);
// The same of what a station announces (the instructor's tiles), "paused" first when the
// instructor holds the flight.
std::vector<std::string> instructor_in_force(const InstructorInForce& f, bool paused = false);

}  // namespace mixpilot::ui
