#pragma once
// `mixpilot replay REC --video OUT.mp4`: what a video of a replay is made of, apart from the
// rendering and the encoder's process (app/video_replay.hpp, app/video_encoder.hpp): the
// options, which frames show which time, ffmpeg's command line, the names of exported clips.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace mixpilot::cli {

// The Debian package that provides ffmpeg, for the message when it is missing.
inline constexpr const char* kFfmpegMissing = "ffmpeg is not installed: apt install ffmpeg";

inline constexpr double kMaxFps = 120.0;
inline constexpr double kMinFps = 1.0;

struct VideoOptions {
  std::string path;          // OUT.mp4 ("": no video)
  double from = 0.0;         // [s] the first frame's time
  std::optional<double> to;  // [s] the end (default: the recording's)
  double fps = 30.0;
};

// --from / --to: a finite time in seconds ≥ 0; nullopt when malformed.
std::optional<double> parse_time(std::string_view text);
// --fps: frames per second from kMinFps to kMaxFps; nullopt otherwise.
std::optional<double> parse_fps(std::string_view text);

// The frames of [from, to) at `fps`: frame i shows time from + i / fps, every one before `to`.
std::int64_t frame_count(double from, double to, double fps);
inline double frame_time(double from, double fps, std::int64_t i) { return from + double(i) / fps; }

// Why [from, to) cannot be cut from a recording `end` seconds long ("" when it can), naming the
// options as the user gave them (`to_given`: --to was on the command line).
std::string range_problem(double from, double to, bool to_given, double end);

struct VideoFormat {
  int width = 1280, height = 720;  // even: H.264 in 4:2:0 halves both for its colour planes
  double fps = 30.0;
};

// ffmpeg's arguments (after its name): raw RGBA frames of `f`, bottom row first (as OpenGL
// reads them), on its standard input; H.264 (libx264, a fast preset, yuv420p, BT.709 tagged)
// in an MP4 file at `output`, which ffmpeg overwrites (it is this run's own temporary).
std::vector<std::string> ffmpeg_arguments(const VideoFormat& f, const std::string& output);

// The last `lines` lines of `text` (a child's standard error), without a trailing newline.
std::string last_lines(std::string_view text, int lines);

// The newest progress in `text`, a child's standard error with lines "LABEL: N %" (as
// cli::Progress prints them when stderr is no terminal); -1 when none yet.
int last_percent(std::string_view text);

// A clip of a replay saved from the window: beside the recording, "<stem>-clip-N.mp4" with the
// smallest N ≥ 1 whose file does not exist (an earlier clip is never replaced).
std::string numbered_clip_path(const std::string& recording);

}  // namespace mixpilot::cli
