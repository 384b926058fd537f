#!/usr/bin/env python3
"""Mutation run over the shipped lessons (docs/lesson-format.md).

For every key and table of every scenarios/lessons/*.toml it writes the variants the scenario
mutations write (tests/mutate_scenarios.py: the key missing, a wrong type, 0, negative, tiny,
huge, nan, +-inf, integer limits, an empty or unknown string; a table missing), plus nesting
deeper than any lesson needs and steps given twice, and reads each with `mixpilot lesson FILE
--check` under a timeout and a memory limit. Each run is classified:

  clean error  exit 1 with a message that points into the file (`file:line:col: key: ...`)
  accepted     exit 0 and the steps printed
  crash        a signal, abort or exit >= 128
  hang         the timeout was reached
  nonsense     exit 0 without the steps, an error that does not point into the file, or another
               exit status

Prints `tried / clean error / accepted / crash / hang / nonsense`; exits 1 if any run crashed,
hung or gave nonsense. --sample K reads a seeded random sample of K variants.
"""
import argparse
import random
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from mutate_scenarios import LOCATED, Tally, limit_memory, variants


def extra_variants(text):
    """Nesting and repetition the key-by-key variants do not make."""
    return [
        ("nested_33", text + "\n" + "a." * 33 + "b = 1\n"),
        ("nested_array_50000", text + "\nx = " + "[" * 50000 + "\n"),
        ("steps_twice", text + "\nsteps = 1\n"),
        ("steps_inline", text.replace("[[steps]]", "[[steps]]\npass = {}", 1)),
        ("binary", text + "\n\x00\x01\xff"),
    ]


def check(binary, path, timeout, memory):
    try:
        p = subprocess.run([str(binary), "lesson", str(path), "--check"], capture_output=True,
                           text=True, errors="replace", timeout=timeout,
                           preexec_fn=limit_memory(memory), cwd=path.parent)
    except subprocess.TimeoutExpired:
        return "hang", ""
    err = (p.stderr or "").strip()
    if p.returncode < 0 or p.returncode >= 128:
        return "crash", err[-400:]
    if p.returncode == 0:
        if " 1. " in p.stdout:
            return "accepted", ""
        return "nonsense", f"exit 0 without the steps: {p.stdout[:200]!r}"
    if p.returncode == 1 and err:
        if not LOCATED.search(err):
            return "nonsense", f"an error that does not point into the file: {err[:200]!r}"
        return "clean error", err.split("\n")[0]
    return "nonsense", f"exit {p.returncode} with message {err[:200]!r}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--mixpilot", default="build/release/app/mixpilot")
    ap.add_argument("--lessons", default="scenarios/lessons")
    ap.add_argument("--timeout", type=float, default=20)
    ap.add_argument("--memory-gb", type=float, default=4,
                    help="address-space limit per run; 0: none (ASan builds reserve terabytes)")
    ap.add_argument("--sample", type=int, default=0, help="read only K random variants")
    ap.add_argument("--seed", type=int, default=12)
    ap.add_argument("--verbose", action="store_true", help="print every run's class")
    args = ap.parse_args()

    binary = Path(args.mixpilot).resolve()
    work = Path(tempfile.mkdtemp(prefix="mutate_lessons."))
    cases = []
    for f in sorted(Path(args.lessons).resolve().glob("*.toml")):
        text = f.read_text()
        for label, mutated in variants(text) + extra_variants(text):
            cases.append((f.stem, label, mutated))
    if args.sample and args.sample < len(cases):
        cases = random.Random(args.seed).sample(cases, args.sample)
    memory = int(args.memory_gb * (1 << 30))
    tally = Tally(args.verbose)
    # The unmutated lessons read.
    for f in sorted(Path(args.lessons).resolve().glob("*.toml")):
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
