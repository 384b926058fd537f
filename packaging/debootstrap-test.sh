#!/usr/bin/env bash
# The full install check: a throwaway Debian 12 (bookworm) minbase root made by debootstrap,
# the package installed in it with apt-get (which pulls its dependencies from Debian's
# archive), and the installed-checks run there from / (nothing of this checkout is in that
# root). Needs root and Debian's archive; takes several minutes (most of it downloading), so CI
# runs the cheaper packaging/install-test.sh instead.
#
# The archive is the one this machine's apt uses, so the check works behind a local mirror or
# a proxy: apt reads its sources (sources.list, sources.list.d/*.list and deb822 *.sources) and
# the first http(s) `deb` entry for bookworm with `main` is debootstrap's mirror; the root gets
# that entry and the machine's bookworm-updates and bookworm-security entries. apt's proxy
# (Acquire::http::Proxy, Acquire::https::Proxy, or one for the mirror's host; DIRECT: none)
# becomes http_proxy / https_proxy for debootstrap and for apt in the root.
set -euo pipefail
cd "$(dirname "$0")/.."

usage() {
  cat <<'EOF'
usage: packaging/debootstrap-test.sh [--mirror URL] [--print-sources] [PACKAGE.deb]
  PACKAGE.deb      the package to check (default: build one with packaging/build-deb.sh)
  --mirror URL     the Debian mirror to use instead of the one in the apt sources (the
                   environment variable DEBIAN_MIRROR does the same; --mirror wins); the root
                   then gets only this mirror's bookworm
  --print-sources  print the mirror, the root's apt sources and the proxy, then exit
                   (needs no root)
The mirror is otherwise the first http(s) `deb` entry for bookworm with `main` in this
machine's apt sources (as `apt-get indextargets` reads them: sources.list, sources.list.d/*.list
and *.sources); apt's Acquire::http(s)::Proxy is honoured. Needs root.
EOF
}

suite=bookworm
mirror=${DEBIAN_MIRROR:-}
print_only=0
deb=
while [ $# -gt 0 ]; do
  case "$1" in
    -h|--help) usage; exit 0 ;;
    --mirror) [ $# -ge 2 ] || { usage >&2; exit 2; }; mirror=$2; shift ;;
    --mirror=*) mirror=${1#--mirror=} ;;
    --print-sources) print_only=1 ;;
    -*) usage >&2; exit 2 ;;
    *) [ -z "$deb" ] || { usage >&2; exit 2; }; deb=$1 ;;
  esac
  shift
done
say() { echo "debootstrap-test: $*"; }
die() { echo "debootstrap-test: $*" >&2; exit 1; }

# The root's sources: "deb URI SUITE COMPONENTS..." for the suite and its updates and security.
if [ -n "$mirror" ]; then
  mirror=${mirror%/}
  sources="deb $mirror $suite main"
else
  # The `deb` entries apt reads, "URI SUITE COMPONENT" a line in apt's order (deb-src, disabled
  # stanzas, options and comments are apt's business).
  # shellcheck disable=SC2016  # $(...) is apt's format, not the shell's
  entries=$(apt-get indextargets --no-release-info 'Identifier: Packages' \
              --format '$(TARGET_OF) $(REPO_URI) $(RELEASE) $(COMPONENT)') ||
    die "apt cannot read this machine's sources (above); give a mirror with --mirror URL"
  entries=$(awk '$1 == "deb" && $2 ~ /^https?:\/\// { sub(/\/$/, "", $2); print $2, $3, $4 }' \
              <<<"$entries" | awk '!seen[$0]++')
  mirror=$(awk -v s="$suite" '$2 == s && $3 == "main" { print $1; exit }' <<<"$entries")
  if [ -z "$mirror" ]; then
    list='' parts=''
    eval "$(apt-config shell list Dir::Etc::SourceList/f parts Dir::Etc::SourceParts/d)"
    die "no http(s) Debian mirror with '$suite main' in the apt sources ($list, ${parts}*.list," \
        "${parts}*.sources); give one with --mirror URL or DEBIAN_MIRROR=URL"
  fi
  sources=$(awk -v s="$suite" -v m="$mirror" '
    ($2 == s && $1 == m) || $2 == s "-updates" || $2 == s "-security" {
      key = $1 " " $2
      if (!(key in comps)) order[++n] = key
      if (!((key, $3) in seen)) { seen[key, $3] = 1; comps[key] = comps[key] " " $3 }
    }
    END { for (i = 1; i <= n; ++i) print "deb " order[i] comps[order[i]] }' <<<"$entries")
fi

# apt's proxy for a scheme: the one for the mirror's host, else the scheme's; DIRECT is none.
host=${mirror#*://}; host=${host%%/*}; host=${host##*@}; host=${host%:*}
apt_proxy() {
  local value='' general=''
  eval "$(apt-config shell value "Acquire::$1::Proxy::$host" general "Acquire::$1::Proxy")"
  value=${value:-$general}
  case "$value" in DIRECT|direct) echo none ;; *) echo "$value" ;; esac
}
for scheme in http https; do
  value=$(apt_proxy $scheme)
  if [ "$value" = none ]; then unset "${scheme}_proxy"
  elif [ -n "$value" ]; then export "${scheme}_proxy=$value"
  fi
done
hide() { sed -E 's#://[^/@]*@#://***@#' <<<"$1"; }  # a proxy's credentials are not printed
say "mirror $mirror"
while IFS= read -r line; do say "root source: $line"; done <<<"$sources"
say "http proxy: $(hide "${http_proxy:-none}"), https proxy: $(hide "${https_proxy:-none}")"
[ "$print_only" -eq 0 ] || exit 0

[ "$(id -u)" -eq 0 ] || die "needs root"
if [ -z "$deb" ]; then
  bash packaging/build-deb.sh --no-check
  deb=$(ls -t build/deb/mixpilot_*.deb | head -1)
fi
command -v debootstrap >/dev/null || apt-get install -y -qq debootstrap

root=$(mktemp -d /var/tmp/mixpilot-root.XXXXXX)
chmod 755 "$root"  # the root's /, which apt's unprivileged _apt user must traverse
cleanup() {
  umount "$root/proc" 2>/dev/null || true
  rm -rf --one-file-system "$root" "$root.log"
}
trap cleanup EXIT
say "Debian 12 minbase in $root"
debootstrap --variant=minbase "$suite" "$root" "$mirror" > "$root.log" 2>&1 ||
  { tail -20 "$root.log"; exit 1; }
printf '%s\n' "$sources" > "$root/etc/apt/sources.list"
mount -t proc proc "$root/proc"
cp "$deb" "$root/tmp/mixpilot.deb"
cp packaging/installed-checks.sh "$root/tmp/installed-checks.sh"
chroot "$root" env DEBIAN_FRONTEND=noninteractive apt-get update -qq
chroot "$root" env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq /tmp/mixpilot.deb
chroot "$root" env MIXPILOT_SOURCE="$PWD" bash /tmp/installed-checks.sh /tmp/work
chroot "$root" env DEBIAN_FRONTEND=noninteractive apt-get purge -y -qq mixpilot
for p in /usr/bin/mixpilot /usr/share/mixpilot /usr/share/doc/mixpilot; do
  [ ! -e "$root$p" ] || die "$p left after purge"
done
say "installed in a fresh Debian 12 root, checked, purged"
