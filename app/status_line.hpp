#pragma once
// The app's status line (the top bar's message): every controller says there what the user
// should know now, and the newest message replaces the last. It writes into the frame's
// snapshot (ui::RunInfo) that the App owns.
#include <string>
#include <utility>

#include "ui/screen.hpp"

namespace mixpilot::cli {

class StatusLine {
 public:
  explicit StatusLine(ui::RunInfo& run) : run_(run) {}
  void say(std::string message, bool error = false) {
    run_.message = std::move(message);
    run_.message_is_error = error;
  }
  // Adds to what is said now ("recorded X; remembered ..."), unless that is an error, which
  // stays until something replaces it.
  void add(const std::string& more) {
    if (run_.message_is_error) return;
    run_.message = run_.message.empty() ? more : run_.message + "; " + more;
  }

 private:
  ui::RunInfo& run_;
};

}  // namespace mixpilot::cli
