#!/usr/bin/env bash
# Regenerates the README's screenshots with the headless renderer (mixpilot fly --screenshot):
# one per mode and one of a replay, 800x450. Usage: docs/screenshots.sh [path/to/mixpilot]
set -euo pipefail
cd "$(dirname "$0")/.."
m=${1:-build/release/app/mixpilot}
out=docs/screenshots
"$m" fly --scenario scenarios/mi_helix.toml --pilot novice --headless --duration 8 \
  --screenshot 7.5:$out/mixed_initiative.png --size 800x450 --force >/dev/null
"$m" fly --scenario scenarios/pendubot_swingup.toml --headless --duration 2 \
  --screenshot 1.2:$out/pendubot.png --size 800x450 --force >/dev/null
"$m" fly --scenario scenarios/tracking_helix.toml --headless --duration 5 \
  --screenshot 4.5:$out/tracking.png --size 800x450 --force >/dev/null
"$m" fly --scenario scenarios/obstacles_thrown_balls.toml --headless --duration 4 \
  --screenshot 3.5:$out/obstacles.png --size 800x450 --force >/dev/null
# A replay: a recording of the reckless pilot shown at 6 s, with the timeline and its events.
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$m" fly --scenario scenarios/mi_helix.toml --pilot reckless --headless --duration 12 \
  --record "$tmp/reckless.mcap" >/dev/null
"$m" replay "$tmp/reckless.mcap" --headless --screenshot 6:$out/replay.png --size 800x450 \
  --force >/dev/null
ls -l $out
