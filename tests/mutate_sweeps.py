#!/usr/bin/env python3
"""Mutation run over the shipped sweep files (docs/sweeps.md).

For every key and table of every scenarios/sweeps/*.toml it writes the variants the scenario
mutations write (tests/mutate_scenarios.py: the key missing, a wrong type, 0, negative, tiny,
huge, nan, +-inf, integer limits, an empty or unknown string, an array emptied or its first
element mutated; a table missing), for quoted keys ("plant.rtt" = [...]) too, plus what only a
sweep can get wrong: an unknown or malformed key path, a key the scenario does not have, a
scenario of another mode, a grid of 10 001 runs, a key given twice, nesting deeper than any
sweep needs, binary junk. Each is read with `mixpilot sweep FILE --check` (the plan expanded
and every run's scenario checked as its flight is set up; nothing flown) under a timeout and a
memory limit, and classified:

  clean error  exit 1 with a message that points into the file (`file:line:col: key: ...`)
  accepted     exit 0 and the plan printed (its plan_sha256)
  crash        a signal, abort or exit >= 128
  hang         the timeout was reached
  nonsense     exit 0 without the plan, an error that does not point into the file, or another
               exit status

Prints `tried / clean error / accepted / crash / hang / nonsense`; exits 1 if any run crashed,
hung or gave nonsense. --sample K reads a seeded random sample of K variants.
"""
import argparse
import random
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from mutate_scenarios import LOCATED, VALUES, Tally, limit_memory, split_value, variants

QUOTED = re.compile(r'^(\s*)("[^"]*")(\s*=\s*)(.*)$')


def quoted_variants(text):
    """The value mutations of variants(), for keys written in quotes ("plant.rtt" = [...])."""
    lines = text.split("\n")
    out = []
    for i, line in enumerate(lines):
        m = QUOTED.match(line)
        if not m:
            continue
        indent, key, eq, rest = m.groups()
        value, comment = split_value(rest)
        where = f"{key}@{i + 1}"

        def put(new_value, lines=lines, i=i, indent=indent, key=key, eq=eq, comment=comment):
            copy = list(lines)
            copy[i] = f"{indent}{key}{eq}{new_value} {comment}".rstrip()
            return "\n".join(copy)

        def rename(new_key, lines=lines, i=i, indent=indent, eq=eq, rest=rest):
            copy = list(lines)
            copy[i] = f"{indent}{new_key}{eq}{rest}"
            return "\n".join(copy)

        out.append((f"{where}:missing", "\n".join(lines[:i] + lines[i + 1:])))
        out.append((f"{where}:not_an_array", put("0.5")))
        out.append((f"{where}:empty_array", put("[]")))
        out.append((f"{where}:strings", put('["a", "b"]')))
        out.append((f"{where}:mixed", put('[1, "a", true]')))
        out.append((f"{where}:repeated", put("[1, 1]")))
        out.append((f"{where}:nested", put("[[1, 2], [3]]")))
        out.append((f"{where}:inline_table", put("[{a = 1}]")))
        items = [s.strip() for s in value.strip("[]").split(",") if s.strip()]
        for label, v in VALUES:
            out.append((f"{where}[0]:{label}", put("[" + ", ".join([v] + items[1:]) + "]")))
        for label, k in [("unknown_key", '"plant.no_such_key"'), ("unknown_table", '"nowhere.x"'),
                         ("through_a_value", key[:-1] + '.x"'), ("empty_key", '""'),
                         ("double_dot", '"plant..rtt"'), ("index", '"plant.start[7]"'),
                         ("bad_index", '"plant.start[x]"'), ("huge_index", '"plant.start[99999999999]"'),
                         ("a_table", '"controller"'), ("flight_option", '"assist"'),
                         ("floor", '"floor"'), ("control_chars", '"plant.\\u0001"')]:
            out.append((f"{where}:{label}", rename(k)))
        out.append((f"{where}:given_twice", "\n".join(lines[:i + 1] + [line] + lines[i + 1:])))
    return out


def extra_variants(text):
    """What the key-by-key variants do not make."""
    grid_of = "\n".join(f'"plant.p{i}" = [' + ", ".join(str(j) for j in range(11)) + "]"
                        for i in range(4))
    return [
        ("nested_33", text + "\n" + "a." * 33 + "b = 1\n"),
        ("nested_array_50000", text + "\nx = " + "[" * 50000 + "\n"),
        ("binary", text + "\n\x00\x01\xff"),
        ("scenario_pendubot", re.sub(r'^scenario = .*$', 'scenario = "pendubot_swingup"', text,
                                     flags=re.M)),
        ("scenario_mi", re.sub(r'^scenario = .*$', 'scenario = "mi_helix"', text, flags=re.M)),
        ("scenario_tracking", re.sub(r'^scenario = .*$', 'scenario = "tracking_helix"', text,
                                     flags=re.M)),
        ("scenario_path", re.sub(r'^scenario = .*$', 'scenario = "../../etc/passwd.toml"', text,
                                 flags=re.M)),
        ("scenario_self", re.sub(r'^scenario = .*$', 'scenario = "SELF"', text, flags=re.M)),
        ("too_many_runs", text + "\n[grid]\n" + grid_of + "\n"),
        ("set_and_grid", text + "\n[set]\n\"plant.rtt\" = 0.01\n"),
        ("runs_empty", text + "\n[[runs]]\n"),
        ("runs_entry", text + "\n[[runs]]\n\"controller.N\" = 20\n"),
        ("runs_not_tables", text + "\nruns = [1, 2]\n"),
        ("pilots_unknown", text + '\npilots = ["nobody"]\n'),
        ("seeds_huge", text + "\nseeds = [9223372036854775807, -1]\n"),
        ("duration_twice", text + "\nduration = 3\n[set]\nduration = 4\n"),
        ("floor_above_ceiling", text + "\n[set]\nfloor = 0.9\nceiling = 0.1\n"),
        ("record", text + "\nrecord = 1\n"),
        ("empty", ""),
    ]


def check(binary, path, timeout, memory):
    try:
        p = subprocess.run([str(binary), "sweep", str(path), "--check"], capture_output=True,
                           text=True, errors="replace", timeout=timeout,
                           preexec_fn=limit_memory(memory), cwd=path.parent)
    except subprocess.TimeoutExpired:
        return "hang", ""
    err = (p.stderr or "").strip()
    if p.returncode < 0 or p.returncode >= 128:
        return "crash", err[-400:]
    if p.returncode == 0:
        if "plan_sha256" in p.stdout:
            return "accepted", ""
        return "nonsense", f"exit 0 without the plan: {p.stdout[:200]!r}"
    if p.returncode == 1 and err:
        first = err.split("\n")[0]
        if not LOCATED.search(first):
            return "nonsense", f"an error that does not point into the file: {err[:300]!r}"
        return "clean error", first
    return "nonsense", f"exit {p.returncode} with message {err[:200]!r}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--mixpilot", default="build/release/app/mixpilot")
    ap.add_argument("--scenarios", default="scenarios")
    ap.add_argument("--timeout", type=float, default=20)
    ap.add_argument("--memory-gb", type=float, default=4,
                    help="address-space limit per run; 0: none (ASan builds reserve terabytes)")
    ap.add_argument("--sample", type=int, default=0, help="read only K random variants")
    ap.add_argument("--seed", type=int, default=12)
    ap.add_argument("--verbose", action="store_true", help="print every run's class")
    args = ap.parse_args()

    binary = Path(args.mixpilot).resolve()
    sweeps = sorted((Path(args.scenarios).resolve() / "sweeps").glob("*.toml"))
    if not sweeps:
        print(f"no sweep files in {args.scenarios}/sweeps")
        return 1
    work = Path(tempfile.mkdtemp(prefix="mutate_sweeps."))
    cases = []
    for f in sweeps:
        text = f.read_text()
        for label, mutated in variants(text) + quoted_variants(text) + extra_variants(text):
            cases.append((f.stem, label, mutated.replace('"SELF"', f'"{f.stem}.toml"')))
    if args.sample and args.sample < len(cases):
        cases = random.Random(args.seed).sample(cases, args.sample)
    memory = int(args.memory_gb * (1 << 30))
    tally = Tally(args.verbose)
    # The unmutated sweeps read (their scenarios are shipped names: the data folder's).
    for f in sweeps:
        path = work / f.name
        path.write_text(f.read_text())
        kind, why = check(binary, path, args.timeout, memory)
        if kind != "accepted":
            print(f"the unmutated {f.name} does not read: {kind}: {why}")
            return 1
    for stem, label, text in cases:
        path = work / f"{stem}.toml"
        path.write_bytes(text.encode("utf-8", "surrogateescape"))
        kind, why = check(binary, path, args.timeout, memory)
        tally.add(kind, f"{stem}: {label}", why)
    shutil.rmtree(work, ignore_errors=True)
    return tally.report()


if __name__ == "__main__":
    sys.exit(main())
