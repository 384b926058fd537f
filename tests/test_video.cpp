// Videos of replays (`mixpilot replay REC --video OUT.mp4`) and the window's "Export clip": the
// file as ffprobe reads it, a decoded frame against `--screenshot` of the same time, the errors
// a user meets (bad values, no ffmpeg, ffmpeg failing, an existing file, ^C), and the helpers
// behind them. Clips are short and small: the suite stays fast.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <imgui.h>

#include "app/child_process.hpp"
#include "app/offscreen.hpp"
#include "app/trainer.hpp"
#include "app/video.hpp"
#include "ui/keys.hpp"
#include "ui/requests.hpp"

#include "run_mixpilot.hpp"
#include "temp_files.hpp"

extern char** environ;

namespace mixpilot {
namespace {

namespace fs = std::filesystem;

const std::string kBinary = MIXPILOT_BINARY;

std::string shell_quoted(const std::string& s) { return "'" + s + "'"; }

// The output of a shell command (stdout), "" when it failed.
std::string output_of(const std::string& command) {
  std::string out;
  if (FILE* p = ::popen(command.c_str(), "r")) {
    char buf[4096];
    std::size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
    if (::pclose(p) != 0) return "";
  }
  return out;
}

// `mixpilot ARGS` with the user's folders in `home` and `env` (NAME=VALUE ...) before it; its
// stdout and stderr in home/out.txt; the exit status.
int run(const fs::path& home, const std::string& args, const std::string& env = "") {
  const std::string cmd = "env XDG_CONFIG_HOME=" + shell_quoted((home / "config").string()) +
                          " XDG_DATA_HOME=" + shell_quoted((home / "data").string()) + " " + env + " " +
                          shell_quoted(kBinary) + " " + args + " >" + shell_quoted((home / "out.txt").string()) +
                          " 2>&1";
  const int rc = std::system(cmd.c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : 128;
}

// What ffprobe says of the video stream: KEY=VALUE lines.
std::string probe(const fs::path& video) {
  return output_of("ffprobe -v error -select_streams v:0 -count_frames -show_entries "
                   "stream=codec_name,width,height,pix_fmt,nb_read_frames,color_space "
                   "-of default=noprint_wrappers=1 " + shell_quoted(video.string()));
}

std::string field(const std::string& probed, const std::string& key) {
  const std::string k = key + "=";
  const auto at = probed.find(k);
  if (at == std::string::npos) return "";
  return probed.substr(at + k.size(), probed.find('\n', at) - at - k.size());
}

// Raw RGBA of an image or of frame `n` of a video, decoded by ffmpeg.
std::vector<std::uint8_t> rgba_of(const fs::path& file, int frame = -1) {
  const fs::path raw = file.string() + ".rgba";
  const std::string select =
      frame < 0 ? "" : " -vf " + shell_quoted("select=eq(n\\," + std::to_string(frame) + ")") + " -frames:v 1";
  const std::string cmd = "ffmpeg -v error -y -i " + shell_quoted(file.string()) + select +
                          " -f rawvideo -pix_fmt rgba " + shell_quoted(raw.string());
  if (std::system(cmd.c_str()) != 0) return {};
  return test::slurp(raw);
}

// Mean absolute difference of the colour channels [0, 255].
double mean_abs_difference(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b) {
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i + 3 < a.size() && i + 3 < b.size(); i += 4)
    for (int c = 0; c < 3; ++c, ++n) sum += std::abs(int(a[i + c]) - int(b[i + c]));
  return n ? sum / double(n) : 255.0;
}

std::vector<fs::path> files_in(const fs::path& dir) {
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(dir)) out.push_back(e.path().filename());
  return out;
}

// Saves the last frame as NAME.png in $MIXPILOT_SHOT_DIR when it is set (to look at).
void save_shot(const cli::Offscreen& screen, const std::string& name) {
  const char* dir = std::getenv("MIXPILOT_SHOT_DIR");
  if (!dir || !*dir) return;
  std::ofstream(std::string(dir) + "/" + name + ".png", std::ios::binary) << screen.png();
}

class Video : public testing::Test {
 protected:
  // One recording for every test of the process: the novice flying mi_helix for 4 s.
  static void SetUpTestSuite() {
    home_ = test::process_temp_dir() / "video_home";
    // The window's exports run `mixpilot replay` as a child of this process: never in the
    // user's folders.
    setenv("XDG_DATA_HOME", (home_ / "data").c_str(), 1);
    setenv("XDG_CONFIG_HOME", (home_ / "config").c_str(), 1);
    fs::create_directories(home_);
    recording_ = (test::process_temp_dir() / "video_rec" / "novice.mcap").string();
    fs::create_directories(fs::path(recording_).parent_path());
    const int rc = run(home_, "fly --scenario " +
                                  shell_quoted(std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/mi_helix.toml") +
                                  " --pilot novice --headless --duration 4 --history off --record " +
                                  shell_quoted(recording_));
    recorded_ = rc == 0;
  }

  void SetUp() override {
    ASSERT_TRUE(recorded_) << test::read_file(home_ / "out.txt");
    std::string error;
    {
      cli::Offscreen probe_egl;
      if (!probe_egl.open(64, 64, error)) GTEST_SKIP() << "no EGL device, nothing renders: " << error;
    }
    const char* path = std::getenv("PATH");
    ASSERT_FALSE(cli::find_program("ffmpeg", path ? path : "/usr/bin:/bin").empty())
        << "ffmpeg is not installed (packaging/setup-debian.sh installs it)";
    dir_ = test::fresh_path("video", testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }

  std::string said() const { return test::read_file(home_ / "out.txt"); }

  static fs::path home_;
  static std::string recording_;
  static bool recorded_;
  fs::path dir_;
};

fs::path Video::home_;
std::string Video::recording_;
bool Video::recorded_ = false;

TEST_F(Video, FfprobeReadsCodecSizeAndFrameCount) {
  const fs::path out = dir_ / "clip.mp4";
  ASSERT_EQ(run(home_, "replay " + shell_quoted(recording_) + " --video " + shell_quoted(out.string()) +
                           " --from 1 --to 3 --fps 15 --size 320x180"),
            0)
      << said();
  EXPECT_NE(said().find("video " + out.string()), std::string::npos) << said();
  const std::string p = probe(out);
  EXPECT_EQ(field(p, "codec_name"), "h264") << p;
  EXPECT_EQ(field(p, "width"), "320") << p;
  EXPECT_EQ(field(p, "height"), "180") << p;
  EXPECT_EQ(field(p, "pix_fmt"), "yuv420p") << p;
  EXPECT_EQ(field(p, "color_space"), "bt709") << p;
  EXPECT_NEAR(std::atof(field(p, "nb_read_frames").c_str()), 2.0 * 15, 1.0) << p;
  // Nothing beside it: the temporary was moved into place.
  EXPECT_EQ(files_in(dir_), std::vector<fs::path>{"clip.mp4"});
}

// The whole recording by default, at 30 fps.
TEST_F(Video, DefaultsAreTheWholeRecordingAt30Fps) {
  const fs::path out = dir_ / "all.mp4";
  ASSERT_EQ(run(home_, "replay " + shell_quoted(recording_) + " --video " + shell_quoted(out.string()) +
                           " --size 160x90"),
            0)
      << said();
  const std::string p = probe(out);
  EXPECT_NEAR(std::atof(field(p, "nb_read_frames").c_str()), 4.0 * 30, 1.0) << p;
}

// Frame i shows time from + i/fps as --screenshot shows it: a decoded frame mid-step (not on a
// step boundary, Δt = 15 ms) against the screenshot of that time.
TEST_F(Video, DecodedFrameMatchesScreenshot) {
  const fs::path out = dir_ / "clip.mp4", shot = dir_ / "shot.png";
  constexpr double kFrom = 1.0075, kFps = 10.0;
  constexpr int kFrame = 7;
  const double t = kFrom + kFrame / kFps;  // 1.7075 s: step 113 of 15 ms, 0.0125 s into it
  // At the default size: 4:2:0 halves the colour's resolution, which costs a smaller share
  // of a larger frame's pixels (thin coloured lines and small text).
  ASSERT_EQ(run(home_, "replay " + shell_quoted(recording_) + " --video " + shell_quoted(out.string()) +
                           " --from 1.0075 --to 2.5 --fps 10"),
            0)
      << said();
  char at[64];
  std::snprintf(at, sizeof at, "%.4f:", t);
  ASSERT_EQ(run(home_, "replay " + shell_quoted(recording_) + " --headless --screenshot " +
                           shell_quoted(at + shot.string())),
            0)
      << said();
  const auto frame = rgba_of(out, kFrame);
  const auto screenshot = rgba_of(shot);
  ASSERT_EQ(frame.size(), std::size_t(1280 * 720 * 4));
  ASSERT_EQ(screenshot.size(), frame.size());
  // x264's quantisation and 4:2:0 chroma on thin lines and small text: about 2/255 on
  // average, more when the RTI-time plot (which follows the machine's load while the recording
  // was flown) is jagged.
  const double difference = mean_abs_difference(frame, screenshot);
  EXPECT_LE(difference, 3.0);
  RecordProperty("mean_abs_difference", std::to_string(difference));
  // The neighbouring frames show other times: the comparison can tell frames apart.
  const auto other = rgba_of(out, kFrame + 5);
  const double other_difference = mean_abs_difference(other, screenshot);
  RecordProperty("neighbour_mean_abs_difference", std::to_string(other_difference));
  EXPECT_GT(other_difference, difference);
}

// Bad values are usage errors naming the option and what was expected; nothing is written.
TEST_F(Video, BadValuesAreNamed) {
  const std::string out = shell_quoted((dir_ / "bad.mp4").string());
  const std::string rec = shell_quoted(recording_);
  struct Case {
    std::string args, needle;
  };
  const std::vector<Case> cases = {
      {"--video " + out + " --fps 0", "--fps expects frames per second from 1 to 120, got '0'"},
      {"--video " + out + " --fps 500", "--fps expects frames per second from 1 to 120"},
      {"--video " + out + " --fps abc", "--fps expects"},
      {"--video " + out + " --from -1", "--from expects a time in seconds >= 0, got '-1'"},
      {"--video " + out + " --to nan", "--to expects a time in seconds"},
      {"--video " + out + " --from 3 --to 2", "--from 3 s is not before --to 2 s: expected --from < --to"},
      {"--video " + out + " --from 2 --to 2", "is not before --to"},
      {"--video " + out + " --to 99", "--to 99 s is beyond the recording's end ("},
      {"--video " + out + " --from 5", "--from 5 s is at or beyond the recording's end ("},
      {"--video " + out + " --size 321x180", "--size for --video expects an even width and height"},
      {"--video " + out + " --size 20x20", "--size expects WxH, each from 64 to 8192"},
      {"--video " + out + " --exit-at-end", "--exit-at-end is for the window"},
      {"--from 1", "--from goes with --video"},
      {"--fps 25 --headless", "--fps goes with --video"},
      {"--video ''", "--video needs a value"},
      {"--video " + rec, "is the same file as the recording"},
  };
  for (const Case& c : cases) {
    EXPECT_EQ(run(home_, "replay " + rec + " " + c.args), 2) << c.args << "\n" << said();
    EXPECT_NE(said().find(c.needle), std::string::npos) << c.args << "\n" << said();
  }
  EXPECT_TRUE(files_in(dir_).empty());
}

// Without ffmpeg on PATH: the package to install, exit 1, before anything is rendered.
TEST_F(Video, NoFfmpegNamesThePackage) {
  const fs::path empty = dir_ / "empty_bin";
  fs::create_directories(empty);
  const fs::path out = dir_ / "clip.mp4";
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(run(home_, "replay " + shell_quoted(recording_) + " --video " + shell_quoted(out.string()),
                "PATH=" + shell_quoted(empty.string())),
            1)
      << said();
  EXPECT_NE(said().find("mixpilot replay: --video: ffmpeg is not installed: apt install ffmpeg"),
            std::string::npos)
      << said();
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(20)) << "it rendered";
  EXPECT_EQ(files_in(dir_), std::vector<fs::path>{"empty_bin"});
}

// ffmpeg failing: the end of what it said, and no file left behind.
TEST_F(Video, FfmpegFailureShowsItsMessage) {
  const fs::path bin = dir_ / "bin";
  fs::create_directories(bin);
  {
    std::ofstream f(bin / "ffmpeg");
    f << "#!/bin/sh\ncat >/dev/null &\necho 'early line' >&2\n"
         "echo '[libx264 @ 0x1] broken encoder for this test' >&2\nexit 1\n";
  }
  fs::permissions(bin / "ffmpeg", fs::perms::owner_all);
  const fs::path out = dir_ / "clip.mp4";
  EXPECT_EQ(run(home_, "replay " + shell_quoted(recording_) + " --video " + shell_quoted(out.string()) +
                           " --to 1 --size 160x90",
                "PATH=" + shell_quoted(bin.string() + ":/usr/bin:/bin")),
            1)
      << said();
  EXPECT_NE(said().find("[libx264 @ 0x1] broken encoder for this test (exit status 1)"),
            std::string::npos)
      << said();
  EXPECT_EQ(files_in(dir_), std::vector<fs::path>{"bin"});
}

// An existing OUT is refused without --force (untouched), replaced with it.
TEST_F(Video, ExistingFileRefusedWithoutForce) {
  const fs::path out = dir_ / "clip.mp4";
  std::ofstream(out) << "keep me";
  const std::string args = "replay " + shell_quoted(recording_) + " --video " + shell_quoted(out.string()) +
                           " --to 0.5 --size 160x90";
  EXPECT_EQ(run(home_, args), 1) << said();
  EXPECT_NE(said().find(out.string() + ": File exists (refusing to overwrite it)"), std::string::npos)
      << said();
  EXPECT_EQ(test::read_file(out), "keep me");
  ASSERT_EQ(run(home_, args + " --force"), 0) << said();
  EXPECT_EQ(field(probe(out), "codec_name"), "h264");
  EXPECT_EQ(files_in(dir_), std::vector<fs::path>{"clip.mp4"});
}

// ^C while frames are encoded: exit 130, no OUT and no temporary.
TEST_F(Video, InterruptLeavesNoFile) {
  const fs::path out = dir_ / "clip.mp4";
  const std::string env_home = "XDG_DATA_HOME=" + (home_ / "data").string();
  const std::string env_config = "XDG_CONFIG_HOME=" + (home_ / "config").string();
  std::vector<std::string> args = {kBinary, "replay", recording_, "--video", out.string(),
                                   "--fps", "60", "--size", "640x360"};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::vector<std::string> env_strings = {env_home, env_config};
  for (char** e = environ; *e; ++e)
    if (!std::string(*e).starts_with("XDG_")) env_strings.push_back(*e);
  std::vector<char*> envp;
  for (std::string& e : env_strings) envp.push_back(e.data());
  envp.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, (dir_ / "../interrupt.txt").c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = -1;
  ASSERT_EQ(posix_spawn(&pid, kBinary.c_str(), &actions, nullptr, argv.data(), envp.data()), 0);
  posix_spawn_file_actions_destroy(&actions);
  // Once the encoder's temporary exists, frames are being piped to ffmpeg.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (test::temporaries_of(out).empty() && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_FALSE(test::temporaries_of(out).empty()) << "the video never started";
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  ::kill(pid, SIGINT);
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  const std::string err = test::read_file(dir_ / "../interrupt.txt");
  ASSERT_TRUE(WIFEXITED(status)) << err;
  EXPECT_EQ(WEXITSTATUS(status), 130) << err;
  EXPECT_NE(err.find("interrupted; no video written"), std::string::npos) << err;
  EXPECT_TRUE(files_in(dir_).empty());
}

// The window's Export clip (E in a replay): the playhead ± 5 s written beside the recording
// under a numbered name by a child process, its progress and result in the status line, while
// the frames go on.
TEST_F(Video, ExportClipFromTheWindow) {
  cli::Offscreen screen;
  std::string error;
  ASSERT_TRUE(screen.open(1280, 720, error)) << error;
  // The clips go beside a copy of the recording, in this test's folder.
  const fs::path rec = dir_ / "flight.mcap";
  fs::copy_file(recording_, rec);
  cli::FlyOptions o;
  o.replay = true;
  o.pilot = rec.string();
  o.history = "off";
  cli::Trainer app(o);
  app.clips().set_program(kBinary);
  ASSERT_TRUE(app.open_replay(rec.string(), error)) << error;
  app.load_replay();
  const auto frame = [&] { screen.frame([&] { app.build_frame(0.0); }); };
  frame();
  app.seek(1.0);  // the window is [0, 6) s clipped to the recording's [0, 4) s
  frame();
  ImGuiIO& io = ImGui::GetIO();
  ui::set_key(io, ui::kExportClipKey, true);
  frame();
  ui::set_key(io, ui::kExportClipKey, false);
  EXPECT_TRUE(app.clips().running());
  EXPECT_EQ(app.clips().path(), (dir_ / "flight-clip-1.mp4").string());
  EXPECT_NE(app.run_info().message.find("exporting"), std::string::npos) << app.run_info().message;
  // A second export while one runs is refused in the status line.
  app.act(ui::ExportClip{0.0, 1.0});
  EXPECT_NE(app.run_info().message.find("being exported already"), std::string::npos);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(180);
  auto slowest = std::chrono::steady_clock::duration::zero();
  bool shot = false;
  while (app.clips().running() && std::chrono::steady_clock::now() < deadline) {
    const auto t0 = std::chrono::steady_clock::now();
    frame();
    slowest = std::max(slowest, std::chrono::steady_clock::now() - t0);
    if (!shot && app.run_info().message.ends_with(" %")) {
      save_shot(screen, "export_clip_progress");
      shot = true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  frame();
  save_shot(screen, "export_clip_saved");
  ASSERT_FALSE(app.clips().running());
  EXPECT_TRUE(app.clips().saved()) << app.run_info().message;
  EXPECT_EQ(app.run_info().message, "clip saved: " + (dir_ / "flight-clip-1.mp4").string());
  // The UI thread only polls: a frame never waited for the child's rendering.
  EXPECT_LT(slowest, std::chrono::seconds(2));
  const std::string p = probe(dir_ / "flight-clip-1.mp4");
  EXPECT_EQ(field(p, "width"), "1280") << p;
  EXPECT_NEAR(std::atof(field(p, "nb_read_frames").c_str()), 4.0 * 30, 1.0) << p;
  // Never over an earlier clip: the next one is numbered 2.
  app.act(ui::clip_around(3.5, 4.0, 0.25));
  EXPECT_EQ(app.clips().path(), (dir_ / "flight-clip-2.mp4").string());
  while (app.clips().running() && std::chrono::steady_clock::now() < deadline) {
    frame();
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_TRUE(app.clips().saved()) << app.run_info().message;
  EXPECT_NEAR(std::atof(field(probe(dir_ / "flight-clip-2.mp4"), "nb_read_frames").c_str()),
              0.5 * 30, 1.0);
}

// ---- the helpers ------------------------------------------------------------------------

TEST(VideoHelpers, FramesOfAWindow) {
  EXPECT_EQ(cli::frame_count(0.0, 3.0, 30.0), 90);
  EXPECT_EQ(cli::frame_count(1.0, 3.0, 15.0), 30);
  EXPECT_EQ(cli::frame_count(0.0, 0.1, 30.0), 3);  // 0, 1/30, 2/30 < 0.1; 3/30 is not
  EXPECT_EQ(cli::frame_count(0.0, 0.101, 30.0), 4);
  EXPECT_EQ(cli::frame_count(2.0, 2.0, 30.0), 0);
  EXPECT_DOUBLE_EQ(cli::frame_time(1.0, 10.0, 7), 1.7);
}

TEST(VideoHelpers, ParsedValues) {
  EXPECT_EQ(cli::parse_fps("30"), 30.0);
  EXPECT_EQ(cli::parse_fps("29.97"), 29.97);
  EXPECT_FALSE(cli::parse_fps("0.5"));
  EXPECT_FALSE(cli::parse_fps("121"));
  EXPECT_FALSE(cli::parse_fps("inf"));
  EXPECT_FALSE(cli::parse_fps("30fps"));
  EXPECT_EQ(cli::parse_time("0"), 0.0);
  EXPECT_FALSE(cli::parse_time("-0.1"));
  EXPECT_FALSE(cli::parse_time(""));
  EXPECT_FALSE(cli::parse_time("nan"));
}

TEST(VideoHelpers, RangeProblems) {
  EXPECT_EQ(cli::range_problem(0, 4, false, 4), "");
  EXPECT_EQ(cli::range_problem(1, 2, true, 4), "");
  EXPECT_NE(cli::range_problem(4, 4, false, 4).find("at or beyond the recording's end"), std::string::npos);
  EXPECT_NE(cli::range_problem(0, 5, true, 4).find("--to 5 s is beyond"), std::string::npos);
  EXPECT_NE(cli::range_problem(2, 1, true, 4).find("not before"), std::string::npos);
}

TEST(VideoHelpers, FfmpegCommandLine) {
  const auto args = cli::ffmpeg_arguments({640, 360, 25.0}, "/tmp/a b.mp4.XyZ123.tmp");
  const auto has = [&](const std::string& a, const std::string& b) {
    for (std::size_t i = 0; i + 1 < args.size(); ++i)
      if (args[i] == a && args[i + 1] == b) return true;
    return false;
  };
  EXPECT_TRUE(has("-video_size", "640x360"));
  EXPECT_TRUE(has("-framerate", "25"));
  EXPECT_TRUE(has("-pix_fmt", "rgba"));
  EXPECT_TRUE(has("-c:v", "libx264"));
  EXPECT_TRUE(has("-pix_fmt", "yuv420p"));
  EXPECT_TRUE(has("-f", "mp4"));
  // The output is one argument, as given (no shell), read as a file whatever its name.
  EXPECT_EQ(args.back(), "file:/tmp/a b.mp4.XyZ123.tmp");
}

TEST(VideoHelpers, ChildOutputs) {
  EXPECT_EQ(cli::last_lines("a\nb\nc\n", 2), "b\nc");
  EXPECT_EQ(cli::last_lines("a\nb\nc", 5), "a\nb\nc");
  EXPECT_EQ(cli::last_lines("", 2), "");
  EXPECT_EQ(cli::last_percent(""), -1);
  EXPECT_EQ(cli::last_percent("video a.mp4: 10 %\nvideo a.mp4: 20 %\n"), 20);
  EXPECT_EQ(cli::last_percent("video a.mp4: 10 %\nvideo a.mp4: 2"), 10);  // a line half written
  EXPECT_EQ(cli::last_percent("video a.mp4: 100 %\nmixpilot replay: done\n"), 100);
}

TEST(VideoHelpers, NumberedClipNames) {
  const fs::path dir = test::fresh_path("video", "numbered");
  fs::create_directories(dir);
  const std::string rec = (dir / "flight.mcap").string();
  EXPECT_EQ(cli::numbered_clip_path(rec), (dir / "flight-clip-1.mp4").string());
  std::ofstream(dir / "flight-clip-1.mp4") << "x";
  fs::create_symlink("nowhere", dir / "flight-clip-2.mp4");  // a dangling link is something too
  EXPECT_EQ(cli::numbered_clip_path(rec), (dir / "flight-clip-3.mp4").string());
  const ui::ExportClip c = ui::clip_around(2.0, 30.0);
  EXPECT_EQ(c.from, 0.0);
  EXPECT_EQ(c.to, 7.0);
  const ui::ExportClip end = ui::clip_around(28.0, 30.0);
  EXPECT_EQ(end.from, 23.0);
  EXPECT_EQ(end.to, 30.0);
}

TEST(VideoHelpers, FindProgram) {
  const fs::path dir = test::fresh_path("video", "path");
  fs::create_directories(dir / "a");
  fs::create_directories(dir / "b");
  std::ofstream(dir / "a" / "tool") << "not executable";
  std::ofstream(dir / "b" / "tool") << "#!/bin/sh\n";
  fs::permissions(dir / "b" / "tool", fs::perms::owner_all);
  const std::string path = (dir / "a").string() + ":" + (dir / "b").string();
  EXPECT_EQ(cli::find_program("tool", path), (dir / "b" / "tool").string());
  EXPECT_EQ(cli::find_program("tool", (dir / "a").string()), "");
  EXPECT_EQ(cli::find_program("tool", ""), "");
  EXPECT_EQ(cli::find_program((dir / "b" / "tool").string(), ""), (dir / "b" / "tool").string());
}

}  // namespace
}  // namespace mixpilot
