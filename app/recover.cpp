// mixpilot recover: a recording cut short by a crash or kill -9, made whole again.
#include <cstdio>
#include <string>

#include "app/cli.hpp"
#include "app/commands.hpp"
#include "core/recording/recover.hpp"

namespace mixpilot::cli {

namespace {

constexpr const char* kRecoverUsage =
    "usage: mixpilot recover FILE [-o OUT.mcap] [--force]\n"
    "\n"
    "Rebuilds a recording that a crash or kill -9 cut short (the temporary 'run.mcap.XXXXXX.tmp'\n"
    "a flight leaves) as a complete MCAP file of every whole control step it holds, marked\n"
    "recovered and interrupted; `score` then reads it like any recording. A file cut before its\n"
    "first whole control step holds no flight and is refused. A temporary that is already\n"
    "complete (its run was stopped while moving it into place) is put in place as it is.\n"
    "\n"
    "  -o OUT.mcap  where to write (default: the temporary's own target, e.g. run.mcap); never\n"
    "               FILE itself\n"
    "  --force      overwrite an existing OUT\n"
    "\n"
    "exit status: 0 recovered, 1 nothing to recover or unreadable, 2 usage\n";

}  // namespace

int recover_command(int argc, char** argv) {
  std::string in, out;
  bool force = false;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "-h" || a == "--help") {
      std::fputs(kRecoverUsage, stdout);
      return kExitOk;
    } else if (a == "-o") {
      out = option_value("recover", argc, argv, i);
    } else if (a == "--force") {
      force = true;
    } else if (!a.empty() && a[0] == '-') {
      usage_error("recover", "unknown option '" + a + "'");
    } else if (in.empty()) {
      in = file_argument("recover", "a file to recover", a);
    } else {
      usage_error("recover", "one FILE at a time, got '" + in + "' and '" + a + "'");
    }
  }
  if (in.empty()) usage_error("recover", "no FILE given");
  if (out.empty()) out = default_recovery_path(in);
  check_not_an_input("recover", "-o", out, {{"the file to recover", in}});
  std::string error;
  const auto r = recover_recording(in, out, force, error);
  if (!r) {
    std::fprintf(stderr, "mixpilot recover: %s\n", error.c_str());
    return kExitError;
  }
  if (r->was_complete) {
    std::printf("mixpilot recover: %s was already complete (its run stopped before moving it into "
                "place): %llu control steps, now in %s\n", in.c_str(),
                static_cast<unsigned long long>(r->steps), out.c_str());
  } else {
    std::printf("mixpilot recover: %s: %llu whole control steps recovered into %s\n", in.c_str(),
                static_cast<unsigned long long>(r->steps), out.c_str());
  }
  return kExitOk;
}

}  // namespace mixpilot::cli
