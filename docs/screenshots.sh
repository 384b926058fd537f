#!/usr/bin/env bash
# Regenerates the README's screenshots with the headless renderer (mixpilot fly --screenshot):
# one per mode, 800x450. Usage: docs/screenshots.sh [path/to/mixpilot]
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
ls -l $out
