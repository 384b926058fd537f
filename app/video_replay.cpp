#include "app/video_replay.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "app/cli.hpp"
#include "app/offscreen.hpp"
#include "app/trainer.hpp"
#include "app/video.hpp"
#include "app/video_encoder.hpp"

namespace mixpilot::cli {

namespace {

// The recording's end as replayed so far [s]: its steps as recorded while loading, as flown
// once loaded (a lost vehicle ends a replay early).
double replay_end(const ReplayTape& tape) { return double(tape.steps()) * tape.dt(); }

// The video's end: --to, else the recording's; a usage error where [from, to) cannot be cut.
double checked_end(const FlyOptions& o, double end) {
  const double to = o.video.to.value_or(end);
  if (const std::string why = range_problem(o.video.from, to, o.video.to.has_value(), end);
      !why.empty())
    usage_error(o.command, why);
  return to;
}

int fail(const FlyOptions& o, const std::string& message) {
  std::fprintf(stderr, "mixpilot %s: %s\n", o.command, message.c_str());
  return kExitError;
}

}  // namespace

int replay_to_video(const FlyOptions& o) {
  const VideoOptions& v = o.video;
  catch_interrupts();
  // As execvp searches: PATH, or the system's folders where it is unset.
  const char* search = std::getenv("PATH");
  const std::string ffmpeg = find_program("ffmpeg", search ? search : "/bin:/usr/bin");
  if (ffmpeg.empty()) return fail(o, std::string("--video: ") + kFfmpegMissing);
  std::string error;
  if (!check_outputs(o, error)) return fail(o, error);

  // A replay is no flight of the history's: the video leaves it alone.
  FlyOptions quiet = o;
  quiet.history = "off";
  Trainer app(quiet);
  if (!app.open_replay(o.pilot, error)) return fail(o, error);
  (void)checked_end(o, replay_end(*app.replay()));  // before the long part: the recorded length
  for (const ScreenshotRequest& r : o.screenshots)
    if (r.t >= replay_end(*app.replay()))
      usage_error(o.command, "--screenshot at t = " + seconds_text(r.t) +
                                 " s is beyond the recording's end (" +
                                 seconds_text(replay_end(*app.replay())) + " s)");
  Offscreen screen;
  if (!screen.open(o.width, o.height, error, o.scale > 0 ? o.scale : 1.0f))
    return fail(o, "--video: " + error);
  app.load_replay();
  if (interrupted()) {
    std::fprintf(stderr, "mixpilot %s: interrupted; no video written\n", o.command);
    return kExitInterrupted;
  }
  if (!app.replay_ghost_error().empty()) return fail(o, "--ghost " + app.replay_ghost_error());
  const double to = checked_end(o, replay_end(*app.replay()));

  // What --screenshot writes, as `replay --headless` writes it.
  int status = kExitOk;
  const auto show = [&](double t) {
    app.seek(t);
    // Two passes, as a screenshot has: ImGui sizes some items from the pass before. The first
    // only lays out, which costs a fraction of a rendered frame.
    screen.layout([&] { app.build_frame(0.0); });
    screen.frame([&] { app.build_frame(0.0); });
  };
  for (const ScreenshotRequest& r : o.screenshots) {
    show(r.t);
    if (!write_file(r.path, screen.png(), o.force, error)) {
      std::fprintf(stderr, "mixpilot %s: %s\n", o.command, error.c_str());
      status = kExitError;
    } else {
      std::printf("  screenshot %s\n", r.path.c_str());
    }
  }

  const std::int64_t frames = frame_count(v.from, to, v.fps);
  VideoEncoder video;
  if (!video.open(ffmpeg, VideoFormat{o.width, o.height, v.fps}, v.path, o.force, error))
    return fail(o, "--video: " + error);
  const auto t0 = std::chrono::steady_clock::now();
  {
    Progress progress("video " + v.path, frames, Progress::Piped::tenths);
    std::vector<std::uint8_t> rgba;
    for (std::int64_t i = 0; i < frames; ++i) {
      if (interrupted()) {
        video.abort();
        progress.finish();
        std::fprintf(stderr, "mixpilot %s: interrupted; no video written\n", o.command);
        return kExitInterrupted;
      }
      show(frame_time(v.from, v.fps, i));
      screen.read_bottom_up(rgba);
      switch (video.write(rgba, error)) {
        case VideoEncoder::Status::ok:
          break;
        case VideoEncoder::Status::interrupted:
          progress.finish();
          std::fprintf(stderr, "mixpilot %s: interrupted; no video written\n", o.command);
          return kExitInterrupted;
        case VideoEncoder::Status::failed:
          progress.finish();
          return fail(o, "--video " + v.path + ": " + error);
      }
      progress.update(i + 1);
    }
  }
  if (!video.finish(error)) return fail(o, "--video " + v.path + ": " + error);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("  video %s: %lld frames of %dx%d at %g fps, t = %s to %s s, encoded in %.1f s\n",
              v.path.c_str(), static_cast<long long>(frames), o.width, o.height, v.fps,
              seconds_text(v.from).c_str(), seconds_text(to).c_str(), wall);
  const int finished = app.finish();
  return status != kExitOk ? status : finished;
}

}  // namespace mixpilot::cli
