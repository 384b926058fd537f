#!/usr/bin/env bash
# The README's two commands. Both install the Debian packages they need and configure the
# release preset, then:
#   run   builds the mixpilot program only and runs the main job: the window (mixed initiative,
#         emulated novice) where a display exists, else the headless demo
#   test  builds everything and runs the whole test suite through CTest
set -euo pipefail
cd "$(dirname "$0")/.."

usage() { echo "usage: packaging/quickstart.sh run|test" >&2; exit 2; }
[ $# -eq 1 ] || usage
case "$1" in run|test) ;; *) usage ;; esac

# `run` installs and builds only what the program needs, so the first flight comes before the
# test suite's packages and build; `test` installs and builds everything.
case "$1" in
  run)
    bash packaging/setup-debian.sh --run
    # The test suite is configured only where its packages are (a machine that ran `test`).
    tests=OFF
    if dpkg-query -W -f='${Status}\n' libgtest-dev libbenchmark-dev 2>/dev/null |
        grep -c '^install ok installed$' | grep -qx 2; then
      tests=ON
    fi
    cmake --preset release -DMIXPILOT_BUILD_TESTS=$tests >/dev/null
    cmake --build --preset release --target mixpilot ;;
  test)
    bash packaging/setup-debian.sh
    cmake --preset release -DMIXPILOT_BUILD_TESTS=ON >/dev/null
    cmake --build --preset release ;;
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
