#!/usr/bin/env bash
# What a user gets from every command's outputs and messages, end to end: empty option values
# are usage errors naming the option; an output never replaces an input of the same command (by
# any name: compared by device and inode); a usage error never leaves a temporary behind; a
# full disk or a folder removed during the run is said as it is; names at NAME_MAX work;
# `recover` refuses a file with no whole control step and puts a complete temporary in place;
# messages never pass a file's terminal escape sequences on; the user's folders never default
# to the current folder; every command has its own --help and summary label; --duration keeps
# the reference clear of the arena's walls. Usage: test_outputs.sh MIXPILOT SOURCE_DIR
set -u
mixpilot=$(realpath "$1")
src=$2
work=$(mktemp -d)
trap 'chmod -R u+rwx "$work" 2>/dev/null; rm -rf "$work"' EXIT
fails=0
pass=0
check() {  # check NAME CONDITION-COMMAND...
  local name=$1
  shift
  if "$@"; then
    pass=$((pass + 1))
  else
    echo "FAILED: $name"
    fails=$((fails + 1))
  fi
}
no_escape() { ! grep -q $'\x1b\|\x07' "$1"; }
no_temporaries() { test -z "$(find "$1" -name '*.tmp' 2>/dev/null)"; }
helix=$src/scenarios/mi_helix.toml
slow=$src/scenarios/mi_helix_slow.toml

"$mixpilot" fly --scenario "$helix" --pilot novice --headless --duration 0.3 \
  --record "$work/rec.mcap" >/dev/null 2>&1
check "a short recording to work with" test -s "$work/rec.mcap"
cp "$work/rec.mcap" "$work/rec.orig"

# --- Empty option values and file arguments: usage errors (exit 2) that name the option. -----
expect_usage() {  # expect_usage NAME OPTION-NAMED-IN-MESSAGE ARGS...
  local name=$1 option=$2
  shift 2
  (cd "$work" && timeout 20 "$mixpilot" "$@") >"$work/u.out" 2>&1
  local rc=$?
  check "$name: exit 2 (got $rc)" test $rc -eq 2
  check "$name: names $option" grep -qF -- "$option" "$work/u.out"
}
f=(fly --scenario "$helix" --pilot novice --headless --duration 0.3)
expect_usage "fly --record ''" "--record" "${f[@]}" --record ''
expect_usage "fly --report ''" "--report" "${f[@]}" --report ''
expect_usage "fly --scenario ''" "--scenario" fly --scenario '' --headless
expect_usage "fly --pilot ''" "--pilot" fly --scenario "$helix" --pilot '' --headless
expect_usage "fly --input-settings ''" "--input-settings" "${f[@]}" --input-settings ''
expect_usage "fly --gamepad-script ''" "--gamepad-script" fly --scenario "$helix" \
  --pilot gamepad --headless --realtime --gamepad-script ''
expect_usage "fly --screenshot ''" "--screenshot" "${f[@]}" --screenshot ''
expect_usage "fly --screenshot 'T:'" "--screenshot" "${f[@]}" --screenshot '0.1:'
expect_usage "fly --duration ''" "--duration" fly --scenario "$helix" --headless --duration ''
expect_usage "replay ''" "empty" replay '' --headless
expect_usage "replay --screenshot ''" "--screenshot" replay rec.mcap --headless --screenshot ''
expect_usage "score ''" "empty" score ''
expect_usage "score --json ''" "--json" score rec.mcap --json ''
expect_usage "recover ''" "empty" recover ''
expect_usage "recover -o ''" "-o" recover rec.mcap -o ''
expect_usage "gamepad-script ''" "empty" gamepad-script '' -o x.csv
expect_usage "gamepad-script -o ''" "-o" gamepad-script rec.mcap -o ''
expect_usage "gamepad-script --input-settings ''" "--input-settings" gamepad-script rec.mcap \
  -o x.csv --input-settings ''
expect_usage "joy-publish --from ''" "--from" joy-publish --from ''
expect_usage "joy-publish --input-settings ''" "--input-settings" joy-publish --from rec.mcap \
  --input-settings ''
expect_usage "vehicle --scenario ''" "--scenario" vehicle --scenario ''
expect_usage "history --html ''" "--html" history --trainee Ada --html ''
check "no empty option wrote anything" test "$(ls "$work" | sort | tr '\n' ' ')" = "rec.mcap rec.orig u.out "

# --- An output never replaces an input of the same command, by any name. ---------------------
ln -s rec.mcap "$work/alias.mcap"
ln "$work/rec.mcap" "$work/hard.mcap"
for out in rec.mcap alias.mcap hard.mcap; do
  (cd "$work" && "$mixpilot" score rec.mcap --json "$out" --force) >"$work/s.out" 2>&1
  check "score --json $out --force (the recording): usage error" test $? -eq 2
  check "... saying so" grep -q "is the same file as the recording" "$work/s.out"
  (cd "$work" && "$mixpilot" gamepad-script rec.mcap -o "$out" --force) >"$work/s.out" 2>&1
  check "gamepad-script -o $out --force (the recording): usage error" test $? -eq 2
  (cd "$work" && "$mixpilot" replay rec.mcap --headless --screenshot "0.1:$out" --force) \
    >"$work/s.out" 2>&1
  check "replay --screenshot 0.1:$out --force (the recording): usage error" test $? -eq 2
  (cd "$work" && "$mixpilot" fly --pilot rec.mcap --headless --record "$out" --force) \
    >"$work/s.out" 2>&1
  check "fly --pilot rec.mcap --record $out --force: usage error" test $? -eq 2
  (cd "$work" && "$mixpilot" recover rec.mcap -o "$out" --force) >"$work/s.out" 2>&1
  check "recover rec.mcap -o $out --force: usage error" test $? -eq 2
done
check "the recording survived every attempt" cmp -s "$work/rec.mcap" "$work/rec.orig"
# The history a command writes or reads is an input too: its database and the -wal and -shm
# that come and go with its connections.
hist=$work/hist/h.sqlite
"$mixpilot" fly --scenario "$helix" --headless --duration 0.3 --trainee Ada \
  --history "sqlite:$hist" >/dev/null 2>&1
check "a history to protect" test -s "$hist"
cp "$hist" "$work/hist.orig"
for out in "$hist" "$hist-wal" "$work/hist/../hist/h.sqlite"; do
  "$mixpilot" history --history "$hist" --trainee Ada --html "$out" --force >"$work/s.out" 2>&1
  check "history --html $out --force (the history): usage error" test $? -eq 2
  check "... saying so" grep -q "is the same file as the history" "$work/s.out"
  "$mixpilot" "${f[@]}" --history "sqlite:$hist" --record "$out" --force >"$work/s.out" 2>&1
  check "fly --record $out --force (its history): usage error" test $? -eq 2
  "$mixpilot" "${f[@]}" --history "$hist" --report "$out" --force >"$work/s.out" 2>&1
  check "fly --report $out --force (its history): usage error" test $? -eq 2
done
check "the history survived every attempt" cmp -s "$hist" "$work/hist.orig"
check "... and no -wal was made of a report" test ! -s "$hist-wal"
rm -rf "$work/hist" "$work/hist.orig"
cp "$helix" "$work/s.toml"
"$mixpilot" fly --scenario "$work/s.toml" --headless --duration 0.3 --report "$work/s.toml" \
  --force >"$work/s.out" 2>&1
check "fly --report over its --scenario: usage error" test $? -eq 2
check "... the scenario intact" cmp -s "$helix" "$work/s.toml"
# A file the scenario names (a reference trajectory) is an input too.
mkdir -p "$work/ob/references"
cp "$src/scenarios/obstacles_thrown_balls.toml" "$work/ob/"
cp "$src/scenarios/references/obstacles_to_1_-1_1.csv" "$work/ob/references/"
cp "$work/ob/references/obstacles_to_1_-1_1.csv" "$work/ob/ref.orig"
"$mixpilot" fly --scenario "$work/ob/obstacles_thrown_balls.toml" --headless --duration 0.3 \
  --report "$work/ob/references/obstacles_to_1_-1_1.csv" --force >"$work/s.out" 2>&1
check "fly --report over the scenario's reference CSV: refused" test $? -eq 1
check "... saying it is an input" grep -q "this run read it as an input" "$work/s.out"
check "... the reference intact" cmp -s "$work/ob/ref.orig" "$work/ob/references/obstacles_to_1_-1_1.csv"
rm -f "$work/alias.mcap" "$work/hard.mcap" "$work/s.toml" "$work"/*.out

# --- Usage errors come before any output is opened: nothing is left behind. ------------------
"$mixpilot" fly --scenario "$helix" --pilot novice --headless --duration 1 \
  --record "$work/u.mcap" --report "$work/u.json" --screenshot 5:"$work/u.png" >"$work/e.out" 2>&1
check "--screenshot beyond the flight: usage error" test $? -eq 2
check "... and no recording, report or temporary" test -z "$(ls "$work" | grep '^u\.')"
"$mixpilot" replay "$work/rec.mcap" --headless --screenshot 0.1:"$work/a.png" \
  --screenshot 99:"$work/b.png" >"$work/e.out" 2>&1
check "replay --screenshot beyond the recording: usage error" test $? -eq 2
check "... and not even the earlier screenshot written" test ! -e "$work/a.png"
no_temporaries "$work"
check "no temporary anywhere" no_temporaries "$work"

# --- recover: no whole control step is nothing to recover; a complete temporary goes in place.
python3 - "$work/rec.mcap" "$work/nostep.mcap.Ab12Cd.tmp" <<'PY'
import struct, sys
data = open(sys.argv[1], "rb").read()
at = 8
while True:  # up to the first Message record (opcode 0x05): header, schemas, channels, metadata
    op = data[at]
    (length,) = struct.unpack_from("<Q", data, at + 1)
    if op == 0x05:
        break
    at += 9 + length
open(sys.argv[2], "wb").write(data[:at + 30])
PY
"$mixpilot" recover "$work/nostep.mcap.Ab12Cd.tmp" >"$work/r.out" 2>&1
check "recover of a file cut before its first step: exit 1" test $? -eq 1
check "... saying why" grep -q "cut before its first whole control step" "$work/r.out"
check "... writing nothing" test ! -e "$work/nostep.mcap"
cp "$work/rec.mcap" "$work/second.mcap.Qw34Er.tmp"
"$mixpilot" recover "$work/second.mcap.Qw34Er.tmp" >"$work/r.out" 2>&1
check "recover of a complete temporary: exit 0" test $? -eq 0
check "... it is in place, byte for byte" cmp -s "$work/second.mcap" "$work/rec.mcap"
check "... and the temporary is gone" test ! -e "$work/second.mcap.Qw34Er.tmp"
"$mixpilot" score "$work/second.mcap" >"$work/r.out" 2>&1
check "... and it scores" grep -q "exact" "$work/r.out"
check "... saying how fast it replayed" grep -Eq "s CPU, [0-9.]+ s wall: [0-9]+x real time" "$work/r.out"
rm -f "$work"/nostep* "$work/second.mcap" "$work/r.out"

# --- Names at NAME_MAX: the temporary's suffix never makes a legal name fail. ----------------
long=$(printf 'n%.0s' $(seq 1 245))
"$mixpilot" fly --scenario "$helix" --pilot novice --headless --duration 0.3 \
  --report "$work/$long.json" --record "$work/${long}1.mcap" >"$work/l.out" 2>&1
check "a 250-character --report and a 251-character --record: exit 0" test $? -eq 0
check "... both written" test -s "$work/$long.json" -a -s "$work/${long}1.mcap"
check "... no temporary left" no_temporaries "$work"
rm -f "$work/$long.json" "$work/${long}1.mcap" "$work/l.out"

# --- A full disk: writes fail with EFBIG beyond a file-size limit (SIGXFSZ ignored, as a full
# disk sends none). Nothing reached the disk: no empty temporary is left, none is called kept.
mkdir "$work/full"
(ulimit -f 0; trap '' XFSZ; exec "$mixpilot" fly --scenario "$helix" --pilot novice --headless \
  --duration 0.3 --record "$work/full/x.mcap" --report "$work/full/x.json") 2>&1 | cat >"$work/f.out"
check "a full disk: the write error is reported" grep -q "File too large" "$work/f.out"
check "... not said to be kept" sh -c "! grep -q 'kept in' '$work/f.out'"
check "... and no empty temporary left" test -z "$(find "$work/full" -name '*.tmp' -size 0)"
# Some of it reached the disk: kept, and said so.
(ulimit -f 64; trap '' XFSZ; exec "$mixpilot" fly --scenario "$helix" --pilot novice --headless \
  --duration 3 --record "$work/full/y.mcap") 2>&1 | cat >"$work/f.out"
tmp=$(find "$work/full" -name 'y.mcap.*.tmp' | head -n 1)
check "a disk that fills mid-flight keeps what was written" test -s "$tmp"
check "... and says where" grep -qF "kept in $tmp" "$work/f.out"
rm -rf "$work/full" "$work/f.out"

# --- The output's folder removed during the run: the message does not claim it is kept. ------
mkdir "$work/gone"
"$mixpilot" fly --scenario "$slow" --pilot novice --headless --record "$work/gone/x.mcap" \
  >"$work/g.out" 2>&1 &
pid=$!
sleep 1
rm -rf "$work/gone"
kill -INT $pid
wait $pid
check "a removed output folder: the recording fails" grep -q "x.mcap" "$work/g.out"
check "... and it is not said to be kept" sh -c "! grep -q 'kept in' '$work/g.out'"
check "... but lost with its folder" grep -q "is gone (its folder was removed" "$work/g.out"
rm -f "$work/g.out"

# --- Messages never pass a file's control characters on; editors' files read as written. ----
printf 't,left_x,left_y,right_x,right_y\n0,0,0,0,0\n0.1,\033[2J\033]0;owned\a,0,0,0\n' >"$work/esc.csv"
"$mixpilot" fly --scenario "$helix" --pilot gamepad --headless --realtime --duration 0.3 \
  --gamepad-script "$work/esc.csv" >"$work/c.out" 2>&1
check "a script with escape sequences: exit 1" test $? -eq 1
check "... the cell shown escaped" grep -qF 'got "\x1B[2J\x1B]0;owned\x07"' "$work/c.out"
check "... never raw" no_escape "$work/c.out"
sed 's/^name = "mi_helix"/name = "mi\\u001b[2Jhelix"/' "$helix" >"$work/esc.toml"
"$mixpilot" fly --scenario "$work/esc.toml" --headless --duration 0.3 >"$work/c.out" 2>&1
check "a scenario name with an escape sequence: refused" test $? -eq 1
check "... shown escaped, never raw" sh -c "grep -qF 'mi\\x1B[2Jhelix' '$work/c.out' && ! grep -q \$'\\x1b' '$work/c.out'"
ln -s loop.toml "$work/loop.toml"
"$mixpilot" gamepad-script "$work/rec.mcap" -o "$work/o.csv" --input-settings "$work/loop.toml" \
  >"$work/c.out" 2>&1
check "a symbolic-link loop as --input-settings: exit 1" test $? -eq 1
check "... said as such" grep -q "Too many levels of symbolic links" "$work/c.out"
rm -f "$work/esc.csv" "$work/esc.toml" "$work/loop.toml" "$work/c.out" "$work/o.csv"

# --- The user's folders: HOME unset, empty or relative never means the current folder. ------
mkdir -p "$work/cwd/.config/mixpilot" "$work/cwd/relative/mixpilot"
printf 'mode = 9\n' >"$work/cwd/.config/mixpilot/input.toml"
printf 'mode = 9\n' >"$work/cwd/relative/mixpilot/input.toml"
for env in "-u HOME -u XDG_CONFIG_HOME" "HOME= XDG_CONFIG_HOME=" "HOME=. XDG_CONFIG_HOME=relative"; do
  (cd "$work/cwd" && env $env "$mixpilot" gamepad-script ../rec.mcap -o o.csv --force) \
    >"$work/h.out" 2>&1
  check "$env: the current folder's .config is not read" sh -c "! grep -q 'value outside \[1, 4\], got 9' '$work/h.out'"
done
rm -rf "$work/cwd" "$work/h.out"

# --- Every command's own --help; every front end's own summary label. ------------------------
for cmd in fly replay score recover gamepad-script joy-publish vehicle demo models sweep; do
  "$mixpilot" $cmd --help >"$work/help.out" 2>&1
  check "$cmd --help: exit 0" test $? -eq 0
  check "$cmd --help: its own usage" grep -q "^usage: mixpilot $cmd" "$work/help.out"
done
"$mixpilot" replay "$work/rec.mcap" --headless >"$work/l.out" 2>&1
check "replay's summary is labelled replay" grep -q "^mixpilot replay: mi_helix" "$work/l.out"
check "... not fly" sh -c "! grep -q 'mixpilot fly:' '$work/l.out'"
"$mixpilot" fly --pilot "$work/rec.mcap" --headless >"$work/l.out" 2>&1
check "fly's summary is labelled fly" grep -q "^mixpilot fly: mi_helix" "$work/l.out"
rm -f "$work/help.out" "$work/l.out"

# --- --duration keeps the ball B and the vehicle clear of the arena's walls. -----------------
"$mixpilot" fly --scenario "$helix" --pilot novice --headless --duration 57 >"$work/d.out" 2>&1
check "--duration 57 on mi_helix: refused" test $? -eq 1
check "... naming the ceiling and the longest session" \
  grep -q "to the arena's ceiling at t = 42.754 s; this scenario allows at most 42.754 s" "$work/d.out"

echo "$pass passed, $fails failed"
test "$fails" -eq 0
