#include "app/video.hpp"

#include <sys/stat.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

namespace mixpilot::cli {

namespace {

std::optional<double> parse_number(std::string_view text) {
  const std::string v(text);
  char* end = nullptr;
  const double d = std::strtod(v.c_str(), &end);
  if (v.empty() || end != v.c_str() + v.size() || !std::isfinite(d)) return std::nullopt;
  return d;
}

// "%g" with the digits a time needs to tell frames apart.
std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

}  // namespace

std::optional<double> parse_time(std::string_view text) {
  const auto d = parse_number(text);
  if (!d || *d < 0.0) return std::nullopt;
  return *d;
}

std::optional<double> parse_fps(std::string_view text) {
  const auto d = parse_number(text);
  if (!d || *d < kMinFps || *d > kMaxFps) return std::nullopt;
  return *d;
}

std::int64_t frame_count(double from, double to, double fps) {
  if (!(to > from) || !(fps > 0.0)) return 0;
  // Frame i is shown when from + i / fps < to; the slack keeps a whole number of frames from
  // growing by one through rounding ((to − from)·fps = 90.000000001).
  return std::int64_t(std::ceil((to - from) * fps - 1e-6));
}

std::string range_problem(double from, double to, bool to_given, double end) {
  const std::string e = number_text(end);
  if (from >= end)
    return "--from " + number_text(from) + " s is at or beyond the recording's end (" + e +
           " s): expected a time from 0 to less than " + e + " s";
  if (to_given && to > end + 1e-9)
    return "--to " + number_text(to) + " s is beyond the recording's end (" + e +
           " s): expected a time up to " + e + " s";
  if (to <= from)
    return "--from " + number_text(from) + " s is not before --to " + number_text(to) +
           " s: expected --from < --to";
  return "";
}

std::vector<std::string> ffmpeg_arguments(const VideoFormat& f, const std::string& output) {
  const std::string size = std::to_string(f.width) + "x" + std::to_string(f.height);
  return {
      "-hide_banner", "-nostats", "-loglevel", "error",
      // The input: raw frames as the renderer reads them.
      "-f", "rawvideo", "-pix_fmt", "rgba", "-video_size", size, "-framerate",
      number_text(f.fps), "-i", "pipe:0",
      // Flipped upright (free: ffmpeg only walks the rows backwards) and converted to BT.709,
      // the colour space players assume for HD, tagged as such.
      "-vf", "vflip,scale=out_color_matrix=bt709:out_range=tv,format=yuv420p",
      "-colorspace", "bt709", "-color_primaries", "bt709", "-color_trc", "bt709",
      "-color_range", "tv",
      // H.264 that every player reads. A fast preset leaves the cores to the renderer, which
      // takes most of a frame's time; tuned for fidelity rather than perceived detail (no psy
      // optimizations), at a quality that keeps thin lines and small text crisp.
      "-c:v", "libx264", "-preset", "superfast", "-tune", "psnr", "-crf", "18", "-pix_fmt",
      "yuv420p", "-an",
      // The index at the front: a clip plays while it downloads.
      "-movflags", "+faststart", "-f", "mp4", "-y", "file:" + output};
}

std::string last_lines(std::string_view text, int lines) {
  if (lines <= 0) return "";
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.remove_suffix(1);
  std::size_t begin = text.size();  // the newline before the lines kept so far
  for (int n = 0; n < lines; ++n) {
    const std::size_t nl = begin == 0 ? std::string_view::npos : text.rfind('\n', begin - 1);
    if (nl == std::string_view::npos) return std::string(text);
    begin = nl;
  }
  return std::string(text.substr(begin + 1));
}

int last_percent(std::string_view text) {
  // The newest complete line that ends in "N %".
  std::size_t end = text.rfind('\n');
  while (end != std::string_view::npos && end > 0) {
    const std::size_t begin = text.rfind('\n', end - 1);
    std::string_view line = text.substr(begin == std::string_view::npos ? 0 : begin + 1,
                                        end - (begin == std::string_view::npos ? 0 : begin + 1));
    if (line.size() >= 3 && line.substr(line.size() - 2) == " %") {
      line.remove_suffix(2);
      std::size_t digits = 0;
      while (digits < line.size() && digits < 3 &&
             std::isdigit(static_cast<unsigned char>(line[line.size() - 1 - digits])))
        ++digits;
      if (digits > 0) {
        const int p = std::atoi(std::string(line.substr(line.size() - digits)).c_str());
        if (p <= 100) return p;
      }
    }
    if (begin == std::string_view::npos) break;
    end = begin;
  }
  return -1;
}

std::string numbered_clip_path(const std::string& recording) {
  const std::filesystem::path rec(recording);
  const std::string stem = rec.stem().string();
  for (int n = 1;; ++n) {
    const std::filesystem::path p = rec.parent_path() / (stem + "-clip-" + std::to_string(n) + ".mp4");
    struct stat st {};
    if (::lstat(p.c_str(), &st) != 0) return p.string();
  }
}

}  // namespace mixpilot::cli
