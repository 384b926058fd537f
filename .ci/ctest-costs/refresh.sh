#!/usr/bin/env bash
# Refreshes .ci/ctest-costs/<preset>.txt from a build folder that ran the suite: each current
# test's longest recorded time, in CTest's cost-data format. CTest starts the longest tests
# first when it knows their times, so the two cores stay busy to the end of a fresh CI run.
#   .ci/ctest-costs/refresh.sh release|sanitize
set -euo pipefail
cd "$(dirname "$0")/../.."
case "${1:-}" in release|sanitize) ;; *) echo "usage: .ci/ctest-costs/refresh.sh release|sanitize" >&2; exit 2 ;; esac
data=build/$1/Testing/Temporary/CTestCostData.txt
[ -s "$data" ] || { echo "no $data: run the suite of that preset first" >&2; exit 1; }
names=$(mktemp)
trap 'rm -f "$names"' EXIT
ctest --preset "$1" -N | sed -n 's/^ *Test *#[0-9]*: //p' | sort > "$names"
{
  awk 'NF == 3 { if (!($1 in c) || $3 > c[$1]) c[$1] = $3 }
       END { for (n in c) printf "%s 1 %.1f\n", n, c[n] }' "$data" | sort -k1,1 | join - "$names"
  echo "---"
} > ".ci/ctest-costs/$1.txt"
echo "$(($(wc -l < ".ci/ctest-costs/$1.txt") - 1)) of $(wc -l < "$names") tests in .ci/ctest-costs/$1.txt"
