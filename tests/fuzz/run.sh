#!/usr/bin/env bash
# Builds the libFuzzer targets (clang++, -fsanitize=fuzzer,address,undefined) and runs them side
# by side, each for SECONDS seconds from its seed corpus (tests/fuzz/corpus/<target>), failing on
# the first crash, sanitizer report, abort, leak, input slower than 10 s (a hang) or over 2 GB of
# memory.
#
#   tests/fuzz/run.sh SECONDS [PRESET]
#
# PRESET is a configure preset that builds the targets: `fuzz` (the default: the fuzzers
# only) or `sanitize` (the test suite and the fuzzers, as CI builds them). Findings are written
# to build/<preset>/fuzz-findings/; reproduce one with
#   build/<preset>/tests/fuzz/fuzz_<target> build/<preset>/fuzz-findings/<target>-crash-...
# New inputs that reach new code collect in build/<preset>/fuzz-corpus/<target> (not committed;
# copy the interesting ones to tests/fuzz/corpus/<target> by hand).
#
# Seeds: corpus/scenario holds the shipped scenarios; corpus/recording short recordings made
# with `mixpilot fly --headless --duration 0.045 --record` (mi_helix, tracking_helix), the same
# with their data and summary CRCs zeroed (*_nocrc: "not computed" in the spec, so mutations
# reach the structure checks and the CDR decoders instead of stopping at a CRC), one cut at two
# thirds (a crashed session's temporary) and the spec's smallest file.
set -euo pipefail
cd "$(dirname "$0")/../.."

usage() { echo "usage: tests/fuzz/run.sh SECONDS [fuzz|sanitize]" >&2; exit 2; }
[ $# -ge 1 ] && [ $# -le 2 ] || usage
seconds=$1
preset=${2:-fuzz}
[[ "$seconds" =~ ^[0-9]+$ ]] && [ "$seconds" -gt 0 ] || usage
case "$preset" in fuzz|sanitize) ;; *) usage ;; esac

cmake --preset "$preset" >/dev/null
cmake --build --preset "$preset" --target fuzz_recording fuzz_scenario

build=build/$preset
findings=$build/fuzz-findings
mkdir -p "$findings"
# Symbolized stacks when llvm-symbolizer is there; leaks are findings too.
symbolizer=$(command -v llvm-symbolizer || command -v llvm-symbolizer-14 || true)
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1${symbolizer:+:external_symbolizer_path=$symbolizer}}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}

# Both targets at once (a process each, one core each where there are two), then each judged.
targets=(recording scenario)
pids=()
for target in "${targets[@]}"; do
  corpus=$build/fuzz-corpus/$target
  mkdir -p "$corpus"
  echo "fuzz_$target: ${seconds} s from tests/fuzz/corpus/$target"
  # The first corpus folder receives new inputs; the seeds are only read. The dictionary lists
  # the scenario keys and values, so mutations produce plausible TOML.
  dict=()
  [ -f "tests/fuzz/$target.dict" ] && dict=(-dict="tests/fuzz/$target.dict")
  "$build/tests/fuzz/fuzz_$target" "${dict[@]}" -max_total_time="$seconds" -timeout=10 \
    -rss_limit_mb=2048 -max_len=65536 -print_final_stats=1 \
    -artifact_prefix="$findings/$target-" "$corpus" "tests/fuzz/corpus/$target" \
    >"$findings/$target.log" 2>&1 &
  pids+=($!)
done
failed=0
for i in "${!targets[@]}"; do
  target=${targets[$i]}
  if ! wait "${pids[$i]}"; then
    echo "fuzz_$target: FAILED (the input is in $findings/$target-*; full log $findings/$target.log)"
    grep -E "ERROR|SUMMARY|Test unit written|^ +#[0-9]+ " "$findings/$target.log" | head -n 30 ||
      tail -n 20 "$findings/$target.log"
    failed=$((failed + 1))
  else
    grep -E "^#[0-9]+ +DONE|stat::number_of_executed_units|stat::peak_rss_mb" "$findings/$target.log" | tail -n 3
    echo "fuzz_$target: no crash"
  fi
done
passed=$((${#targets[@]} - failed))
echo "fuzz: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
