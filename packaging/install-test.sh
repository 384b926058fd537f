#!/usr/bin/env bash
# The cheap install check (CI runs it): builds the package from a release build (default
# build/release, the test build), installs it on this machine with apt-get, runs the
# installed-checks from /, purges it and checks that none of its files is left. Needs root.
# The full check in a throwaway Debian 12 root is packaging/debootstrap-test.sh.
#   packaging/install-test.sh [BUILD_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
src=$PWD
build=${1:-build/release}
[ "$(id -u)" -eq 0 ] || { echo "install-test: needs root (it installs the package)" >&2; exit 1; }
if dpkg-query -W mixpilot >/dev/null 2>&1; then
  echo "install-test: mixpilot is already installed here; purge it first" >&2
  exit 1
fi
bash packaging/build-deb.sh --build-dir "$build"
deb=$(ls -t "$build"/mixpilot_*.deb | head -1)
work=$(mktemp -d)
trap 'apt-get purge -y -qq mixpilot >/dev/null 2>&1 || true; rm -rf "$work"' EXIT

DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "$(realpath "$deb")"
dpkg -L mixpilot > "$work/files.txt"
echo "install-test: $(wc -l < "$work/files.txt") paths installed"
MIXPILOT_SOURCE=$src bash packaging/installed-checks.sh "$work/run"

DEBIAN_FRONTEND=noninteractive apt-get purge -y -qq mixpilot
left=0
while read -r path; do
  # Folders other packages share (/usr/share/man/man1, ...) stay; mixpilot's own go.
  if [ -d "$path" ]; then
    case "$path" in
      */mixpilot|*/mixpilot/*) echo "install-test: left behind: $path/"; left=1 ;;
    esac
  elif [ -e "$path" ] || [ -L "$path" ]; then
    echo "install-test: left behind: $path"; left=1
  fi
done < "$work/files.txt"
[ "$left" -eq 0 ] || exit 1
echo "install-test: installed, checked from /, purged; nothing left behind"
