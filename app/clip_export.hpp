#pragma once
// "Export clip" in the window's replay: a time window of a recording saved as a video beside
// it, under a numbered name that never replaces a file. `mixpilot replay REC --video OUT --from
// A --to B` does the work as a child process, with its own offscreen context and ffmpeg: the UI
// thread only starts it and, once a frame, reads what it has said without waiting. Its progress
// and result go to the status line.
#include <string>

#include "app/child_process.hpp"
#include "app/status_line.hpp"

namespace mixpilot::cli {

class ClipExporter {
 public:
  explicit ClipExporter(StatusLine& status);
  ClipExporter(const ClipExporter&) = delete;
  ClipExporter& operator=(const ClipExporter&) = delete;
  // An export under way is stopped (SIGTERM: the child removes its temporary file).
  ~ClipExporter();

  // The mixpilot executable that renders (default: this process's own; tests name theirs).
  void set_program(std::string path) { program_ = std::move(path); }

  // Starts saving [from, to) [s] of `recording`; false, with the reason in the status line,
  // when another export is under way, ffmpeg is missing or the window is empty.
  bool start(const std::string& recording, double from, double to);
  // Once a frame: the progress and, at the end, the result into the status line. Never blocks.
  void poll();
  bool running() const { return child_.running(); }
  // The file being written, or the last one written ("" none).
  const std::string& path() const { return path_; }
  // The last export's outcome once it ended: true when the file was written.
  bool saved() const { return saved_; }

 private:
  void ended(const ChildExit& e);

  StatusLine& status_;
  std::string program_;
  ChildProcess child_;
  std::string said_;  // the child's standard error so far
  std::string path_;
  int percent_ = -1;
  bool saved_ = false;
};

}  // namespace mixpilot::cli
