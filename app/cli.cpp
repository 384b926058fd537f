#include "app/cli.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "core/base/output_file.hpp"

namespace mixpilot::cli {

void usage_error(const char* command, const std::string& message) {
  throw UsageError{command, message};
}

std::string usage_message(const char* command, const std::string& message) {
  return message + " (see 'mixpilot " + command + " --help')";
}

void print_usage_error(const UsageError& e) {
  std::fprintf(stderr, "mixpilot %s: %s\n", e.command.c_str(),
               usage_message(e.command.c_str(), e.message).c_str());
}

std::string option_value(const char* command, int argc, char** argv, int& i) {
  const std::string option = argv[i];
  if (i + 1 >= argc) usage_error(command, option + " needs a value");
  const std::string value = argv[++i];
  if (value.empty()) usage_error(command, option + " needs a value, got an empty string");
  return value;
}

std::string file_argument(const char* command, const char* what, std::string_view arg) {
  if (arg.empty()) usage_error(command, std::string("an empty string where ") + what + " is expected");
  return std::string(arg);
}

void check_not_an_input(const char* command, const std::string& option, const std::string& output,
                        const std::vector<std::pair<std::string, std::string>>& inputs) {
  for (const auto& [input_option, input] : inputs) {
    // The same file by any name, or the same path where the input is still to be made (an
    // SQLite history's -wal and -shm come and go with its connections).
    if (input.empty() || !same_output_path(output, input)) continue;
    const std::string what = input_option.empty() ? std::string("the input") : input_option;
    usage_error(command, option + " " + output + " is the same file as " + what + " " + input +
                             ": an output never replaces what the command reads");
  }
}

std::optional<double> parse_seconds(std::string_view text, double max) {
  const std::string v(text);
  char* end = nullptr;
  const double d = std::strtod(v.c_str(), &end);
  if (v.empty() || end != v.c_str() + v.size() || !std::isfinite(d) || !(d > 0.0) || d > max)
    return std::nullopt;
  return d;
}

bool write_file(const std::string& path, const std::string& text, bool overwrite,
                std::string& error) {
  OutputFile out;
  if (!out.open(path, overwrite, error)) return false;
  if (std::fwrite(text.data(), 1, text.size(), out.stream()) != text.size()) {
    error = path + ": write failed: " + std::strerror(errno) + "; nothing written";
    out.discard();
    return false;
  }
  // A part of a report or an image is of no use: only a complete file is kept when it cannot
  // be moved into place.
  return out.commit(error, /*keep_partial=*/false);
}

namespace {

std::atomic<bool> g_interrupted{false};
static_assert(std::atomic<bool>::is_always_lock_free, "set from a signal handler");

extern "C" void on_interrupt(int) { g_interrupted.store(true, std::memory_order_relaxed); }

}  // namespace

void catch_interrupts() {
  struct sigaction sa {};
  sa.sa_handler = on_interrupt;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESETHAND;  // the second signal takes the default action
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

bool interrupted() { return g_interrupted.load(std::memory_order_relaxed); }

Progress::Progress(std::string label, std::int64_t total, Piped piped)
    : label_(std::move(label)), total_(total), tty_(::isatty(STDERR_FILENO) == 1), piped_(piped) {}

void Progress::update(std::int64_t done) {
  if (total_ <= 0) return;
  if (!tty_) {
    if (piped_ == Piped::silent) return;
    const int tenths = int(std::clamp(done * 10 / total_, std::int64_t(0), std::int64_t(10)));
    if (tenths <= tenths_said_) return;
    tenths_said_ = tenths;
    std::fprintf(stderr, "%s: %d %%\n", label_.c_str(), 10 * tenths);
    std::fflush(stderr);
    return;
  }
  const std::int64_t now = std::chrono::duration_cast<std::chrono::nanoseconds>(
                               std::chrono::steady_clock::now().time_since_epoch())
                               .count();
  if (drawn_ && now - last_ns_ < 100'000'000 && done < total_) return;
  last_ns_ = now;
  constexpr int kWidth = 30;
  const double f = std::clamp(double(done) / double(total_), 0.0, 1.0);
  const int filled = int(f * kWidth);
  std::string bar(std::size_t(filled), '#');
  bar.append(std::size_t(kWidth - filled), ' ');
  std::fprintf(stderr, "\r%s [%s] %3d%%", label_.c_str(), bar.c_str(), int(100.0 * f));
  std::fflush(stderr);
  drawn_ = true;
}

void Progress::finish() {
  if (!drawn_) return;
  std::fprintf(stderr, "\r\033[K");
  std::fflush(stderr);
  drawn_ = false;
}

}  // namespace mixpilot::cli
