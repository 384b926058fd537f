#pragma once
// A video file written by ffmpeg (app/video.hpp gives its command line): frames piped to its
// standard input as they are rendered, the file written into a temporary beside the target
// (core/base/output_file.hpp) that is moved into place only once ffmpeg has finished it. A
// failure or ^C leaves nothing behind.
#include <condition_variable>
#include <csignal>
#include <cstdint>
#include <deque>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "app/child_process.hpp"
#include "app/video.hpp"
#include "core/base/output_file.hpp"

namespace mixpilot::cli {

class VideoEncoder {
 public:
  VideoEncoder() = default;
  VideoEncoder(const VideoEncoder&) = delete;
  VideoEncoder& operator=(const VideoEncoder&) = delete;
  ~VideoEncoder();  // unfinished: ffmpeg stopped, nothing kept

  // Starts `ffmpeg` (its path) encoding to `path` (over an existing file only with
  // `overwrite`); false with the reason.
  [[nodiscard]] bool open(const std::string& ffmpeg, const VideoFormat& format,
                          const std::string& path, bool overwrite, std::string& error);

  enum class Status { ok, failed, interrupted };
  // One frame: width × height × 4 bytes of RGBA, bottom row first, handed over by swapping:
  // `rgba` comes back as a buffer to fill with the next frame. The pipe is written on a thread
  // of its own, so the next frame renders while ffmpeg takes this one (this waits only when
  // two frames are queued). `failed`: ffmpeg stopped (the error has the end of what it said);
  // `interrupted`: ^C (cli::interrupted()).
  [[nodiscard]] Status write(std::vector<std::uint8_t>& rgba, std::string& error);
  // No more frames: waits for ffmpeg to finish the file, then moves it into place; false with
  // the reason (and nothing kept).
  [[nodiscard]] bool finish(std::string& error);
  // Stops ffmpeg and removes its temporary.
  void abort();

 private:
  void write_frames();  // the writer thread
  // After the writer stopped on a failed write: ffmpeg reaped, nothing kept, the reason.
  Status failed(std::string& error);
  void join_threads();
  // What ffmpeg said, for a message: its last lines, or its exit when it said nothing.
  std::string ffmpeg_said(const ChildExit& e);

  VideoFormat format_;
  std::size_t frame_bytes_ = 0;
  OutputFile out_;
  ChildProcess ffmpeg_;

  // Frames on their way to the pipe: queued by write(), written and handed back as spares by
  // the writer thread.
  std::thread writer_;
  std::mutex frames_mutex_;
  std::condition_variable frames_changed_;
  std::deque<std::vector<std::uint8_t>> queued_;
  std::vector<std::vector<std::uint8_t>> spares_;
  bool closing_ = false;  // no more frames come
  ChildProcess::Write outcome_ = ChildProcess::Write::done;  // the writer's first failure

  // ffmpeg's standard error, read on a thread of its own: a full pipe would stall ffmpeg, and
  // with it the frames written to it.
  std::thread reader_;
  std::mutex said_mutex_;
  std::string said_;  // the end of it, bounded
  struct sigaction old_pipe_ {};
  bool pipe_ignored_ = false;
};

}  // namespace mixpilot::cli
