#!/usr/bin/env bash
# Builds the Debian package from a clean checkout: a release build with the install prefix
# /usr (no tests), CPack's DEB generator (dependencies from dpkg-shlibdeps), then the checks the
# package must pass: lintian (no errors), desktop-file-validate and appstreamcli validate on the
# files it installs. The package lands in build/deb/.
#
#   packaging/build-deb.sh                       build and check
#   packaging/build-deb.sh --no-check            build only
#   packaging/build-deb.sh --build-dir DIR       package an existing release build instead
#                                                (the CI's, which has the tests too)
set -euo pipefail
cd "$(dirname "$0")/.."
check=1
build=
while [ $# -gt 0 ]; do
  case "$1" in
    --no-check) check=0 ;;
    --build-dir) build="$2"; shift ;;
    *) echo "usage: packaging/build-deb.sh [--no-check] [--build-dir DIR]" >&2; exit 2 ;;
  esac
  shift
done
bash packaging/setup-debian.sh

if [ -z "$build" ]; then
  build=build/deb
  cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DMIXPILOT_BUILD_TESTS=OFF
fi
cmake --build "$build" -j "$(nproc)"
rm -f "$build"/mixpilot_*.deb
(cd "$build" && cpack -G DEB)
deb=$(ls -t "$build"/mixpilot_*.deb | head -1)
echo "build-deb: $deb"
dpkg-deb --field "$deb" Package Version Depends Recommends Suggests Installed-Size
[ "$check" -eq 1 ] || exit 0

# lintian: errors fail the build; warnings are printed (packaging/README.md explains them).
# Run as root it warns that it should not be; that is not about the package.
echo "build-deb: lintian"
lintian --tag-display-limit 0 --allow-root "$deb" | tee "$build/lintian.txt" || true
if grep -q '^E:' "$build/lintian.txt"; then
  echo "build-deb: lintian reports errors" >&2
  exit 1
fi

# The installed desktop entry and metainfo, as the package holds them.
root=$(mktemp -d)
trap 'rm -rf "$root"' EXIT
dpkg-deb -x "$deb" "$root"
desktop-file-validate "$root/usr/share/applications/org.mixpilot.mixpilot.desktop"
appstreamcli validate --no-net "$root/usr/share/metainfo/org.mixpilot.mixpilot.metainfo.xml"
echo "build-deb: $deb passes lintian (no errors), desktop-file-validate and appstreamcli"
