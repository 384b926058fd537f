#!/usr/bin/env bash
# The README's two commands. Both install missing Debian packages and configure the release
# preset, then:
#   run   builds the mixpilot program only and runs the main job: the window (mixed initiative,
#         emulated novice) where a display exists, else the headless demo
#   test  builds everything and runs the whole test suite through CTest
set -euo pipefail
cd "$(dirname "$0")/.."

usage() { echo "usage: packaging/quickstart.sh run|test" >&2; exit 2; }
[ $# -eq 1 ] || usage
case "$1" in run|test) ;; *) usage ;; esac

bash packaging/setup-debian.sh
cmake --preset release >/dev/null
# `run` builds the one program it runs (the first flight comes before the test suite's build);
# `test` builds everything.
case "$1" in
  run) cmake --build --preset release --target mixpilot ;;
  test) cmake --build --preset release ;;
esac

case "$1" in
  run)
    # The window where a display exists (mi_helix; the first time, a welcome with three ways
    # in), else the headless demo.
    if [ -n "${DISPLAY:-}${WAYLAND_DISPLAY:-}" ]; then
      exec ./build/release/app/mixpilot fly
    fi
    exec ./build/release/app/mixpilot demo ;;
  test) exec ctest --preset release -j "$(nproc)" ;;
esac
