#!/usr/bin/env bash
# End-to-end checks of the mixpilot command line (issue 5): fly --record/--report, then score of
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
check "recording exists (no .tmp left)" test -f "$work/novice.mcap" -a ! -e "$work/novice.mcap.tmp"
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

# Usage errors exit 2 with a message; --help exits 0.
"$mixpilot" fly --scenario "$src/scenarios/mi_helix.toml" --pilot novice >"$work/e1" 2>&1
check "fly without --headless is a usage error" test $? -eq 2
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

echo "$pass passed, $fails failed"
test "$fails" -eq 0
