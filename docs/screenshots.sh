#!/usr/bin/env bash
# Regenerates the README's screenshots with the headless renderer (mixpilot fly --screenshot):
# one per mode, one of a replay and one of input loss, 800x450; the screen on a 150 % display,
# why λ fell, a ghost run, and the input settings, Progress and lesson panels, fly from here and
# the debrief at 1280x720 (app tests render them), the first launch's welcome and tour at 100 %
# and 150 %, and the instructor's window with two
# stations. The flights
# flown here go to a temporary data folder, never into the developer's history.
# Usage: docs/screenshots.sh [path/to/mixpilot]
set -euo pipefail
cd "$(dirname "$0")/.."
m=${1:-build/release/app/mixpilot}
out=docs/screenshots
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export XDG_DATA_HOME="$tmp/data"
"$m" fly --scenario scenarios/mi_helix.toml --pilot novice --headless --duration 8 \
  --screenshot 7.5:$out/mixed_initiative.png --size 800x450 --force >/dev/null
# What a 150 % display (Xft.dpi 144) shows in a 1280x720 window.
"$m" fly --scenario scenarios/mi_helix.toml --pilot novice --headless --duration 8 \
  --screenshot 7.5:$out/scale_150.png --size 1280x720 --scale 1.5 --force >/dev/null
"$m" fly --scenario scenarios/pendubot_swingup.toml --headless --duration 2 \
  --screenshot 1.2:$out/pendubot.png --size 800x450 --force >/dev/null
"$m" fly --scenario scenarios/tracking_helix.toml --headless --duration 5 \
  --screenshot 4.5:$out/tracking.png --size 800x450 --force >/dev/null
"$m" fly --scenario scenarios/obstacles_thrown_balls.toml --headless --duration 4 \
  --screenshot 3.5:$out/obstacles.png --size 800x450 --force >/dev/null
# A replay: a recording of the reckless pilot shown at 6 s, with the timeline and its events.
"$m" fly --scenario scenarios/mi_helix.toml --pilot reckless --headless --duration 12 \
  --record "$tmp/reckless.mcap" >/dev/null
"$m" replay "$tmp/reckless.mcap" --headless --screenshot 6:$out/replay.png --size 800x450 \
  --force >/dev/null
# Why λ fell: the reckless pilot at 1.2 s, the planner flying 85 %; the HUD says why and the
# arena draws the prediction λ came from, its node i*, the ball B there and the gap.
"$m" fly --scenario scenarios/mi_helix.toml --pilot reckless --headless --duration 2 \
  --screenshot 1.2:$out/reason.png --size 1280x720 --force >/dev/null
# A ghost run: the novice flying with the experienced pilot's recording as the ghost (lavender,
# translucent, a dashed trail, tagged "ghost"), at 12 s; the HUD says how far behind it the
# novice is along the reference.
"$m" fly --scenario scenarios/mi_helix.toml --pilot experienced --headless --duration 14 \
  --record "$tmp/experienced.mcap" >/dev/null
"$m" fly --scenario scenarios/mi_helix.toml --pilot novice --headless --duration 14 \
  --ghost "$tmp/experienced.mcap" --screenshot 12:$out/ghost.png --size 1280x720 --force >/dev/null
# A person's gamepad (a scripted SDL virtual pad) unplugged at 1 s: the planner flies.
printf 't,left_x,left_y,right_x,right_y\n0,0,0,0.3,0\n1.0,unplug\n' >"$tmp/unplug.csv"
XDG_CONFIG_HOME="$tmp/config" "$m" fly --scenario scenarios/mi_helix.toml --pilot gamepad \
  --gamepad-script "$tmp/unplug.csv" --headless --realtime --duration 2 \
  --screenshot 1.6:$out/input_lost.png --size 800x450 --force >/dev/null
# The input settings and Progress panels, from the app tests that open them (MIXPILOT_SHOT_DIR;
# the Progress panel over a trainee's history the test makes in its own data folder), and fly
# from here: a novice's replay taken over at 10 s, READY at that moment.
tests=$(dirname "$m")/../tests
MIXPILOT_SHOT_DIR="$tmp" XDG_CONFIG_HOME="$tmp/config" "$tests/test_app" \
  --gtest_filter='App.TheInputSettingsPanel:App.TheProgressPanel' >/dev/null
MIXPILOT_SHOT_DIR="$tmp" "$tests/test_fly_from_here_app" \
  --gtest_filter='FlyFromHereApp.TakeOverANovicesFlightAt10sWithTheExperiencedPilot' >/dev/null
cp "$tmp/input_settings.png" $out/input_settings.png
cp "$tmp/progress.png" $out/progress.png
cp "$tmp/fly_from_here.png" $out/fly_from_here.png
# The first launch: the welcome and each callout of its tour at 100 % and 150 %, from the test
# that drives them with the keyboard alone (in a fresh data and config folder of its own).
MIXPILOT_SHOT_DIR="$tmp" "$tests/test_onboarding" \
  --gtest_filter='Scales/FirstLaunchAtScale.TheKeyboardAloneGoesFromTheWelcomeToTwoFlightsAndTheImprovement/*' >/dev/null
for at in 100 150; do cp "$tmp/first_launch_welcome_$at.png" $out/first_launch_$at.png; done
for step in 1 2 3 4; do cp "$tmp/first_launch_tour_${step}_100.png" $out/tour_${step}_100.png; done
cp "$tmp/first_launch_tour_1_150.png" $out/tour_1_150.png
# The score card after a trainee's first and third flight of mi_helix (novice, experienced,
# reckless), each compared with the history the test keeps in its own data folder.
MIXPILOT_SHOT_DIR="$tmp" "$tests/test_score_card" \
  --gtest_filter='ScoreCardApp.TheSecondFlightShowsTheChangeSinceTheFirstAndTheBest' >/dev/null
cp "$tmp/score_card_1_100.png" $out/score_card_first.png
cp "$tmp/score_card_3_100.png" $out/score_card_third.png
# The lesson picker: the beginner course of a trainee two steps in, after a failed attempt at
# the third (the test fills a history of its own).
MIXPILOT_SHOT_DIR="$tmp" "$tests/test_lesson" \
  --gtest_filter='Scales/LessonPicker.ShowsTheTraineesStepOfTheCourse/0' >/dev/null
cp "$tmp/lesson_picker_100.png" $out/lesson_picker.png
# The debrief: a replay of the reckless pilot's whole flight (`fly --pilot reckless --record`),
# its Debrief panel listing the events, the last one clicked (selected, the playhead there).
MIXPILOT_SHOT_DIR="$tmp" "$tests/test_debrief" \
  --gtest_filter='Scales/DebriefScreen.ThePanelListsTheEventsAndTheBracketsStepThroughThem/0' >/dev/null
cp "$tmp/debrief_100.png" $out/debrief.png
# The instructor's window (mixpilot instruct): two stations flying in real time on a domain of
# this run's own (loopback only), the novice at station A (it obeys unauthenticated commands on
# loopback), the experienced pilot at B (it obeys no instructor); a ceiling of 0.3 sent to A from
# the command line first, so A's announced results show it; the window 4 s after both are heard.
domain=$((1 + $$ % 200))
for s in A:novice B:experienced; do
  extra=()
  [ "${s%%:*}" = A ] && extra=(--instructor --allow-unauthenticated-commands)
  "$m" fly --scenario scenarios/mi_helix_endurance.toml --pilot "${s#*:}" --headless --realtime \
    --publish --domain $domain --station "${s%%:*}" --trainee "${s#*:} pilot" --history off \
    "${extra[@]}" >"$tmp/station-${s%%:*}.txt" 2>&1 &
done
"$m" instruct --domain $domain --list --count 2 --wait 60 >/dev/null
"$m" instruct --domain $domain --station A --ceiling 0.3 --issuer docs >/dev/null
"$m" instruct --domain $domain --headless --count 2 --wait 60 --screenshot 4:$out/instructor.png \
  --force >/dev/null
kill -INT $(jobs -p) 2>/dev/null || true
wait
# The progress report to take home (history --html) of a trainee who flew the helix three times
# as the novice, three times as the experienced pilot (each attempt with its own position noise)
# and once unassisted, as headless Chromium prints it (Debian's chromium package).
for i in 1 2 3 4 5 6 7; do
  pilot=novice assist=on
  [ "$i" -gt 3 ] && pilot=experienced
  [ "$i" -eq 7 ] && assist=off
  sed "s/^position_noise = 0.0/position_noise = 0.01/; s/^seed = 1/seed = $i/" \
    scenarios/mi_helix.toml >"$tmp/helix.toml"
  "$m" fly --scenario "$tmp/helix.toml" --pilot $pilot --assist $assist --headless \
    --trainee "Ada Lovelace" --record "$tmp/ada-$i.mcap" >/dev/null
done
"$m" history --trainee "Ada Lovelace" --html "$tmp/ada.html" >/dev/null
if command -v chromium >/dev/null; then
  chromium --headless=new --no-sandbox --disable-gpu --hide-scrollbars --window-size=1000,900 \
    --screenshot="$out/progress_report.png" "file://$tmp/ada.html" >/dev/null 2>&1
else
  echo "docs/screenshots.sh: chromium is not installed (apt install chromium): progress_report.png kept" >&2
fi
ls -l $out
