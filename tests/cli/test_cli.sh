#!/usr/bin/env bash
# End-to-end checks of the mixpilot command line: fly --record/--report, then score of
# that recording gives the identical score; corrupt recordings and bad arguments give clear
# errors. Usage: test_cli.sh MIXPILOT SOURCE_DIR
set -u
mixpilot=$1
src=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fails=0
pass=0
check() {  # check NAME CONDITION-COMMAND...
  local name=$1
  shift
  if "$@"; then
    pass=$((pass + 1))
  else
    echo "FAILED: $name"
    fails=$((fails + 1))
  fi
}

# fly → record + report; score → JSON; the score fields must be identical.
"$mixpilot" fly --scenario "$src/scenarios/mi_helix.toml" --pilot novice --headless --duration 5 \
  --record "$work/novice.mcap" --report "$work/fly.json" >"$work/fly.out" 2>&1
check "fly exits 0" test $? -eq 0
check "fly prints a summary" grep -q "skill" "$work/fly.out"
check "recording exists (no temporary left)" test -f "$work/novice.mcap" -a -z "$(ls "$work" | grep '\.tmp$')"
"$mixpilot" score "$work/novice.mcap" --jobs 2 --json "$work/score.json" >"$work/score.out" 2>"$work/score.err"
check "score exits 0" test $? -eq 0
check "score reports an exact replay" grep -q "exact" "$work/score.out"
check "score shows progress" grep -q "\[1/1\]" "$work/score.err"
# Compare every score field (all lines after the labels) of the two JSON documents.
fields() { grep -E '^\s+"(duration_s|progress|time_in_ball|max_deviation_m|rms_deviation_m|mean_lambda|min_lambda|collisions|min_clearance_m|override_rms|stick_smoothness|rti_median_us|rti_p99_us|deadline_misses|fallbacks|skill)"' "$1" | sed 's/,$//; s/^ *//'; }
check "16 score fields in the report" test "$(fields "$work/fly.json" | wc -l)" -eq 16
check "fly --report and score --json agree exactly" diff <(fields "$work/fly.json") <(fields "$work/score.json")

# A truncated recording: an error naming a byte offset, exit 1, no crash.
head -c 3000 "$work/novice.mcap" >"$work/cut.mcap"
"$mixpilot" score "$work/cut.mcap" >"$work/cut.out" 2>&1
check "truncated recording fails with exit 1" test $? -eq 1
check "truncated recording error names a byte offset" grep -q "byte" "$work/cut.out"

# Flying from a recording replays it.
"$mixpilot" fly --pilot "$work/novice.mcap" --headless >"$work/replay.out" 2>&1
check "fly --pilot REC.mcap replays with the embedded scenario" test $? -eq 0

# fly --pilot REC replays the recording at its own length: the same score as `score`, exactly.
"$mixpilot" fly --pilot "$work/novice.mcap" --headless --report "$work/replay.json" >"$work/replay2.out" 2>&1
check "fly --pilot REC exits 0" test $? -eq 0
check "fly --pilot REC says the replay is exact" grep -q "replay exact" "$work/replay2.out"
check "fly --pilot REC and score give the same score, timing fields included" diff <(fields "$work/replay.json") <(fields "$work/score.json")
# A recording whose embedded scenario is broken (CRCs zeroed: "not computed"): the error says it
# is the recording's embedded scenario, not the file it was recorded from.
python3 - "$src/tests" "$work/novice.mcap" "$work/broken_embedded.mcap" <<'PY'
import sys
sys.path.insert(0, sys.argv[1])
from mutate_recordings import zero_crcs
data = zero_crcs(open(sys.argv[2], "rb").read())
assert data.count(b"[controller]") == 1
open(sys.argv[3], "wb").write(data.replace(b"[controller]", b"[controller["))
PY
for cmd in "score" "fly --headless --pilot"; do
  "$mixpilot" $cmd "$work/broken_embedded.mcap" >"$work/be.out" 2>&1
  check "$cmd: a broken embedded scenario exits 1" test $? -eq 1
  check "$cmd: ... naming the recording's embedded scenario" \
    grep -q "broken_embedded.mcap: its embedded scenario: .*mi_helix.toml:15:" "$work/be.out"
done
"$mixpilot" fly --pilot "$work/novice.mcap" --scenario "$src/scenarios/mi_helix_slow.toml" --headless >"$work/e6" 2>&1
check "a --scenario other than the embedded one exits 3" test $? -eq 3
check "... and says so" grep -q "differs from the scenario embedded" "$work/e6"

# ^C ends the flight at the next step: exit 130, a complete recording that replays exactly, the
# report marked interrupted.
"$mixpilot" fly --scenario "$src/scenarios/mi_helix_slow.toml" --pilot novice --headless \
  --record "$work/int.mcap" --report "$work/int.json" >"$work/int.out" 2>&1 &
pid=$!
sleep 1
kill -INT $pid
wait $pid
check "SIGINT exits 130" test $? -eq 130
check "interrupted flight says so" grep -q "interrupted at t" "$work/int.out"
check "interrupted recording is complete" test -f "$work/int.mcap" -a -z "$(ls "$work" | grep 'int\.mcap.*\.tmp$')"
check "interrupted report is marked" grep -q '"interrupted": "true"' "$work/int.json"
"$mixpilot" score "$work/int.mcap" --json "$work/int_score.json" >"$work/int.score" 2>&1
check "interrupted recording replays exactly" grep -q "exact" "$work/int.score"
# One flight, one score: scored against its planned length, as the live flight was, and said.
check "score says the recording was interrupted" grep -q "interrupted at t = .* s of 60.0 s" "$work/int.score"
check "... and marks it in the JSON" grep -q '"interrupted": "true"' "$work/int_score.json"
check "the interrupted flight's report and its score agree exactly" \
  diff <(fields "$work/int.json") <(fields "$work/int_score.json")

# Usage errors exit 2 with a message; --help exits 0.
"$mixpilot" fly --scenario "$src/scenarios/mi_helix.toml" --headless --record "$work/same" --report "$work/same" >"$work/e7" 2>&1
check "one path for two outputs is a usage error" test $? -eq 2
"$mixpilot" fly --scenario "$src/scenarios/mi_helix.toml" --headless --duration 1e9 >"$work/e8" 2>&1
check "a huge duration is a usage error" test $? -eq 2
"$mixpilot" fly --scenario "$src/scenarios/mi_helix.toml" --pilot novice --realtime >"$work/e1" 2>&1
check "--realtime without --headless is a usage error" test $? -eq 2

# Paced by the wall clock: the summary reports the real-time figures.
"$mixpilot" fly --scenario "$src/scenarios/mi_helix.toml" --pilot novice --headless --realtime \
  --duration 0.5 >"$work/rt.out" 2>&1
check "fly --headless --realtime exits 0" test $? -eq 0
check "... and reports deadline misses" grep -q "real time: [0-9]* deadline misses" "$work/rt.out"
# Paced: 0.5 s of flight take at least 0.5 s less a period of wall time (never less, however
# loaded the machine; without the runner's sleep they took milliseconds).
wall=$(sed -n 's/.* s flown in \([0-9.]*\) s of wall time.*/\1/p' "$work/rt.out")
check "Pacing: 0.5 s of flight take at least 0.485 s of wall time (took ${wall:-?})" \
  python3 -c "import sys; sys.exit(0 if float('${wall:-0}') >= 0.485 else 1)"
check "... and the summary says how far simulated time fell behind" grep -q "simulated time fell" "$work/rt.out"

# Headless screenshots (EGL): a PNG at the requested time; a time beyond the flight is refused.
"$mixpilot" fly --scenario "$src/scenarios/mi_helix.toml" --pilot novice --headless --duration 1 \
  --screenshot 0.5:"$work/shot.png" --size 320x200 >"$work/shot.out" 2>&1
check "--screenshot writes a PNG" sh -c "head -c 8 '$work/shot.png' | od -c | grep -q 'P   N   G'"
"$mixpilot" fly --scenario "$src/scenarios/mi_helix.toml" --pilot novice --headless --duration 1 \
  --screenshot 5:"$work/late.png" >"$work/late.out" 2>&1
check "--screenshot beyond the flight is a usage error" test $? -eq 2
check "... and nothing is written" test ! -e "$work/late.png"
# --scale: the frame a 150 % display shows (larger text: another picture); out of range refused.
"$mixpilot" fly --scenario "$src/scenarios/mi_helix.toml" --pilot novice --headless --duration 1 \
  --screenshot 0.5:"$work/shot150.png" --size 320x200 --scale 1.5 >"$work/shot150.out" 2>&1
check "--scale 1.5 writes a PNG" test $? -eq 0 -a -s "$work/shot150.png"
check "... another frame than at 100 %" sh -c "! cmp -s '$work/shot.png' '$work/shot150.png'"
"$mixpilot" fly --scenario "$src/scenarios/mi_helix.toml" --pilot novice --headless --duration 1 \
  --scale 0.1 >"$work/scale.out" 2>&1
check "--scale 0.1 is a usage error" test $? -eq 2
check "... naming the range" grep -q "from 0.5 to 4" "$work/scale.out"

# A recording flown longer than its scenario (--duration) replays at its own length, and
# `replay` shows a recording of any mode headless.
"$mixpilot" fly --scenario "$src/scenarios/obstacles_thrown_balls.toml" --headless --duration 4 \
  --record "$work/ob.mcap" >/dev/null 2>&1
"$mixpilot" score "$work/ob.mcap" >"$work/ob.score" 2>&1
check "a recording longer than its scenario replays exactly" grep -q "exact" "$work/ob.score"
"$mixpilot" replay "$work/ob.mcap" --headless --screenshot 3.5:"$work/ob.png" >"$work/ob.out" 2>&1
check "replay --headless --screenshot exits 0" test $? -eq 0
check "... writes the frame" test -s "$work/ob.png"
"$mixpilot" replay "$work/nothing.txt" >"$work/r2" 2>&1
check "replay of a non-recording is a usage error" test $? -eq 2

# No display: the window's absence is said before anything is written.
env -u DISPLAY -u WAYLAND_DISPLAY "$mixpilot" fly --scenario "$src/scenarios/mi_helix.toml" \
  --pilot novice --record "$work/nodisplay.mcap" >"$work/nd.out" 2>&1
check "no display: fly without --headless exits 1" test $? -eq 1
check "... says to use --headless" grep -q "use --headless" "$work/nd.out"
check "... and writes nothing" test -z "$(ls "$work" | grep nodisplay)"

# The window, under Xvfb where it is installed: flies, closes itself, and its frame shows the UI.
if command -v xvfb-run >/dev/null 2>&1; then
  # A random first display number: parallel runs on one machine do not race for :99.
  xvfb-run -a -n $((100 + RANDOM % 800)) -s "-screen 0 1280x800x24" "$mixpilot" fly --scenario "$src/scenarios/mi_helix.toml" \
    --pilot novice --duration 2 --exit-at-end --screenshot 1.5:"$work/window.png" \
    --record "$work/window.mcap" --report "$work/window.json" >"$work/win.out" 2>&1
  check "the window flies and closes itself" test $? -eq 0
  check "... with a frame of it" test -s "$work/window.png"
  check "... and the real-time summary" grep -q "real time:" "$work/win.out"
  # Recorded in the window, in real time: nothing lost, and `score` of the file gives the live
  # score to the bit (timing fields included: score takes them from the recording).
  check "... recorded without losing a step" grep -q "recorded $work/window.mcap$" "$work/win.out"
  "$mixpilot" score "$work/window.mcap" --json "$work/window_score.json" >"$work/win.score" 2>&1
  check "the window's recording replays exactly" grep -q "exact" "$work/win.score"
  check "the window's report and score of its recording agree exactly" \
    diff <(fields "$work/window.json") <(fields "$work/window_score.json")
  # `replay` in the window plays the recording to its end and closes itself.
  xvfb-run -a -n $((100 + RANDOM % 800)) -s "-screen 0 1280x800x24" "$mixpilot" replay "$work/window.mcap" \
    --exit-at-end --screenshot 1:"$work/replay_window.png" >"$work/rwin.out" 2>&1
  check "replay in the window plays to the end and closes itself" test $? -eq 0
  check "... with a frame of it" test -s "$work/replay_window.png"
else
  echo "SKIPPED: the window checks: xvfb-run is not installed (packaging/setup-debian.sh installs it)"
fi
"$mixpilot" fly --scenario "$src/scenarios/mi_helix.toml" --headless --duration -3 >"$work/e2" 2>&1
check "negative duration is a usage error" test $? -eq 2
check "negative duration message" grep -q "positive number" "$work/e2"
"$mixpilot" fly --scenario "$src/scenarios/mi_helix.toml" --headless --pilot nobody >"$work/e3" 2>&1
check "unknown pilot fails" test $? -eq 1
check "unknown pilot lists the profiles" grep -q "experienced" "$work/e3"
"$mixpilot" score >"$work/e4" 2>&1
check "score without files is a usage error" test $? -eq 2
"$mixpilot" fly --help >"$work/h" 2>&1
check "fly --help exits 0" test $? -eq 0
printf 'name = "x"\nmode = "mixed_initiative"\nmodel = "mikrokopter"\n[controller]\nN = "fifty"\n' >"$work/bad.toml"
"$mixpilot" fly --scenario "$work/bad.toml" --headless >"$work/e5" 2>&1
check "bad scenario fails" test $? -eq 1
check "bad scenario names file, line and key" grep -q "bad.toml:5:5: controller.N" "$work/e5"

# An input settings file named on the command line that is broken stops the flight (the user's
# own config file only gives a note and the defaults): exit 1, file:line:col, nothing written.
printf 'mode = 7\n' >"$work/bad_input.toml"
printf 't,left_x,left_y,right_x,right_y\n0,0,0,0,0\n' >"$work/pad.csv"
"$mixpilot" fly --scenario "$src/scenarios/mi_helix.toml" --pilot gamepad --gamepad-script "$work/pad.csv" \
  --input-settings "$work/bad_input.toml" --headless --realtime --duration 1 \
  --record "$work/bad_input.mcap" >"$work/bi.out" 2>&1
check "a broken --input-settings file stops the flight" test $? -eq 1
check "... saying where and what" grep -q "bad_input.toml:1:8: mode: value outside \[1, 4\], got 7" "$work/bi.out"
check "... and nothing is recorded" test -z "$(ls "$work" | grep bad_input.mcap)"

# Special files as inputs are refused, with the reason.
mkfifo "$work/fifo.toml"
timeout 10 "$mixpilot" fly --scenario "$work/fifo.toml" --headless >"$work/e9" 2>&1
check "a FIFO as scenario is refused, not read" test $? -eq 1
check "... with the reason" grep -q "expected a regular file" "$work/e9"
"$mixpilot" fly --scenario /dev/zero --headless >"$work/e10" 2>&1
check "/dev/zero as scenario is refused" grep -q "expected a regular file" "$work/e10"

# Outputs never clobber: an existing file needs --force, a device is never replaced.
"$mixpilot" fly --scenario "$src/scenarios/mi_helix.toml" --headless --duration 1 --record "$work/novice.mcap" >"$work/e11" 2>&1
check "an existing recording is not overwritten" test $? -eq 1
check "... and the message says so" grep -q "refusing to overwrite" "$work/e11"
"$mixpilot" fly --scenario "$src/scenarios/mi_helix.toml" --headless --duration 1 --record "$work/novice.mcap" --force >/dev/null 2>&1
check "--force overwrites it" test $? -eq 0
if [ -w /dev/full ]; then
  "$mixpilot" fly --scenario "$src/scenarios/mi_helix.toml" --headless --duration 1 --record /dev/full >"$work/e12" 2>&1
  check "a device as recording is refused" grep -q "not a regular file" "$work/e12"
  check "the device stays a device" test -c /dev/full
else
  echo "SKIPPED: a device as recording: /dev/full is not writable here"
fi

# kill -9 mid-flight leaves a temporary that `recover` makes whole; it then replays exactly.
"$mixpilot" fly --scenario "$src/scenarios/mi_helix_slow.toml" --pilot novice --headless \
  --record "$work/killed.mcap" >/dev/null 2>&1 &
pid=$!
sleep 1
kill -9 $pid
wait $pid 2>/dev/null
tmp=$(ls "$work"/killed.mcap.*.tmp 2>/dev/null | head -n 1)
check "kill -9 leaves the temporary" test -n "$tmp"
"$mixpilot" recover "$tmp" >"$work/rec.out" 2>&1
check "recover exits 0" test $? -eq 0
check "recover writes the target" test -f "$work/killed.mcap"
"$mixpilot" score "$work/killed.mcap" >"$work/killed.score" 2>&1
check "the recovered recording replays exactly" grep -q "exact" "$work/killed.score"

# A vehicle that leaves the arena is lost: the flight ends there, the summary and the report
# say so. (A 3 s input delay: the hover command arrives too late and the vehicle falls.)
sed 's/^input_delay = 0.0/input_delay = 3.0/' "$src/scenarios/mi_helix.toml" >"$work/falls.toml"
"$mixpilot" fly --scenario "$work/falls.toml" --pilot novice --headless --duration 10 \
  --report "$work/falls.json" >"$work/falls.out" 2>&1
check "a lost flight exits 0 (a result, not an error)" test $? -eq 0
check "... the summary says LOST" grep -q "LOST: the vehicle was lost at t = " "$work/falls.out"
check "... the report has lost = 1" grep -q '"lost": 1,' "$work/falls.json"
check "... and when, before the 10 s asked for" \
  sh -c "grep -Eq '\"lost_at_s\": [0-9]\.' '$work/falls.json'"

echo "$pass passed, $fails failed"
test "$fails" -eq 0
