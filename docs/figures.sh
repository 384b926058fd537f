#!/usr/bin/env bash
# Regenerates docs/figures/: the thesis's figures as `mixpilot figures` renders them (SPEC §11),
# 1200 px across for the README (their print size is 1800). The flights go nowhere but a
# temporary folder; Fig. 7.9's RTI times are this machine's.
# Usage: docs/figures.sh [path/to/mixpilot]
set -euo pipefail
cd "$(dirname "$0")/.."
m=${1:-build/release/app/mixpilot}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export XDG_DATA_HOME="$tmp/data" XDG_CONFIG_HOME="$tmp/config"
"$m" figures --out "$tmp/figures" --width 1200
mkdir -p docs/figures
cp "$tmp"/figures/fig_*.png docs/figures/
