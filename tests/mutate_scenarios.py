#!/usr/bin/env python3
"""Mutation run over the shipped scenarios (docs/scenario-format.md, "Ranges").

For every key of every scenarios/*.toml (walked line by line, tables included) it writes
variants -- the key missing, a wrong type, 0, negative, tiny, huge, nan, +-inf, integer limits;
for an array, its first element mutated too -- and, for each reference CSV, variants of its
cells (the same values), rows, header and time grid; it flies each one headless for a short
time under a timeout and a memory limit. Each run is classified:

  clean error  exit 1 or 2 with a message that points into the file (`file:line:col: key: ...`;
               a reference CSV's error comes through the scenario key that names it)
  accepted     exit 0, and the JSON report holds only finite numbers
  crash        a signal, abort or exit >= 128
  hang         the timeout was reached
  nonsense     exit 0 with inf/nan in the report, or an error exit with no message

Prints `tried / clean error / accepted / crash / hang / nonsense`; exits 1 if any run crashed,
hung or gave nonsense. --sample K flies a seeded random sample of K variants (the CTest).
"""
import argparse
import json
import math
import os
import random
import re
import resource
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

VALUES = [
    ("zero", "0"),
    ("negative", "-1.5"),
    ("negative_int", "-1"),
    ("tiny", "1e-300"),
    ("huge", "1e300"),
    ("nan", "nan"),
    ("inf", "inf"),
    ("-inf", "-inf"),
    ("int_max", "2147483647"),
    ("int_min", "-2147483648"),
    ("int64_max", "9223372036854775807"),
]
HEADER = re.compile(r"^\s*(\[\[?)\s*([^\]]+?)\s*\]\]?")
KEYVAL = re.compile(r"^(\s*)([A-Za-z0-9_\-]+)(\s*=\s*)(.*)$")
LOCATED = re.compile(r":\d+:\d+: (?:TOML syntax|\S+): ")  # file:line:col: key path:


def split_value(rest):
    """Value text and trailing comment of `rest` (the text after `key =`)."""
    depth, quote = 0, False
    for i, ch in enumerate(rest):
        if ch == '"':
            quote = not quote
        elif not quote and ch == "[":
            depth += 1
        elif not quote and ch == "]":
            depth -= 1
        elif not quote and depth == 0 and ch == "#":
            return rest[:i].rstrip(), rest[i:]
    return rest.rstrip(), ""


def variants(text):
    """(label, mutated text) for every key and table of one scenario."""
    lines = text.split("\n")
    table = ""
    out = []
    # Whole tables missing: a header line and its body up to the next header.
    headers = [i for i, l in enumerate(lines) if HEADER.match(l)]
    for n, i in enumerate(headers):
        end = headers[n + 1] if n + 1 < len(headers) else len(lines)
        name = HEADER.match(lines[i]).group(2)
        out.append((f"[{name}]#{i + 1}:missing", "\n".join(lines[:i] + lines[end:])))
    for i, line in enumerate(lines):
        h = HEADER.match(line)
        if h:
            table = h.group(2)
            continue
        m = KEYVAL.match(line)
        if not m or line.lstrip().startswith("#"):
            continue
        indent, key, eq, rest = m.groups()
        value, comment = split_value(rest)
        path = f"{table}.{key}" if table else key
        where = f"{path}@{i + 1}"

        def put(new_value, lines=lines, i=i):
            copy = list(lines)
            copy[i] = f"{indent}{key}{eq}{new_value} {comment}".rstrip()
            return "\n".join(copy)

        out.append((f"{where}:missing", "\n".join(lines[:i] + lines[i + 1:])))
        if value.startswith('"'):
            out.append((f"{where}:wrong_type", put("1")))
            out.append((f"{where}:empty_string", put('""')))
            out.append((f"{where}:other_string", put('"no such thing"')))
            continue
        out.append((f"{where}:wrong_type", put('"text"')))
        if value in ("true", "false"):
            out.append((f"{where}:int", put("1")))
            continue
        if value.startswith("["):
            items = [s.strip() for s in value.strip("[]").split(",") if s.strip()]
            out.append((f"{where}:empty_array", put("[]")))
            out.append((f"{where}:longer_array", put("[" + ", ".join(items + ["1.0"]) + "]")))
            for label, v in VALUES:
                out.append((f"{where}[0]:{label}", put("[" + ", ".join([v] + items[1:]) + "]")))
            continue
        for label, v in VALUES:
            out.append((f"{where}:{label}", put(v)))
    return out


CSV_REF = re.compile(r'^\s*(?:file|reference)\s*=\s*"references/([^"]+)"', re.M)


def csv_variants(csv):
    """(label, mutated text) of one reference CSV: cells, rows, header, time grid."""
    lines = csv.rstrip("\n").split("\n")
    out = [("empty", ""), ("header_only", lines[0] + "\n"),
           ("no_header", "\n".join(lines[1:]) + "\n"),
           ("row_dropped", "\n".join(lines[:3] + lines[4:]) + "\n"),
           ("time_repeated", "\n".join(lines[:3] + [lines[2]] + lines[3:]) + "\n"),
           ("extra_column", "\n".join(l + ",1" for l in lines) + "\n"),
           ("last_row_dropped", "\n".join(lines[:-1]) + "\n")]
    ncols = len(lines[0].split(","))
    for col in (0, 1, ncols - 1):
        for label, v in VALUES + [("text", "x")]:
            copy = list(lines)
            cells = copy[2].split(",")
            cells[col] = v
            copy[2] = ",".join(cells)
            out.append((f"row2.col{col}:{label}", "\n".join(copy) + "\n"))
    return out


def limit_memory(limit_bytes):
    def apply():
        if limit_bytes > 0:
            resource.setrlimit(resource.RLIMIT_AS, (limit_bytes, limit_bytes))
    return apply


def null_keys(path):
    """Keys of the report whose value is null (the report's spelling of a non-finite value)."""
    try:
        data = json.loads(Path(path).read_text())
    except (OSError, ValueError):
        return set()
    return {k for k, v in data.items() if v is None} if isinstance(data, dict) else set()


def finite_json(path, allowed_nulls=frozenset()):
    """True when the report parses, every number in it is finite, and no value is null but
    those null in the unmutated scenario's report (e.g. no obstacle ever near)."""
    if null_keys(path) - allowed_nulls:
        return False
    try:
        text = Path(path).read_text()
    except OSError:
        return False
    if re.search(r"\b(nan|inf|NaN|Infinity)\b", text):
        return False
    try:
        data = json.loads(text)
    except ValueError:
        return False

    def walk(v):
        if isinstance(v, dict):
            return all(walk(x) for x in v.values())
        if isinstance(v, list):
            return all(walk(x) for x in v)
        if isinstance(v, float):
            return math.isfinite(v) and abs(v) < 1e100
        return True
    return walk(data)


def fly(binary, scenario, workdir, duration, timeout, memory, allowed_nulls=frozenset(),
        located=True):
    report = workdir / "report.json"
    if report.exists():
        report.unlink()
    cmd = [str(binary), "fly", "--scenario", str(scenario), "--headless",
           "--duration", str(duration), "--report", str(report)]
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, errors="replace",
                           timeout=timeout, preexec_fn=limit_memory(memory), cwd=workdir)
    except subprocess.TimeoutExpired:
        return "hang", ""
    err = (p.stderr or "").strip()
    if p.returncode < 0 or p.returncode >= 128:
        return "crash", err[-400:]
    if p.returncode == 0:
        if finite_json(report, allowed_nulls):
            return "accepted", ""
        return "nonsense", f"non-finite report (null: {sorted(null_keys(report))})"
    if p.returncode in (1, 2, 3) and err:
        if located and not LOCATED.search(err):
            return "nonsense", f"an error that does not point into the file: {err[:200]!r}"
        return "clean error", err.split("\n")[0]
    return "nonsense", f"exit {p.returncode} with message {err[:200]!r}"


class Tally:
    """Counts of each class of run; the bad ones listed; the summary line of a mutation run."""

    KINDS = ("clean error", "accepted", "crash", "hang", "nonsense")

    def __init__(self, verbose=False):
        self.counts = {k: 0 for k in self.KINDS}
        self.bad = []
        self.verbose = verbose

    def add(self, kind, label, why):
        self.counts[kind] += 1
        if self.verbose:
            print(f"{kind:12s} {label}: {why}")
        if kind in ("crash", "hang", "nonsense"):
            self.bad.append(f"{kind}: {label}: {why}")

    def report(self):
        """Prints the bad runs and the counts; the exit status (1 if any run was bad)."""
        for b in self.bad:
            print(b)
        c = self.counts
        print(f"tried {sum(c.values())} / clean error {c['clean error']} / accepted "
              f"{c['accepted']} / crash {c['crash']} / hang {c['hang']} / nonsense "
              f"{c['nonsense']}")
        return 1 if self.bad else 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--mixpilot", default="build/release/app/mixpilot")
    ap.add_argument("--scenarios", default="scenarios")
    ap.add_argument("--duration", type=float, default=0.3)
    ap.add_argument("--timeout", type=float, default=20)
    ap.add_argument("--memory-gb", type=float, default=4,
                    help="address-space limit per run; 0: none (ASan builds reserve terabytes)")
    ap.add_argument("--sample", type=int, default=0, help="fly only K random variants")
    ap.add_argument("--seed", type=int, default=12)
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--verbose", action="store_true", help="print every run's class")
    args = ap.parse_args()

    binary = Path(args.mixpilot).resolve()
    scen_dir = Path(args.scenarios).resolve()
    work = Path(tempfile.mkdtemp(prefix="mutate_scenarios."))
    cases = []
    seen_csv = set()
    for f in sorted(scen_dir.glob("*.toml")):
        text = f.read_text()
        for label, mutated in variants(text):
            cases.append((f.stem, label, mutated, None))
        for name in CSV_REF.findall(text):
            if name in seen_csv:
                continue
            seen_csv.add(name)
            for label, csv in csv_variants((scen_dir / "references" / name).read_text()):
                cases.append((f.stem, f"references/{name}:{label}", text, (name, csv)))
    # Nulls the unmutated scenarios' reports have (a metric with nothing to measure).
    baseline_nulls = {}
    for f in sorted(scen_dir.glob("*.toml")):
        d = work / "baseline"
        d.mkdir(exist_ok=True)
        if not (d / "references").exists():
            (d / "references").symlink_to(scen_dir / "references")
        (d / f.name).write_text(f.read_text())
        kind, why = fly(binary, d / f.name, d, args.duration, args.timeout,
                        int(args.memory_gb * (1 << 30)))
        if kind not in ("accepted", "nonsense"):
            print(f"the unmutated {f.name} does not fly: {kind}: {why}")
            return 1
        baseline_nulls[f.stem] = frozenset(null_keys(d / "report.json"))
    if args.sample and args.sample < len(cases):
        cases = random.Random(args.seed).sample(cases, args.sample)

    def run(idx_case):
        idx, (stem, label, text, csv) = idx_case
        d = work / f"run{idx % max(1, args.jobs)}"
        d.mkdir(exist_ok=True)
        refs = d / "references"
        if refs.is_symlink():
            refs.unlink()
        elif refs.exists():
            shutil.rmtree(refs)
        if csv is None:
            refs.symlink_to(scen_dir / "references")
        else:  # the other reference files as they are, the mutated one written
            refs.mkdir()
            for other in (scen_dir / "references").iterdir():
                if other.name != csv[0]:
                    (refs / other.name).symlink_to(other)
            (refs / csv[0]).write_text(csv[1])
        path = d / f"{stem}.toml"
        path.write_text(text)
        return stem, label, fly(binary, path, d, args.duration, args.timeout,
                                int(args.memory_gb * (1 << 30)), baseline_nulls[stem])

    if args.jobs > 1:
        # One worker directory per job slot: runs in a slot are sequential.
        from concurrent.futures import ThreadPoolExecutor
        slots = [[(i, c) for i, c in enumerate(cases) if i % args.jobs == j]
                 for j in range(args.jobs)]
        with ThreadPoolExecutor(args.jobs) as ex:
            results = [r for rs in ex.map(lambda s: [run(c) for c in s], slots) for r in rs]
    else:
        results = [run(c) for c in enumerate(cases)]
    tally = Tally(args.verbose)
    for stem, label, (kind, why) in results:
        tally.add(kind, f"{stem}: {label}", why)
    shutil.rmtree(work, ignore_errors=True)
    return tally.report()


if __name__ == "__main__":
    sys.exit(main())
