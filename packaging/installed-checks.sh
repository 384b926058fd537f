#!/usr/bin/env bash
# What a user does with the installed package, from a folder that holds no source: the demo, a
# flight of an installed scenario with a report, a recording scored, a headless screenshot, a
# thesis figure, a video of a replay (or, without ffmpeg, the package to install), the
# instructor's DDS Security test CA (mixpilot-security-ca), the man pages and the help.
# Runs wherever mixpilot is installed (this machine, or the throwaway root of
# packaging/debootstrap-test.sh). Usage: installed-checks.sh WORK_DIR
set -euo pipefail
work=$1
mkdir -p "$work/home"
export HOME=$work/home XDG_CONFIG_HOME=$work/home/.config XDG_DATA_HOME=$work/home/.local/share
unset MIXPILOT_DATA_DIR CYCLONEDDS_URI
cd /
share=/usr/share/mixpilot
say() { echo "installed-checks: $*"; }

[ "$(command -v mixpilot)" = /usr/bin/mixpilot ] || { say "mixpilot is not /usr/bin/mixpilot"; exit 1; }
mixpilot --version
mixpilot --help >/dev/null
say "demo"
mixpilot demo | tee "$work/demo.txt"
grep -q "skill" "$work/demo.txt"
say "fly an installed scenario"
mixpilot fly --scenario $share/scenarios/tracking_smooth_step.toml --headless \
  --report "$work/tracking.json"
grep -q '"lost": 0' "$work/tracking.json"
say "record and score"
mixpilot fly --scenario $share/scenarios/mi_helix.toml --pilot novice --headless --duration 5 \
  --record "$work/novice.mcap" --report "$work/novice.json"
mixpilot score "$work/novice.mcap" --json "$work/score.json"
grep -q skill "$work/score.json"
say "the shipped lessons"
mixpilot lesson --list | grep -q '^beginner ' || { say "no beginner lesson installed"; exit 1; }
mixpilot lesson beginner --check >/dev/null
say "headless screenshot"
mixpilot fly --scenario $share/scenarios/mi_helix.toml --pilot novice --headless --duration 3 \
  --screenshot "2:$work/shot.png"
[ "$(head -c 8 "$work/shot.png" | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] || {
  say "the screenshot is not a PNG"; exit 1; }
say "a thesis figure from the installed scenarios"
mixpilot figures --out "$work/figures" --only 4.4 --width 600 2>"$work/figures.err" || {
  cat "$work/figures.err"; say "figures failed"; exit 1; }
[ "$(head -c 8 "$work/figures/fig_4_4.png" | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] || {
  say "the figure is not a PNG"; exit 1; }
grep -q '^t \[s\],q1 \[rad\]' "$work/figures/fig_4_4.csv" || { say "the figure's CSV has no header"; exit 1; }
# ffmpeg is recommended, not required: without it the command names the package to install.
if command -v ffmpeg >/dev/null; then
  say "video of a replay"
  mixpilot replay "$work/novice.mcap" --video "$work/novice.mp4" --to 1 --size 320x180
  [ "$(head -c 8 "$work/novice.mp4" | tail -c 4)" = ftyp ] || { say "the video is no MP4"; exit 1; }
else
  say "video without ffmpeg"
  if mixpilot replay "$work/novice.mcap" --video "$work/novice.mp4" 2>"$work/video.err"; then
    say "a video without ffmpeg"; exit 1
  fi
  grep -q "apt install ffmpeg" "$work/video.err" || { say "no word of the ffmpeg package"; exit 1; }
fi
say "the DDS Security test CA"
[ "$(command -v mixpilot-security-ca)" = /usr/bin/mixpilot-security-ca ] || {
  say "mixpilot-security-ca is not /usr/bin/mixpilot-security-ca"; exit 1; }
mixpilot-security-ca --help > "$work/ca-help.txt"
grep -q '^usage: mixpilot-security-ca DIR' "$work/ca-help.txt" || {
  say "mixpilot-security-ca --help does not give its usage"; cat "$work/ca-help.txt"; exit 1; }
# openssl is recommended, not required: without it the command names the package to install.
if command -v openssl >/dev/null; then
  mixpilot-security-ca "$work/ca" > "$work/ca.txt"
  for who in instructor trainee-a trainee-b other-ca expired; do
    for f in identity_ca.pem cert.pem key.pem permissions_ca.pem governance.p7s permissions.p7s \
             cyclonedds.xml; do
      [ -s "$work/ca/$who/$f" ] || { say "mixpilot-security-ca made no $who/$f"; exit 1; }
    done
  done
  if mixpilot-security-ca "$work/ca" 2>"$work/ca.err"; then
    say "mixpilot-security-ca replaced a setup without --force"; exit 1
  fi
  grep -q "already holds a setup" "$work/ca.err" || { say "no word of the setup there"; exit 1; }
else
  if mixpilot-security-ca "$work/ca" 2>"$work/ca.err"; then
    say "mixpilot-security-ca made a setup without openssl"; exit 1
  fi
  grep -q "apt-get install openssl" "$work/ca.err" || { say "no word of the openssl package"; exit 1; }
fi
say "man pages"
for page in mixpilot mixpilot-fly mixpilot-score mixpilot-vehicle mixpilot-lesson mixpilot-sweep \
            mixpilot-figures mixpilot-reference mixpilot-security-ca; do
  [ -f /usr/share/man/man1/$page.1.gz ] || { say "no man page $page(1)"; exit 1; }
  zcat /usr/share/man/man1/$page.1.gz | grep -q '^\.TH' || { say "$page(1) is not a man page"; exit 1; }
done
say "no path of the build machine in the binaries"
if [ -n "${MIXPILOT_SOURCE:-}" ] && grep -q -a -F "$MIXPILOT_SOURCE" /usr/bin/mixpilot /usr/bin/mixpilot-reference; then
  say "a binary names $MIXPILOT_SOURCE"; exit 1
fi
say "all passed"
