#!/usr/bin/env python3
"""Mutation run over what every command reads: the type of each input file, deep TOML nesting,
empty paths and the environment's folders.

Inputs (each through every command that reads it):
  --scenario (fly, vehicle), --input-settings (fly --pilot gamepad, gamepad-script,
  joy-publish), the config folder's input.toml and gamecontrollerdb.txt
  ($XDG_CONFIG_HOME/mixpilot/; fly --pilot gamepad, gamepad-script), --gamepad-script (fly),
  the reference CSVs a scenario names (fly), recordings (score, replay, replay --video, fly
  --pilot, gamepad-script, joy-publish, recover), a ghost's recording (fly --ghost, replay
  --ghost), a lesson (lesson --check, lesson --status), a sweep file (sweep --check) and
  MIXPILOT_DATA_DIR (demo); replay --video's
  --from, --to, --fps and --size values out of range or no numbers.
File types: a regular file, an empty one, a directory, a FIFO, /dev/zero, /dev/full, a
symbolic-link loop, a dangling link, an unreadable file (as root, which reads mode-000 files,
the run drops to user nobody with setpriv; without setpriv that kind is left out and the count
says so) and a huge (sparse) file. TOML nesting of depth 33 and 50 000 (dotted keys, table and
array-of-tables headers, nested arrays and inline tables) in scenarios, input settings (the
option and the config folder's file) and a recording's embedded scenario. An empty string for
every file option. HOME and XDG_CONFIG_HOME unset, empty or relative, with a poisoned
./.config in the current folder.

Each run is classified:

  clean error  exit 1 or 2 with a message naming the input (a TOML error pointing into the text:
               `file:line:col: key: ...`; an empty path: exit 2 naming the option)
  accepted     exit 0 where that is a right answer (a valid file; a broken config file, which
               never stops a flight: its problem is said and the defaults are used)
  crash        a signal, abort or exit >= 128
  hang         the timeout was reached (a FIFO that blocks a reader)
  nonsense     exit 0 where the input cannot be right (an empty path, a device, a directory as
               a scenario), an error that does not name what was wrong, an escape character in
               the output, or the current folder's .config read as the user's

Prints `tried / clean error / accepted / crash / hang / nonsense`; exits 1 if any run crashed,
hung or gave nonsense. --sample K runs a seeded random sample of K cases (the CTest); --only TEXT
the cases whose label holds TEXT (--only ghost); the full run is the script without either
(tests/mutate_inputs.py --mixpilot build/release/app/mixpilot).
"""
import argparse
import os
import random
import re
import shutil
import struct
import sqlite3
import subprocess
import sys
import tempfile
from pathlib import Path

from mutate_scenarios import LOCATED, Tally, limit_memory

KINDS = ("regular", "empty", "directory", "fifo", "dev_zero", "dev_full", "symlink_loop",
         "dangling_symlink", "unreadable", "huge")
HUGE_BYTES = 64 << 30  # sparse: beyond every reader's bound, never read


def nested_variants(depth):
    """(label, TOML text appended to a valid file) nesting `depth` levels deep."""
    return [
        (f"dotted_key{depth}", ".".join(["k"] * depth) + " = 1\n"),
        (f"table_header{depth}", "[" + ".".join(["t"] * depth) + "]\nx = 1\n"),
        (f"array_of_tables{depth}", "[[" + ".".join(["a"] * depth) + "]]\nx = 1\n"),
        (f"nested_arrays{depth}", "n = " + "[" * depth + "1" + "]" * depth + "\n"),
        (f"inline_tables{depth}", "i = " + "{ i = " * (depth - 1) + "1" + " }" * (depth - 1) + "\n"),
    ]


# ---- MCAP: a recording with another embedded scenario ---------------------------------------

MAGIC = b"\x89MCAP0\r\n"


def _string(b):
    return struct.pack("<I", len(b)) + b


def with_embedded_scenario(data, scenario_text):
    """The recording `data` with the 'mixpilot' metadata record's scenario replaced; written
    without a summary section (the Footer says none, CRCs "not computed"), which readers accept."""
    at = len(MAGIC)
    out = bytearray(MAGIC)
    while at + 9 <= len(data):
        op = data[at]
        (length,) = struct.unpack_from("<Q", data, at + 1)
        content = data[at + 9:at + 9 + length]
        if op == 0x0F:  # Data End: the summary follows
            break
        if op == 0x0C:  # Metadata: name, then a map of strings
            (n,) = struct.unpack_from("<I", content, 0)
            name = content[4:4 + n]
            p = 4 + n
            (map_len,) = struct.unpack_from("<I", content, p)
            p += 4
            end = p + map_len
            pairs = []
            while p < end:
                (kl,) = struct.unpack_from("<I", content, p)
                k = content[p + 4:p + 4 + kl]
                p += 4 + kl
                (vl,) = struct.unpack_from("<I", content, p)
                v = content[p + 4:p + 4 + vl]
                p += 4 + vl
                if name == b"mixpilot" and k == b"scenario":
                    v = scenario_text.encode()
                pairs.append(_string(k) + _string(v))
            body = b"".join(pairs)
            content = _string(name) + struct.pack("<I", len(body)) + body
        out += bytes([op]) + struct.pack("<Q", len(content)) + content
        at += 9 + length
    out += bytes([0x0F]) + struct.pack("<Q", 4) + struct.pack("<I", 0)
    out += bytes([0x02]) + struct.pack("<Q", 20) + struct.pack("<QQI", 0, 0, 0)
    out += MAGIC
    return bytes(out)


# ---- the cases --------------------------------------------------------------------------

class Case:
    """One run: argv (with {X} for the input's path), what the input is, what may be right."""

    def __init__(self, label, argv, expect, needle=None, env=None, kind=None, make=None,
                 cwd_poison=False):
        self.label = label
        self.argv = argv
        self.expect = expect    # "any" | "refused" | "toml" | "usage" | "config"
        self.needle = needle    # text the message must hold (the input's name or the option)
        self.env = env or {}
        self.kind = kind        # file type of the input at {X}
        self.make = make        # callable(case_dir) -> path of the input (valid content)
        self.cwd_poison = cwd_poison


def build_cases(base, binary, scen_dir, setpriv):
    """Every case; `base` holds the valid files the cases copy."""
    rec = base / "rec.mcap"
    script = base / "script.csv"
    cases = []

    def file_input(name, content):
        def make(d, name=name, content=content):
            p = d / name
            p.write_bytes(content)
            return p
        return make

    scenario_text = (scen_dir / "mi_helix.toml").read_bytes()
    settings_text = b"mode = 2\n"
    db_text = b"03000000aaaa0000bbbb000000000000,Fake pad,a:b0,b:b1,leftx:a0,lefty:a1,platform:Linux,\n"
    short = ["--duration", "0.3"]
    gamepad_fly = ["fly", "--scenario", str(scen_dir / "mi_helix.toml"), "--pilot", "gamepad",
                   "--headless", "--realtime"] + short

    # (input label, make, [(command label, argv with {X}, expect for non-regular kinds)], env)
    inputs = [
        ("--scenario", file_input("s.toml", scenario_text), [
            ("fly", ["fly", "--scenario", "{X}", "--headless"] + short, "refused"),
            ("vehicle", ["vehicle", "--scenario", "{X}", "--wait", "0"], "refused"),
        ], {}),
        ("--input-settings", file_input("in.toml", settings_text), [
            ("gamepad-script", ["gamepad-script", str(rec), "-o", "{D}/out.csv",
                                "--input-settings", "{X}"], "refused"),
            ("joy-publish", ["joy-publish", "--from", str(rec), "--wait", "0",
                             "--input-settings", "{X}"], "refused"),
            ("fly", gamepad_fly + ["--gamepad-script", str(script), "--input-settings", "{X}"],
             "refused"),
        ], {}),
        ("--gamepad-script", file_input("pad.csv", script.read_bytes()), [
            ("fly", gamepad_fly + ["--gamepad-script", "{X}"], "refused"),
        ], {}),
        ("recording", file_input("r.mcap", rec.read_bytes()), [
            ("score", ["score", "{X}", "--jobs", "1"], "refused"),
            ("replay", ["replay", "{X}", "--headless"], "refused"),
            ("replay --video", ["replay", "{X}", "--video", "{D}/out.mp4", "--size", "64x64",
                                "--fps", "5"], "refused"),
            ("fly --pilot", ["fly", "--pilot", "{X}", "--headless"], "refused"),
            ("gamepad-script", ["gamepad-script", "{X}", "-o", "{D}/out.csv"], "refused"),
            ("joy-publish", ["joy-publish", "--from", "{X}", "--wait", "0"], "refused"),
            ("recover", ["recover", "{X}", "-o", "{D}/out.mcap"], "refused"),
        ], {}),
        # A lesson (SPEC §10): read to check it, and to say a trainee's progress in it.
        ("lesson", file_input("l.toml", (scen_dir / "lessons" / "beginner.toml").read_bytes()), [
            ("lesson --check", ["lesson", "{X}", "--check"], "refused"),
            ("lesson --status", ["lesson", "{X}", "--trainee", "t", "--status", "--history",
                                 "{D}/h.sqlite"], "refused"),
        ], {}),
        # A sweep file (docs/sweeps.md): read, its plan expanded and every run checked.
        ("sweep", file_input("sw.toml", (scen_dir / "sweeps" / "tracking_rtt.toml").read_bytes()), [
            ("sweep --check", ["sweep", "{X}", "--check"], "refused"),
        ], {}),
        # A ghost (SPEC §10): a recording of the scenario flown, read beside the flight.
        ("--ghost", file_input("g.mcap", rec.read_bytes()), [
            ("fly", ["fly", "--scenario", str(scen_dir / "mi_helix.toml"), "--pilot", "novice",
                     "--headless", "--history", "off", "--ghost", "{X}"] + short, "refused"),
            ("replay", ["replay", str(rec), "--headless", "--ghost", "{X}"], "refused"),
        ], {}),
    ]
    # The config folder's files: their problems never stop a flight.
    for name, content in (("input.toml", settings_text), ("gamecontrollerdb.txt", db_text)):
        def make(d, name=name, content=content):
            p = d / "cfg" / "mixpilot" / name
            p.parent.mkdir(parents=True, exist_ok=True)
            p.write_bytes(content)
            return p
        cmds = [("fly", gamepad_fly + ["--gamepad-script", str(script)], "config")]
        if name == "input.toml":
            cmds.append(("gamepad-script", ["gamepad-script", str(rec), "-o", "{D}/out.csv"],
                         "config"))
        inputs.append((f"config {name}", make, cmds, {"XDG_CONFIG_HOME": "{D}/cfg"}))
    # Reference CSVs, each through the scenario that names it.
    for toml in sorted(scen_dir.glob("*.toml")):
        m = re.search(r'^\s*(?:file|reference)\s*=\s*"references/([^"]+)"', toml.read_text(), re.M)
        if not m:
            continue
        csv_name = m.group(1)

        def make(d, toml=toml, csv_name=csv_name):
            (d / "references").mkdir(exist_ok=True)
            shutil.copy(toml, d / toml.name)
            p = d / "references" / csv_name
            p.write_bytes((scen_dir / "references" / csv_name).read_bytes())
            return p
        inputs.append((f"reference {csv_name} of {toml.stem}", make, [
            ("fly", ["fly", "--scenario", "{D}/" + toml.name, "--headless"] + short, "refused")],
            {}))

    # The trainee's history (SQLite): a flight is never refused for its history (the problem is
    # said, naming the file), a listing is; `history import` reads a folder.
    def history_db(d):
        p = d / "h.sqlite"
        sqlite3.connect(str(p)).close()  # an empty database: the app migrates it
        return p
    inputs.append(("--history", history_db, [
        ("fly", ["fly", "--scenario", str(scen_dir / "mi_helix.toml"), "--pilot", "novice",
                 "--headless", "--history", "{X}"]
         + short, "config"),
        ("history", ["history", "--history", "{X}"], "refused"),
    ], {}))
    def recordings_folder(d):
        p = d / "recs"
        p.mkdir()
        shutil.copy(rec, p / "a.mcap")
        return p
    inputs.append(("history import DIR", recordings_folder, [
        ("history import", ["history", "import", "{X}", "--history", "{D}/h.sqlite"],
         "refused"),
    ], {}))

    # An empty file is a valid settings file (every key defaulted), mapping database and
    # SQLite database; a history import of an empty folder imports nothing.
    empty_ok = ("--input-settings", "config input.toml", "config gamecontrollerdb.txt",
                "--history")
    for input_label, make, cmds, env in inputs:
        for cmd_label, argv, expect in cmds:
            for kind in KINDS:
                if kind == "unreadable" and os.geteuid() == 0 and not setpriv:
                    continue
                right = "any" if kind == "regular" or (kind == "empty" and
                                                       input_label in empty_ok) else expect
                if input_label == "history import DIR" and kind == "directory":
                    right = "any"  # an empty folder: nothing to import
                cases.append(Case(f"{input_label} {kind} via {cmd_label}", argv, right, "{X}",
                                  env, kind, make))

    # MIXPILOT_DATA_DIR: the folder itself, and the scenario demo reads from it.
    def data_dir(d):
        p = d / "data"
        p.mkdir()
        return p

    def data_scenario(d):
        (d / "data" / "scenarios").mkdir(parents=True)
        p = d / "data" / "scenarios" / "mi_helix.toml"
        p.write_bytes(scenario_text)
        return p
    for kind in KINDS:
        if kind == "unreadable" and os.geteuid() == 0 and not setpriv:
            continue
        if kind != "regular":  # a valid folder is the second group's regular case
            cases.append(Case(f"MIXPILOT_DATA_DIR {kind} via demo", ["demo"], "refused",
                              "MIXPILOT_DATA_DIR", {"MIXPILOT_DATA_DIR": "{X}"},
                              "directory_empty" if kind == "directory" else kind, data_dir))
        cases.append(Case(f"MIXPILOT_DATA_DIR/scenarios/mi_helix.toml {kind} via demo", ["demo"],
                          "any" if kind == "regular" else "refused", "{X}",
                          {"MIXPILOT_DATA_DIR": "{D}/data"}, kind, data_scenario))

    # Deep nesting: in a scenario, the settings (the option and the config folder's file) and a
    # recording's embedded scenario.
    for depth in (33, 50000):
        for label, extra in nested_variants(depth):
            text = scenario_text + b"\n" + extra.encode()
            cases.append(Case(f"nesting {label} in --scenario via fly",
                              ["fly", "--scenario", "{X}", "--headless"] + short, "toml", None,
                              {}, "regular", file_input("deep.toml", text)))
            ltext = (scen_dir / "lessons" / "beginner.toml").read_bytes() + b"\n" + extra.encode()
            cases.append(Case(f"nesting {label} in a lesson via lesson --check",
                              ["lesson", "{X}", "--check"], "toml", None, {}, "regular",
                              file_input("deep_lesson.toml", ltext)))
            wtext = (scen_dir / "sweeps" / "tracking_rtt.toml").read_bytes() + b"\n" + extra.encode()
            cases.append(Case(f"nesting {label} in a sweep file via sweep --check",
                              ["sweep", "{X}", "--check"], "toml", None, {}, "regular",
                              file_input("deep_sweep.toml", wtext)))
            stext = settings_text + extra.encode()
            cases.append(Case(f"nesting {label} in --input-settings via gamepad-script",
                              ["gamepad-script", str(rec), "-o", "{D}/out.csv",
                               "--input-settings", "{X}"], "toml", None, {}, "regular",
                              file_input("deep_in.toml", stext)))

            def cfg(d, stext=stext):
                p = d / "cfg" / "mixpilot" / "input.toml"
                p.parent.mkdir(parents=True, exist_ok=True)
                p.write_bytes(stext)
                return p
            cases.append(Case(f"nesting {label} in config input.toml via gamepad-script",
                              ["gamepad-script", str(rec), "-o", "{D}/out.csv"], "config_toml",
                              None, {"XDG_CONFIG_HOME": "{D}/cfg"}, "regular", cfg))
            deep_rec = with_embedded_scenario(rec.read_bytes(), text.decode())
            # As a ghost the embedded scenario is only parsed for its name when its text is not
            # the one flown: refused as another scenario, naming the file.
            cases.append(Case(f"nesting {label} in an embedded scenario via fly --ghost",
                              ["fly", "--scenario", str(scen_dir / "mi_helix.toml"), "--pilot",
                               "novice", "--headless", "--history", "off", "--ghost", "{X}"]
                              + short, "refused", "{X}", {}, "regular",
                              file_input("deep_ghost.mcap", deep_rec)))
            for cmd_label, argv in (
                    ("score", ["score", "{X}", "--jobs", "1"]),
                    ("replay", ["replay", "{X}", "--headless"]),
                    ("fly --pilot", ["fly", "--pilot", "{X}", "--headless"]),
                    ("gamepad-script", ["gamepad-script", "{X}", "-o", "{D}/out.csv"]),
                    ("joy-publish", ["joy-publish", "--from", "{X}", "--wait", "0"])):
                cases.append(Case(f"nesting {label} in an embedded scenario via {cmd_label}",
                                  argv, "toml", None, {}, "regular",
                                  file_input("deep.mcap", deep_rec)))

    # An empty string for every file option and file argument: a usage error naming it.
    S = str(scen_dir / "mi_helix.toml")
    R = str(rec)
    fly = ["fly", "--scenario", S, "--pilot", "novice", "--headless"] + short
    for label, argv, option in (
            ("fly --scenario", ["fly", "--scenario", "", "--headless"], "--scenario"),
            ("fly --pilot", ["fly", "--scenario", S, "--pilot", "", "--headless"], "--pilot"),
            ("fly --record", fly + ["--record", ""], "--record"),
            ("fly --report", fly + ["--report", ""], "--report"),
            ("fly --screenshot", fly + ["--screenshot", ""], "--screenshot"),
            ("fly --screenshot T:", fly + ["--screenshot", "0.1:"], "--screenshot"),
            ("fly --input-settings", fly + ["--input-settings", ""], "--input-settings"),
            ("fly --gamepad-script", gamepad_fly + ["--gamepad-script", ""], "--gamepad-script"),
            ("replay FILE", ["replay", "", "--headless"], "empty"),
            ("replay --screenshot", ["replay", R, "--headless", "--screenshot", ""],
             "--screenshot"),
            ("replay --video", ["replay", R, "--video", ""], "--video"),
            ("replay --from", ["replay", R, "--video", "{D}/o.mp4", "--from", ""], "--from"),
            ("replay --to", ["replay", R, "--video", "{D}/o.mp4", "--to", ""], "--to"),
            ("replay --fps", ["replay", R, "--video", "{D}/o.mp4", "--fps", ""], "--fps"),
            ("replay --size", ["replay", R, "--video", "{D}/o.mp4", "--size", ""], "--size"),
            ("score FILE", ["score", ""], "empty"),
            ("score --json", ["score", R, "--json", ""], "--json"),
            ("recover FILE", ["recover", ""], "empty"),
            ("recover -o", ["recover", R, "-o", ""], "-o"),
            ("gamepad-script FILE", ["gamepad-script", "", "-o", "{D}/o.csv"], "empty"),
            ("gamepad-script -o", ["gamepad-script", R, "-o", ""], "-o"),
            ("gamepad-script --input-settings", ["gamepad-script", R, "-o", "{D}/o.csv",
                                                 "--input-settings", ""], "--input-settings"),
            ("joy-publish --from", ["joy-publish", "--from", ""], "--from"),
            ("joy-publish --input-settings", ["joy-publish", "--from", R, "--wait", "0",
                                              "--input-settings", ""], "--input-settings"),
            ("vehicle --scenario", ["vehicle", "--scenario", ""], "--scenario"),
            ("fly --history", fly + ["--history", ""], "--history"),
            ("fly --trainee", fly + ["--trainee", ""], "--trainee"),
            ("fly --assist", fly + ["--assist", ""], "--assist"),
            ("fly --ghost", fly + ["--ghost", ""], "--ghost"),
            ("replay --ghost", ["replay", R, "--headless", "--ghost", ""], "--ghost"),
            ("history --history", ["history", "--history", ""], "--history"),
            ("history import DIR", ["history", "import", ""], "empty"),
            ("lesson FILE", ["lesson", "", "--check"], "empty"),
            ("sweep FILE", ["sweep", "", "--check"], "empty"),
            ("sweep --out", ["sweep", str(scen_dir / "sweeps" / "tracking_rtt.toml"), "--out", ""],
             "--out"),
            ("sweep --shard", ["sweep", str(scen_dir / "sweeps" / "tracking_rtt.toml"), "--shard",
                               ""], "--shard"),
            ("score --out", ["score", "{D}", "--out", ""], "--out"),
            ("lesson --trainee", ["lesson", "beginner", "--trainee", "", "--status"],
             "--trainee"),
            ("lesson --record-dir", ["lesson", "beginner", "--trainee", "t", "--headless",
                                     "--record-dir", ""], "--record-dir"),
            ("lesson --history", ["lesson", "beginner", "--trainee", "t", "--status",
                                  "--history", ""], "--history"),
            ("figures --out", ["figures", "--out", ""], "--out"),
            ("figures --only", ["figures", "--out", "{D}/figures", "--only", ""], "--only")):
        cases.append(Case(f"empty path {label}", argv, "usage", option))

    # replay --video's values: out of range, not numbers, not finite; each a usage error
    # naming its option (nothing rendered, nothing written).
    video = ["replay", R, "--video", "{D}/v.mp4", "--size", "64x64"]
    numbers = ["-1", "nan", "inf", "-inf", "1e999", " ", "1,5", "10abc", "\u0661", "--"]
    for option, values in (("--from", numbers), ("--to", numbers + ["0", "99"]),
                           ("--fps", numbers + ["0", "0.5", "121", "1e9"]),
                           ("--size", ["0x0", "64x", "x64", "65x64", "64x-64", "99999x99999",
                                       "64X64", "64x64x64"])):
        for v in values:
            argv = [a for a in video if option != "--size" or a not in ("--size", "64x64")]
            cases.append(Case(f"value {option} {v!r} via replay --video", argv + [option, v],
                              "usage", option))

    # The user's folders from the environment: never the current folder's .config.
    for label, env in (("HOME unset", {"HOME": None, "XDG_CONFIG_HOME": None}),
                       ("HOME empty", {"HOME": "", "XDG_CONFIG_HOME": ""}),
                       ("HOME relative", {"HOME": ".", "XDG_CONFIG_HOME": None}),
                       ("XDG_CONFIG_HOME relative", {"HOME": ".", "XDG_CONFIG_HOME": ".config"})):
        cases.append(Case(f"environment {label} via gamepad-script",
                          ["gamepad-script", R, "-o", "{D}/o.csv"], "any", None, env,
                          cwd_poison=True))
    return cases


def make_kind(kind, path, make, case_dir):
    """Puts an input of `kind` at the path `make` fills with valid content."""
    p = make(case_dir)
    if kind in ("regular", "unreadable"):
        if kind == "unreadable":
            p.chmod(0)
        return p
    if p.is_dir():
        shutil.rmtree(p)
    else:
        p.unlink()
    if kind == "empty":
        p.write_bytes(b"")
    elif kind == "directory":
        p.mkdir()
    elif kind == "directory_empty":
        p.mkdir()
    elif kind == "fifo":
        os.mkfifo(p)
    elif kind == "dev_zero":
        p.symlink_to("/dev/zero")
    elif kind == "dev_full":
        p.symlink_to("/dev/full")
    elif kind == "symlink_loop":
        p.symlink_to(p.name)
    elif kind == "dangling_symlink":
        p.symlink_to(p.name + ".missing")
    elif kind == "huge":
        with open(p, "wb") as f:
            f.truncate(HUGE_BYTES)
    return p


def run_case(case, binary, work, idx, timeout, memory, setpriv):
    d = work / f"case{idx}"
    if d.exists():
        subprocess.run(["chmod", "-R", "u+rwx", str(d)])
        shutil.rmtree(d)
    d.mkdir()
    d.chmod(0o777)
    x = make_kind(case.kind, None, case.make, d) if case.make else None
    sub = lambda s: s.replace("{D}", str(d)).replace("{X}", str(x) if x else "")
    argv = [str(binary)] + [sub(a) for a in case.argv]
    env = dict(os.environ)
    for k, v in case.env.items():
        if v is None:
            env.pop(k, None)
        else:
            env[k] = sub(v)
    cwd = d
    if case.cwd_poison:  # the current folder holds a broken .config/mixpilot/input.toml
        (d / ".config" / "mixpilot").mkdir(parents=True)
        (d / ".config" / "mixpilot" / "input.toml").write_text("mode = 9\n")
    if case.kind == "unreadable" and os.geteuid() == 0:
        argv = [setpriv, "--reuid=65534", "--regid=65534", "--clear-groups"] + argv
    try:
        p = subprocess.run(argv, capture_output=True, timeout=timeout, cwd=cwd, env=env,
                           preexec_fn=limit_memory(memory))
    except subprocess.TimeoutExpired:
        return "hang", ""
    out = p.stdout.decode("utf-8", "replace")
    err = p.stderr.decode("utf-8", "replace").strip()
    first = err.split("\n")[0][:200] if err else ""
    if p.returncode < 0 or p.returncode >= 128:
        return "crash", err[-400:]
    if "\x1b" in out or "\x1b" in err:
        return "nonsense", "an escape character reached the terminal"
    if case.cwd_poison and ("value outside [1, 4], got 9" in err or str(d / ".config") in err):
        return "nonsense", f"the current folder's .config was read: {first!r}"
    needle = sub(case.needle) if case.needle else None
    if case.expect == "usage":
        if p.returncode == 2 and case.needle in err:
            return "clean error", first
        return "nonsense", f"exit {p.returncode}, not a usage error naming {case.needle}: {first!r}"
    if p.returncode == 0:
        if case.expect in ("refused", "toml"):
            return "nonsense", f"accepted ({case.kind})"
        if case.expect == "config_toml" and not LOCATED.search(err):
            return "nonsense", "accepted without saying where the config file is broken"
        if case.expect == "config" and needle not in err:
            return "nonsense", f"accepted a {case.kind} config file without a word"
        return "accepted", ""
    if p.returncode not in (1, 2, 3) or not err:
        return "nonsense", f"exit {p.returncode} with message {err[:200]!r}"
    if case.expect in ("toml", "config_toml"):
        if not LOCATED.search(err):
            return "nonsense", f"a TOML error that does not point into the text: {first!r}"
        return "clean error", first
    if case.expect == "any":
        return "clean error", first
    if needle and needle not in err and os.path.basename(needle) not in err:
        return "nonsense", f"an error that does not name {os.path.basename(needle)}: {first!r}"
    return "clean error", first


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--mixpilot", default="build/release/app/mixpilot")
    ap.add_argument("--scenarios", default="scenarios")
    ap.add_argument("--timeout", type=float, default=30)
    ap.add_argument("--memory-gb", type=float, default=4,
                    help="address-space limit per run; 0: none (ASan builds reserve terabytes)")
    ap.add_argument("--sample", type=int, default=0, help="run only K random cases")
    ap.add_argument("--only", default="", help="run only the cases whose label holds this text")
    ap.add_argument("--seed", type=int, default=12)
    ap.add_argument("--verbose", action="store_true", help="print every run's class")
    args = ap.parse_args()

    binary = Path(args.mixpilot).resolve()
    scen_dir = Path(args.scenarios).resolve()
    memory = int(args.memory_gb * (1 << 30))
    setpriv = shutil.which("setpriv")
    work = Path(tempfile.mkdtemp(prefix="mutate_inputs."))
    work.chmod(0o755)  # the unreadable kind runs as user nobody
    base = work / "base"
    base.mkdir()
    base.chmod(0o755)
    # The scenarios are read from a copy in the work folder: the unreadable kind runs as user
    # nobody, who may not reach the source tree (a clone in a mode-700 temporary folder).
    shutil.copytree(scen_dir, work / "scenarios")
    scen_dir = work / "scenarios"
    subprocess.run(["chmod", "-R", "a+rX", str(scen_dir)])
    p = subprocess.run([str(binary), "fly", "--scenario", str(scen_dir / "mi_helix.toml"),
                        "--pilot", "novice", "--headless", "--duration", "0.3", "--record",
                        str(base / "rec.mcap")], capture_output=True, text=True, timeout=120)
    if p.returncode != 0:
        print(f"cannot record the base flight: {p.stderr.strip()}")
        return 1
    p = subprocess.run([str(binary), "gamepad-script", str(base / "rec.mcap"), "-o",
                        str(base / "script.csv")], capture_output=True, text=True, timeout=60,
                       env=dict(os.environ, XDG_CONFIG_HOME=str(base / "nocfg")))
    if p.returncode != 0:
        print(f"cannot make the base script: {p.stderr.strip()}")
        return 1
    for f in base.iterdir():
        f.chmod(0o644)
    cases = [c for c in build_cases(base, binary, scen_dir, setpriv) if args.only in c.label]
    total = len(cases)
    if args.sample and args.sample < len(cases):
        cases = random.Random(args.seed).sample(cases, args.sample)
    tally = Tally(args.verbose)
    for i, case in enumerate(cases):
        kind, why = run_case(case, binary, work, i % 2, args.timeout, memory, setpriv)
        tally.add(kind, case.label, why)
    if os.geteuid() == 0 and not setpriv:
        print("unreadable files: not tried (running as root, which reads mode-000 files, "
              "without setpriv to run as another user)")
    subprocess.run(["chmod", "-R", "u+rwx", str(work)])
    shutil.rmtree(work, ignore_errors=True)
    print(f"{len(cases)} of {total} cases")
    return tally.report()


if __name__ == "__main__":
    sys.exit(main())
