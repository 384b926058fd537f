#!/usr/bin/env bash
# The full install check: a throwaway Debian 12 (bookworm) minbase root made by debootstrap,
# the package installed in it with apt-get (which pulls its dependencies from Debian's
# archive), and the installed-checks run there from / (nothing of this checkout is in that
# root). Needs root and Debian's archive; takes several minutes (most of it downloading), so CI
# runs the cheaper packaging/install-test.sh instead.
#   packaging/debootstrap-test.sh [PACKAGE.deb]   (default: build one with build-deb.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
[ "$(id -u)" -eq 0 ] || { echo "debootstrap-test: needs root" >&2; exit 1; }
mirror=${DEBIAN_MIRROR:-http://deb.debian.org/debian}
deb=${1:-}
if [ -z "$deb" ]; then
  bash packaging/build-deb.sh --no-check
  deb=$(ls -t build/deb/mixpilot_*.deb | head -1)
fi
command -v debootstrap >/dev/null || apt-get install -y -qq debootstrap

root=$(mktemp -d /var/tmp/mixpilot-root.XXXXXX)
cleanup() {
  umount "$root/proc" 2>/dev/null || true
  rm -rf --one-file-system "$root" "$root.log"
}
trap cleanup EXIT
echo "debootstrap-test: Debian 12 minbase in $root"
debootstrap --variant=minbase bookworm "$root" "$mirror" > "$root.log" 2>&1 ||
  { tail -20 "$root.log"; exit 1; }
mount -t proc proc "$root/proc"
cp "$deb" "$root/tmp/mixpilot.deb"
cp packaging/installed-checks.sh "$root/tmp/installed-checks.sh"
chroot "$root" env DEBIAN_FRONTEND=noninteractive apt-get update -qq
chroot "$root" env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq /tmp/mixpilot.deb
chroot "$root" env MIXPILOT_SOURCE="$PWD" bash /tmp/installed-checks.sh /tmp/work
chroot "$root" env DEBIAN_FRONTEND=noninteractive apt-get purge -y -qq mixpilot
for p in /usr/bin/mixpilot /usr/share/mixpilot /usr/share/doc/mixpilot; do
  [ ! -e "$root$p" ] || { echo "debootstrap-test: $p left after purge"; exit 1; }
done
echo "debootstrap-test: installed in a fresh Debian 12 root, checked, purged"
