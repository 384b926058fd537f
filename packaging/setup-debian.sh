#!/usr/bin/env bash
# Installs every Debian 12 package mixpilot needs to build, test and run. Idempotent: packages
# already installed are left alone, and nothing is done when all are present.
# As root it calls apt-get; otherwise sudo apt-get.
set -euo pipefail

packages=(
  # toolchain
  g++ cmake ninja-build pkgconf git
  # core maths: linear algebra, offline NLPs (reference trajectories, converged baselines)
  libeigen3-dev coinor-libipopt-dev
  # scenario files
  libtomlplusplus-dev
  # the trainee's history: SQLite (sqlite3: its shell, to look into a history), SHA-256 of
  # recordings and scenarios (libcrypto), PostgreSQL for a training centre (libpq)
  libsqlite3-dev sqlite3 libssl-dev libpq-dev
  # desktop app: ImGui 1.86 with backends, GLFW windows, EGL (Mesa surfaceless) headless rendering
  libimgui-dev libglfw3-dev libgl-dev libegl-dev libegl-mesa0 libgles-dev libepoxy-dev
  libgl1-mesa-dri libfontconfig-dev fonts-dejavu-core libstb-dev xvfb xauth
  # videos of replays (mixpilot replay --video, the window's Export clip; ffprobe in the tests)
  ffmpeg
  # gamepads
  libsdl2-dev
  # network peers (C API + idlc); openssl makes a training centre's DDS Security CA and
  # certificates (packaging/dds-security-ca.sh, and the security tests' test CA)
  cyclonedds-dev cyclonedds-tools openssl
  # tests and benchmarks; the PostgreSQL server the history tests start themselves
  libgtest-dev libgmock-dev libbenchmark-dev valgrind postgresql
  # the single-node Slurm cluster the sweep tests start themselves (tests/slurm_cluster.hpp).
  # Installing them starts no Slurm daemon: Debian's units and init scripts wait for an
  # /etc/slurm/slurm.conf, which nothing here writes; munge's postinst starts munged (on a
  # machine with an init system), which listens on a Unix socket only.
  slurm-wlm munge
  # fuzzing: clang++ and its libFuzzer/sanitizer runtimes (tests/fuzz)
  clang libclang-rt-dev
  # tooling: independent MCAP reader in the recording tests
  nodejs
  # the Debian package: man pages, dpkg-shlibdeps, its checks (packaging/build-deb.sh)
  help2man dpkg-dev lintian desktop-file-utils appstream
)
# Debian's npm conflicts with a nodejs that already bundles npm; ask for it only when missing.
command -v npm >/dev/null 2>&1 || packages+=(npm)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q '^install ok installed$'; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup-debian: all ${#packages[@]} packages already installed"
  exit 0
fi

if [ "$(id -u)" -eq 0 ]; then sudo=(); else sudo=(sudo); fi
echo "setup-debian: installing ${#missing[@]} package(s): ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${sudo[@]}" apt-get update -qq
"${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
echo "setup-debian: done"
