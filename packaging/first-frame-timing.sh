#!/usr/bin/env bash
# The first ten minutes, timed: a throwaway Debian 12 (bookworm) minbase root made by
# debootstrap (git and ca-certificates only), an Xvfb display on this machine shared with it,
# and inside it the README's first command as a new user types it:
#   git clone <this repository> && cd mixpilot && packaging/quickstart.sh run
# The time is from `git clone` to the window's first frame (the first grab of the display that
# is not all black, polled every half second). It prints the time, the time of each stage of
# the log (the package installation, the configuration, the build) and keeps a PNG of that
# first frame. Needs root, debootstrap, Xvfb and ffmpeg on this machine, and Debian's archive.
set -euo pipefail
cd "$(dirname "$0")/.."

usage() {
  cat <<'EOF'
usage: packaging/first-frame-timing.sh [--base DIR] [--out DIR] [REVISION]
  REVISION     the commit of this repository to clone (default: HEAD)
  --base DIR   a minbase root made earlier by this script (kept there when it does not exist
               yet); each run copies it, so the runs start from the same fresh machine
  --out DIR    where the log and the first frame's PNG go (default: a new temporary folder)
Needs root.
EOF
}
rev=HEAD
base=
out=
while [ $# -gt 0 ]; do
  case "$1" in
    -h|--help) usage; exit 0 ;;
    --base) [ $# -ge 2 ] || { usage >&2; exit 2; }; base=$2; shift ;;
    --out) [ $# -ge 2 ] || { usage >&2; exit 2; }; out=$2; shift ;;
    -*) usage >&2; exit 2 ;;
    *) rev=$1 ;;
  esac
  shift
done
say() { echo "first-frame: $*"; }
die() { echo "first-frame: $*" >&2; exit 1; }
[ "$(id -u)" -eq 0 ] || die "needs root (debootstrap, chroot)"
for tool in debootstrap Xvfb ffmpeg; do
  command -v "$tool" >/dev/null || die "needs $tool (apt-get install debootstrap xvfb ffmpeg)"
done
commit=$(git rev-parse --verify "$rev^{commit}") || die "no commit $rev in this repository"
out=${out:-$(mktemp -d /var/tmp/first-frame.XXXXXX)}
mkdir -p "$out"

if [ -z "$base" ] || [ ! -d "$base/etc" ]; then
  base=${base:-$out/base}
  say "making a minbase bookworm root in $base (a few minutes, mostly downloading)"
  debootstrap --variant=minbase --include=git,ca-certificates bookworm "$base" \
    http://deb.debian.org/debian > "$out/debootstrap.log" 2>&1 ||
    die "debootstrap failed; see $out/debootstrap.log"
fi

root=$(mktemp -d /var/tmp/first-frame-root.XXXXXX)
display=
xvfb=
cleanup() {
  set +e
  # Whatever still runs in the root (the window), then the mounts, the display and the root.
  for p in /proc/[0-9]*; do
    [ "$(readlink "$p/root" 2>/dev/null)" = "$root" ] && kill -9 "${p#/proc/}" 2>/dev/null
  done
  sleep 0.5
  for m in tmp/.X11-unix dev/pts dev sys proc; do umount "$root/$m" 2>/dev/null; done
  [ -n "$xvfb" ] && kill "$xvfb" 2>/dev/null
  rm -rf "$root"
}
trap cleanup EXIT
cp -a "$base/." "$root/"
cp /etc/resolv.conf "$root/etc/resolv.conf"
mount -t proc proc "$root/proc"
mount --bind /sys "$root/sys"
mount --bind /dev "$root/dev"
mount --bind /dev/pts "$root/dev/pts"
# The repository as a remote the new user clones from (a bare copy of the one commit's history).
git clone -q --bare --no-local . "$root/srv/mixpilot.git"
git -C "$root/srv/mixpilot.git" update-ref refs/heads/first-frame "$commit"
git -C "$root/srv/mixpilot.git" symbolic-ref HEAD refs/heads/first-frame

# A display nobody else uses, its socket shared with the root.
for n in $(seq 90 120); do [ -e "/tmp/.X11-unix/X$n" ] || { display=:$n; break; }; done
[ -n "$display" ] || die "no free X display number in :90-:120"
Xvfb "$display" -screen 0 1280x720x24 -nolisten tcp > "$out/xvfb.log" 2>&1 &
xvfb=$!
for _ in $(seq 100); do [ -e "/tmp/.X11-unix/X${display#:}" ] && break; sleep 0.1; done
mkdir -p "$root/tmp/.X11-unix"
mount --bind /tmp/.X11-unix "$root/tmp/.X11-unix"

# Each line of the log with the seconds since the clone started.
start=$(date +%s.%N)
stamp() {
  while IFS= read -r line; do
    printf '%7.1f %s\n' "$(echo "$(date +%s.%N) - $start" | bc)" "$line"
  done
}
say "clone $commit and packaging/quickstart.sh run, DISPLAY=$display; log: $out/log.txt"
chroot "$root" env -i HOME=/root TERM=dumb LANG=C.UTF-8 DISPLAY="$display" \
  PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin DEBIAN_FRONTEND=noninteractive \
  bash -c 'cd /root && echo "== git clone" && git clone -q /srv/mixpilot.git mixpilot &&
           cd mixpilot && echo "== packaging/quickstart.sh run" && exec packaging/quickstart.sh run' \
  2>&1 | stamp > "$out/log.txt" &
runner=$!

# The first frame: a grab of the display with anything drawn in it.
frame=$out/first-frame.png
while :; do
  if ! kill -0 "$runner" 2>/dev/null; then
    tail -n 20 "$out/log.txt" >&2
    die "quickstart.sh run ended before a window appeared (above; $out/log.txt)"
  fi
  lit=$(ffmpeg -loglevel error -f x11grab -video_size 1280x720 -i "$display" -frames:v 1 \
          -f rawvideo -pix_fmt gray - 2>/dev/null | tr -d '\000' | wc -c)
  if [ "$lit" -gt 10000 ]; then
    now=$(date +%s.%N)
    ffmpeg -loglevel error -y -f x11grab -video_size 1280x720 -i "$display" -frames:v 1 "$frame"
    break
  fi
  sleep 0.5
done
total=$(echo "$now - $start" | bc)
# The build's first and last lines ("[1/N] ...", "[N/N] ..."): before it, the packages and the
# configuration; after it, the program's start.
build_first=$(grep -m1 -E '^ *[0-9.]+ \[1/[0-9]+\]' "$out/log.txt" | awk '{print $1}')
build_last=$(grep -E '^ *[0-9.]+ \[[0-9]+/[0-9]+\]' "$out/log.txt" | tail -n1 | awk '{print $1, $2}')
steps=$(echo "$build_last" | sed -E 's/.*\[([0-9]+)\/([0-9]+)\].*/\2/')
printf 'first-frame: %s: clone -> first frame %.1f s\n' "$commit" "$total" | tee "$out/summary.txt"
printf 'first-frame:   packages and configuration until %s s, the build (%s steps) until %s s\n' \
  "${build_first:-?}" "${steps:-?}" "${build_last%% *}" | tee -a "$out/summary.txt"
say "first frame: $frame"
