#!/usr/bin/env bash
# The README's two commands. Both install missing Debian packages, configure and build the
# release preset, then:
#   run   runs the main job: the window (mixed initiative, emulated novice) where a display
#         exists, else the headless demo
#   test  runs the whole test suite through CTest
set -euo pipefail
cd "$(dirname "$0")/.."

usage() { echo "usage: packaging/quickstart.sh run|test" >&2; exit 2; }
[ $# -eq 1 ] || usage
case "$1" in run|test) ;; *) usage ;; esac

bash packaging/setup-debian.sh
cmake --preset release >/dev/null
cmake --build --preset release

case "$1" in
  run)
    # The window where a display exists, else the headless demo.
    if [ -n "${DISPLAY:-}${WAYLAND_DISPLAY:-}" ]; then
      exec ./build/release/app/mixpilot fly --scenario scenarios/mi_helix.toml --pilot novice
    fi
    exec ./build/release/app/mixpilot demo ;;
  test) exec ctest --preset release -j "$(nproc)" ;;
esac
