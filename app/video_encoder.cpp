#include "app/video_encoder.hpp"

#include "app/cli.hpp"

namespace mixpilot::cli {

namespace {

constexpr std::size_t kSaidBytes = 16 << 10;  // of ffmpeg's standard error, the newest kept
constexpr int kSaidLines = 6;                 // in a message
constexpr std::size_t kQueuedFrames = 2;      // rendered, not yet taken by ffmpeg

}  // namespace

VideoEncoder::~VideoEncoder() {
  abort();
  if (pipe_ignored_) sigaction(SIGPIPE, &old_pipe_, nullptr);
}

bool VideoEncoder::open(const std::string& ffmpeg, const VideoFormat& format,
                        const std::string& path, bool overwrite, std::string& error) {
  format_ = format;
  frame_bytes_ = std::size_t(format.width) * std::size_t(format.height) * 4;
  if (!out_.open(path, overwrite, error)) return false;
  // A write to a pipe whose reader has gone raises SIGPIPE, which would end this process
  // without a word: ignored, the write fails and ffmpeg's own message is shown.
  if (!pipe_ignored_) {
    struct sigaction ignore {};
    ignore.sa_handler = SIG_IGN;
    sigemptyset(&ignore.sa_mask);
    pipe_ignored_ = sigaction(SIGPIPE, &ignore, &old_pipe_) == 0;
  }
  if (!ffmpeg_.start(ffmpeg, ffmpeg_arguments(format, out_.temp_path()),
                     ChildProcess::Input::pipe, error)) {
    out_.discard();
    return false;
  }
  closing_ = false;
  outcome_ = ChildProcess::Write::done;
  reader_ = std::thread([this] {
    std::string chunk;
    while (true) {
      chunk.clear();
      const bool more = ffmpeg_.read_error(chunk);
      {
        std::lock_guard<std::mutex> lock(said_mutex_);
        said_ += chunk;
        if (said_.size() > kSaidBytes) said_.erase(0, said_.size() - kSaidBytes);
      }
      if (!more) break;
    }
  });
  writer_ = std::thread([this] { write_frames(); });
  return true;
}

void VideoEncoder::write_frames() {
  std::unique_lock<std::mutex> lock(frames_mutex_);
  while (true) {
    frames_changed_.wait(lock, [&] { return !queued_.empty() || closing_; });
    if (queued_.empty()) return;  // closing, every frame written
    std::vector<std::uint8_t> frame = std::move(queued_.front());
    queued_.pop_front();
    lock.unlock();
    const ChildProcess::Write w = ffmpeg_.write(frame.data(), frame_bytes_, &interrupted);
    lock.lock();
    spares_.push_back(std::move(frame));
    frames_changed_.notify_all();
    if (w != ChildProcess::Write::done) {
      outcome_ = w;
      return;
    }
  }
}

VideoEncoder::Status VideoEncoder::write(std::vector<std::uint8_t>& rgba, std::string& error) {
  if (rgba.size() != frame_bytes_) {
    error = "a frame of " + std::to_string(rgba.size()) + " bytes where " +
            std::to_string(frame_bytes_) + " are expected";
    abort();
    return Status::failed;
  }
  {
    std::unique_lock<std::mutex> lock(frames_mutex_);
    frames_changed_.wait(lock, [&] {
      return queued_.size() < kQueuedFrames || outcome_ != ChildProcess::Write::done;
    });
    if (outcome_ == ChildProcess::Write::done) {
      queued_.push_back(std::move(rgba));
      if (!spares_.empty()) {
        rgba = std::move(spares_.back());
        spares_.pop_back();
      } else {
        rgba.clear();
      }
      frames_changed_.notify_all();
      return Status::ok;
    }
  }
  return failed(error);
}

VideoEncoder::Status VideoEncoder::failed(std::string& error) {
  if (writer_.joinable()) writer_.join();
  if (outcome_ == ChildProcess::Write::interrupted) {
    abort();
    error = "interrupted";
    return Status::interrupted;
  }
  const ChildExit e = ffmpeg_.wait();
  join_threads();
  out_.discard();
  error = "ffmpeg stopped before the last frame: " + ffmpeg_said(e);
  return Status::failed;
}

bool VideoEncoder::finish(std::string& error) {
  if (!ffmpeg_.running()) {
    error = "the video encoder is not running";
    return false;
  }
  {
    std::lock_guard<std::mutex> lock(frames_mutex_);
    closing_ = true;
    frames_changed_.notify_all();
  }
  if (writer_.joinable()) writer_.join();
  if (outcome_ != ChildProcess::Write::done) {
    (void)failed(error);
    return false;
  }
  ffmpeg_.close_input();
  const ChildExit e = ffmpeg_.wait();
  join_threads();
  if (!e.ok()) {
    out_.discard();
    error = "ffmpeg failed: " + ffmpeg_said(e);
    return false;
  }
  // A video cut short is of no use: a file that cannot be moved into place is not kept.
  return out_.commit(error, /*keep_partial=*/false);
}

void VideoEncoder::abort() {
  // ffmpeg killed first: a write blocked on its pipe returns, and the writer with it.
  if (ffmpeg_.running()) ffmpeg_.signal(SIGKILL);
  {
    std::lock_guard<std::mutex> lock(frames_mutex_);
    closing_ = true;
    queued_.clear();
    frames_changed_.notify_all();
  }
  if (writer_.joinable()) writer_.join();
  if (ffmpeg_.running()) (void)ffmpeg_.wait();
  join_threads();
  out_.discard();
}

void VideoEncoder::join_threads() {
  if (writer_.joinable()) writer_.join();
  // ffmpeg has ended: its standard error reaches its end and the reader returns.
  if (reader_.joinable()) reader_.join();
}

std::string VideoEncoder::ffmpeg_said(const ChildExit& e) {
  std::lock_guard<std::mutex> lock(said_mutex_);
  const std::string tail = last_lines(said_, kSaidLines);
  return tail.empty() ? "it ended with " + to_string(e) + " and said nothing"
                      : tail + " (" + to_string(e) + ")";
}

}  // namespace mixpilot::cli
