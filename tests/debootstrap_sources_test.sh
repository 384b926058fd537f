#!/usr/bin/env bash
# packaging/debootstrap-test.sh takes its mirror, the root's sources and the proxy from the
# machine's apt configuration: checked with `--print-sources` on sample apt configurations
# (APT_CONFIG points apt at sample sources files; this machine's own are not read).
# Usage: debootstrap_sources_test.sh DEBOOTSTRAP_TEST_SH
set -u
script=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
unset DEBIAN_MIRROR http_proxy https_proxy
pass=0
fails=0

# A fresh apt configuration: sources.list (absent until written), an empty sources.list.d and
# conf.d, and the extra lines given.
fresh() {
  rm -rf "${work:?}/etc" && mkdir -p "$work/etc/sources.list.d" "$work/etc/apt.conf.d" "$work/lists"
  cat >"$work/apt.conf" <<EOF
Dir::Etc::SourceList "$work/etc/sources.list";
Dir::Etc::SourceParts "$work/etc/sources.list.d";
Dir::Etc::Parts "$work/etc/apt.conf.d";
Dir::Etc::Main "/dev/null";
Dir::State::Lists "$work/lists";
$*
EOF
}
run() { APT_CONFIG=$work/apt.conf bash "$script" --print-sources "$@" 2>&1; }
expect() {  # expect NAME WANT_STATUS OUTPUT_LINE... [-- ARGS]: every line is in the output
  local name=$1 want=$2 out status line missing=
  shift 2
  local lines=()
  while [ $# -gt 0 ] && [ "$1" != -- ]; do lines+=("$1"); shift; done
  [ $# -eq 0 ] || shift
  out=$(run "$@")
  status=$?
  for line in "${lines[@]}"; do
    grep -q -F -- "$line" <<<"$out" || missing+="  missing: $line"$'\n'
  done
  if [ "$status" -eq "$want" ] && [ -z "$missing" ]; then
    pass=$((pass + 1))
  else
    echo "FAILED: $name (exit $status, want $want)"$'\n'"$missing$out"
    fails=$((fails + 1))
  fi
}
refuse() {  # refuse NAME TEXT: the output does not hold TEXT
  if grep -q -F -- "$2" <<<"$(run)"; then
    echo "FAILED: $1: the output holds $2"; fails=$((fails + 1))
  else
    pass=$((pass + 1))
  fi
}

# One-line format: comments, a commented-out entry, options in brackets, deb-src, a
# third-party repository and the security archive.
fresh
cat >"$work/etc/sources.list" <<'EOF'
# deb http://commented.example/debian bookworm main

deb-src http://src.example/debian bookworm main
deb http://repo.example/apt nodistro main
deb [signed-by=/usr/share/keyrings/debian-archive-keyring.gpg arch=amd64] http://mirror.example/debian/ bookworm main contrib # trailing comment
deb [ signed-by=/usr/share/keyrings/debian-archive-keyring.gpg ] http://security.example/debian-security bookworm-security main
EOF
expect "one-line sources" 0 \
  "debootstrap-test: mirror http://mirror.example/debian" \
  "debootstrap-test: root source: deb http://mirror.example/debian bookworm main contrib" \
  "debootstrap-test: root source: deb http://security.example/debian-security bookworm-security main" \
  "debootstrap-test: http proxy: none, https proxy: none"
refuse "a commented-out entry is not read" "commented.example"
refuse "deb-src is not a mirror" "src.example"

# deb822 only (no sources.list): comments, a disabled stanza first, deb-src, several suites, a
# Signed-By with an embedded key, an https mirror.
fresh
cat >"$work/etc/sources.list.d/debian.sources" <<'EOF'
# The archive, deb822 style.
Enabled: no
Types: deb
URIs: http://disabled.example/debian
Suites: bookworm
Components: main

Types: deb-src
URIs: http://src.example/debian
Suites: bookworm
Components: main

Types: deb
# a comment inside a stanza
URIs: https://deb822.example/debian
Suites: bookworm bookworm-updates
Components: main non-free-firmware
Signed-By:
 -----BEGIN PGP PUBLIC KEY BLOCK-----
 .
 mDMEZAAAABYJKwYBBAHaRw8BAQdAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAA
 -----END PGP PUBLIC KEY BLOCK-----

Types: deb
URIs: http://deb822.example/debian-security
Suites: bookworm-security
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
EOF
expect "deb822 sources" 0 \
  "debootstrap-test: mirror https://deb822.example/debian" \
  "debootstrap-test: root source: deb https://deb822.example/debian bookworm main non-free-firmware" \
  "debootstrap-test: root source: deb https://deb822.example/debian bookworm-updates main non-free-firmware" \
  "debootstrap-test: root source: deb http://deb822.example/debian-security bookworm-security main"
refuse "a disabled stanza is not read" "disabled.example"

# Both formats: sources.list comes first, then sources.list.d in order; an entry without main
# or of another suite is not the mirror.
fresh
echo "deb http://nomain.example/debian bookworm contrib" >"$work/etc/sources.list"
echo "deb http://trixie.example/debian trixie main" >"$work/etc/sources.list.d/a.list"
printf 'Types: deb\nURIs: http://b.example/debian\nSuites: bookworm\nComponents: main\n' \
  >"$work/etc/sources.list.d/b.sources"
echo "deb http://c.example/debian bookworm main" >"$work/etc/sources.list.d/c.list"
expect "both formats, first usable entry" 0 "debootstrap-test: mirror http://b.example/debian"
refuse "another suite is not read" "trixie.example"

# No sources at all, only deb-src, only a mirror+file URI: a clear failure naming the override.
fresh
expect "missing sources files" 1 "no http(s) Debian mirror with 'bookworm main' in the apt sources" \
  "$work/etc/sources.list" "--mirror URL or DEBIAN_MIRROR=URL"
echo "deb-src http://src.example/debian bookworm main" >"$work/etc/sources.list"
expect "deb-src only" 1 "no http(s) Debian mirror"
echo "deb mirror+file:/etc/apt/mirrors.txt bookworm main" >"$work/etc/sources.list"
expect "an unusable URI scheme" 1 "no http(s) Debian mirror"
echo "deb http://broken.example/debian bookworm" >"$work/etc/sources.list"
expect "malformed sources" 1 "apt cannot read this machine's sources"

# The override: the option or the environment, even without sources; the option wins.
fresh
expect "--mirror" 0 "debootstrap-test: mirror http://override.example/debian" \
  "debootstrap-test: root source: deb http://override.example/debian bookworm main" \
  -- --mirror http://override.example/debian/
DEBIAN_MIRROR=http://env.example/debian \
  expect "DEBIAN_MIRROR" 0 "debootstrap-test: mirror http://env.example/debian"
DEBIAN_MIRROR=http://env.example/debian \
  expect "--mirror wins over DEBIAN_MIRROR" 0 "debootstrap-test: mirror http://opt.example/debian" \
  -- --mirror=http://opt.example/debian

# apt's proxy: the scheme's, the mirror host's (which wins), DIRECT; credentials not printed.
fresh 'Acquire::http::Proxy "http://user:secret@proxy.example:3142/";'
echo "deb http://mirror.example/debian bookworm main" >"$work/etc/sources.list"
expect "apt's http proxy" 0 \
  "debootstrap-test: http proxy: http://***@proxy.example:3142/, https proxy: none"
refuse "proxy credentials are not printed" "secret"
fresh 'Acquire::http::Proxy "http://proxy.example:3142";
Acquire::http::Proxy::mirror.example "http://near.example:3128";
Acquire::https::Proxy "http://tls.example:3128";'
echo "deb http://mirror.example/debian bookworm main" >"$work/etc/sources.list"
expect "a proxy for the mirror's host" 0 \
  "debootstrap-test: http proxy: http://near.example:3128, https proxy: http://tls.example:3128"
fresh 'Acquire::http::Proxy "http://proxy.example:3142";
Acquire::http::Proxy::mirror.example "DIRECT";'
echo "deb http://mirror.example/debian bookworm main" >"$work/etc/sources.list"
http_proxy=http://env-proxy.example:8080 \
  expect "DIRECT for the mirror's host" 0 "debootstrap-test: http proxy: none, https proxy: none"
fresh
echo "deb http://mirror.example/debian bookworm main" >"$work/etc/sources.list"
http_proxy=http://env-proxy.example:8080 \
  expect "no apt proxy: the environment's stays" 0 \
  "debootstrap-test: http proxy: http://env-proxy.example:8080, https proxy: none"

# The usage names the override.
out=$(bash "$script" --help)
if grep -q -- "--mirror URL" <<<"$out" && grep -q DEBIAN_MIRROR <<<"$out"; then
  pass=$((pass + 1))
else
  echo "FAILED: --help names --mirror and DEBIAN_MIRROR"; fails=$((fails + 1))
fi

echo "debootstrap_sources_test: $pass passed, $fails failed"
[ "$fails" -eq 0 ]
