#!/usr/bin/env python3
"""Break-it checks: does the suite notice when the code that matters is broken?

Each mutation below is a small, deliberate defect in production code at a place the tests
promise to guard -- allocation in the control loop, pacing by the wall clock, staleness of
device input, the score's formulas, replay equality, deadline accounting, the safety net, the
QP's handling of singular directions, what a snapshot of a flight keeps, the TOML nesting bound. For each one the script applies
the edit to a private copy of the tree (a git worktree under build/break-it, built there with
the release preset), builds the named test target and runs the named tests. The mutation is
*killed* when a test fails (or crashes, or times out), *survived* when every test passes; a
mutation whose text no longer matches the source is *stale* (the list must follow the code).

Prints one line per mutation and `tried / killed / survived / stale`; exits 1 when any survived
or is stale. Several minutes (each mutation rebuilds its test). Usage:

  python3 tests/break_it.py [--only NAME] [--keep]

CTest runs it with the label `breakit` when configured with -DMIXPILOT_BREAK_IT=ON.
"""
import argparse
import os
import shutil
import subprocess
import sys
from pathlib import Path

# (name, file, original text, broken text, test target, gtest filter)
MUTATIONS = [
    ("allocation in RTI prepare", "core/nlp/rti.cpp",
     "  bool finite = true;\n",
     "  bool finite = true;\n  { void* volatile p = std::malloc(64); std::free(p); }\n",
     "test_no_malloc", "NoMalloc.*"),
    ("allocation in the MI mode's step", "core/modes/mi_mode.cpp",
     "  const double t = double(run_.step) * dt_;\n",
     "  const double t = double(run_.step) * dt_;\n  { void* volatile p = std::malloc(64); std::free(p); }\n",
     "test_modes", "Shipped/EveryMode.RunsDeterministically*/mi_helix_novice"),
    ("runner does not sleep", "core/runtime/realtime_runner.cpp",
     "    std::this_thread::sleep_until(next);\n", "\n",
     "test_runtime", "RealtimeRunner.Pacing*"),
    ("runner ignores the speed", "core/runtime/realtime_runner.cpp",
     "    const double period_us = 1e6 * dt / speed;\n",
     "    const double period_us = 1e6 * dt;\n",
     "test_runtime", "RealtimeRunner.Pacing*"),
    ("device read one step late", "input/device_pilot.cpp",
     "  reading_ = source_.latest();\n",
     "  static StickReading older;\n  reading_ = older;\n  older = source_.latest();\n",
     "test_input_flight", "GamepadLatency.*"),
    ("device input never times out", "input/device_pilot.cpp",
     "steady_ns() - reading_.alive_ns <= timeout_ns;",
     "steady_ns() - reading_.alive_ns <= 1000 * timeout_ns;",
     "test_input", "DevicePilot.*"),
    ("skill weighs time in B at 0.5", "core/modes/score.cpp",
     "const double quality = 0.4 * sc.time_in_ball",
     "const double quality = 0.5 * sc.time_in_ball",
     "test_score", "ScoreFormula.*"),
    ("progress window of 2 s", "core/modes/score.cpp",
     "std::lround(1.0 / dt_));", "std::lround(2.0 / dt_));",
     "test_score", "ScoreFormula.*"),
    ("a collision per contact step", "core/modes/score.cpp",
     "  const bool started = contact && !m.in_contact;\n",
     "  const bool started = contact;\n",
     "test_score", "ScoreFormula.*"),
    ("replay check ignores λ", "core/recording/replay.cpp",
     "rec_->lambda[k].lambda != s.lambda", "false",
     "test_replay_check", "*"),
    ("replay ignores recorded overruns", "core/recording/replay.cpp",
     "    mode->replay_timing(recorded_steps(rec, kEventOverrun), recorded_steps(rec, kEventDeadlineMiss));",
     "    mode->replay_timing({}, recorded_steps(rec, kEventDeadlineMiss));",
     "test_replay_check", "ReplayCheck.RecordedOverrunsAreReplayed"),
    ("a late input is no deadline miss", "core/modes/mode.hpp",
     "(late_us_ + compute_us > period_us_ || compute_us > 1e6 * dt());",
     "(compute_us > 1e6 * dt());",
     "test_runtime", "RealtimeRunner.ADeadlineMiss*"),
    ("the safety net never engages", "core/modes/safety_net.hpp",
     "if (!engaged_ && failed_in_row_ >= after_) engaged_ = true;",
     "if (false) engaged_ = true;",
     "test_modes", "Shipped/EveryMode.OverrunsInARow*"),
    ("a singular pivot is dropped again", "core/qp/detail/qp_kernels.cpp",
     "        p = std::max(pivot_floor, psd_tol * mag);  // no curvature: regularized (see the header)\n",
     "        p = 1e300;  // dropped: its column vanishes\n",
     "test_session", "MixedInitiative.ThePlannerFliesEveryStepWhileTheInputIsLost"),
    ("a snapshot leaves the random generator out", "core/modes/mi_mode.cpp",
     "  scorer_.restore(s.score);\n  run_ = s.run;\n",
     "  scorer_.restore(s.score);\n  const auto rng = run_.rng;\n  const auto noise = run_.noise;\n"
     "  run_ = s.run;\n  run_.rng = rng;\n  run_.noise = noise;\n",
     "test_snapshot", "Shipped/Restore.*/mi_helix_noise_and_delay"),
    ("a snapshot leaves the QP warm start out", "core/nlp/rti.cpp",
     "  if (!fits(state)) return false;\n  state_ = state;\n",
     "  if (!fits(state)) return false;\n  const OcpQpSolution kept = state_.qp_solution;\n"
     "  const bool had = state_.have_qp_solution;\n  state_ = state;\n"
     "  state_.qp_solution = kept;\n  state_.have_qp_solution = had;\n",
     "test_snapshot", "Shipped/Restore.*"),
    ("a snapshot leaves the pilot's reaction delay out", "core/control/pilot_emulated.cpp",
     "  delay_line_ = s->delay_line;\n", "",
     "test_snapshot", "Shipped/Restore.*/mi_helix_novice"),
    ("a restore leaves the replay cursors out", "core/modes/mode.cpp",
     "  next_forced_ = s.next_forced_;\n", "",
     "test_snapshot", "Shipped/Restore.IntoTheModeThatFlewOn*"),
    ("no TOML nesting bound", "core/base/toml_read.hpp",
     "  if (const std::optional<Pos> at = too_deep(text)) {",
     "  if (const std::optional<Pos> at = std::optional<Pos>{}) {",
     "test_scenario", "Scenario.Nesting*"),
]


def run(cmd, cwd, timeout=None, env=None):
    return subprocess.run(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          text=True, timeout=timeout, env=env)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--only", help="run the mutations whose name contains this text")
    ap.add_argument("--keep", action="store_true", help="keep the worktree and its build")
    args = ap.parse_args()
    repo = Path(__file__).resolve().parent.parent
    work = repo / "build" / "break-it"
    src = work / "src"
    if src.exists():
        run(["git", "worktree", "remove", "--force", str(src)], repo)
        shutil.rmtree(src, ignore_errors=True)
    work.mkdir(parents=True, exist_ok=True)
    r = run(["git", "worktree", "add", "--detach", str(src), "HEAD"], repo)
    if r.returncode != 0:
        print(r.stdout)
        return 2
    env = dict(os.environ)
    if shutil.which("ccache"):
        env["CCACHE_BASEDIR"] = "/"
    configure = ["cmake", "--preset", "release"]
    if shutil.which("ccache"):
        configure += ["-DCMAKE_CXX_COMPILER_LAUNCHER=ccache", "-DCMAKE_C_COMPILER_LAUNCHER=ccache"]
    counts = {"tried": 0, "killed": 0, "survived": 0, "stale": 0}
    try:
        r = run(configure, src, env=env)
        if r.returncode != 0:
            print(r.stdout)
            return 2
        for name, rel, old, new, target, gfilter in MUTATIONS:
            if args.only and args.only not in name:
                continue
            counts["tried"] += 1
            path = src / rel
            text = path.read_text()
            if text.count(old) != 1:
                counts["stale"] += 1
                print(f"STALE     {name}: the original text is not in {rel} exactly once")
                continue
            path.write_text(text.replace(old, new))
            try:
                b = run(["cmake", "--build", "--preset", "release", "--target", target], src,
                        env=env)
                if b.returncode != 0:
                    verdict = "killed (does not build)"
                else:
                    exe = src / "build" / "release" / "tests" / target
                    try:
                        t = run([str(exe), f"--gtest_filter={gfilter}"], src / "build" / "release",
                                timeout=600, env=env)
                        verdict = "survived" if t.returncode == 0 else "killed"
                    except subprocess.TimeoutExpired:
                        verdict = "killed (timeout)"
            finally:
                path.write_text(text)
            key = "survived" if verdict == "survived" else "killed"
            counts[key] += 1
            print(f"{verdict.upper().split()[0]:9s} {name}: {target} --gtest_filter={gfilter}"
                  + ("" if verdict in ("killed", "survived") else f" [{verdict}]"), flush=True)
    finally:
        if not args.keep:
            run(["git", "worktree", "remove", "--force", str(src)], repo)
    print("{tried} tried / {killed} killed / {survived} survived / {stale} stale".format(**counts))
    return 1 if counts["survived"] or counts["stale"] else 0


if __name__ == "__main__":
    sys.exit(main())
