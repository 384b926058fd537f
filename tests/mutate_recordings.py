#!/usr/bin/env python3
"""Mutation run over recordings (docs/recording-format.md).

It records a short headless flight of each shipped scenario (`mixpilot fly --record`), and one of
mi_helix with an instructor's commands of each recorded kind (`--commands`), makes a
second copy of each with its CRCs zeroed ("not computed" in the MCAP spec, so mutations reach
the structure checks and the CDR decoders instead of stopping at a CRC), and writes variants of
every record, top-level and inside chunks: cut at its start, after its opcode, after its header
and half-way; its length 0, one less, one more, huge; its opcode unknown or another record's;
its content zeroed or all 0xff; the record dropped or repeated; plus seeded random byte flips
and 8-byte overwrites with boundary values. Each variant goes through `mixpilot score` (read,
replay, check) and `mixpilot recover` under a timeout and a memory limit, classified as:

  clean error  exit 1 or 3 with a message naming the file (and a byte offset for a read error)
  accepted     exit 0, and the JSON report holds only finite numbers (recover: and `score`
               reads the recording it wrote)
  crash        a signal, abort or exit >= 128
  hang         the timeout was reached
  nonsense     exit 0 with inf/nan in the report, a recovered file `score` refuses, or an error
               exit without a proper message

Prints `tried / clean error / accepted / crash / hang / nonsense`; exits 1 if any run crashed,
hung or gave nonsense. --sample K runs a seeded random sample of K variants (the CTest).
"""
import argparse
import random
import resource
import shutil
import struct
import subprocess
import sys
import tempfile
from pathlib import Path

from mutate_scenarios import Tally, finite_json, limit_memory

MAGIC = b"\x89MCAP0\r\n"
CHUNK, DATA_END, FOOTER = 0x06, 0x0F, 0x02
OPCODES = [0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08, 0x09, 0x0A, 0x0B, 0x0C, 0x0D, 0x0E,
           0x0F]
BOUNDARY_U64 = [0, 1, 0x7FFFFFFF, 0xFFFFFFFF, 1 << 32, (1 << 63) - 1, (1 << 64) - 1]
# Commands within the base recordings' first three steps (15 ms each).
COMMANDS = """
[[command]]
at = 0.0
kind = "bounds"
floor = 0.1
ceiling = 0.3

[[command]]
at = 0.015
kind = "gust"
force = [2.0, -1.0, 0.5]
duration = 0.5

[[command]]
at = 0.015
kind = "marker"
text = "mutate me"

[[command]]
at = 0.03
kind = "extra_delay"
delay = 0.03

[[command]]
at = 0.03
kind = "input_loss"
duration = 0.2
"""


def records(data, start, end):
    """(offset, opcode, content offset, content length) of the records in data[start:end]."""
    out = []
    at = start
    while at + 9 <= end:
        op = data[at]
        (length,) = struct.unpack_from("<Q", data, at + 1)
        if at + 9 + length > end:
            break
        out.append((at, op, at + 9, length))
        at += 9 + length
    return out


def chunk_records(data, rec):
    """(offset, length) bounds of the records section inside a Chunk record."""
    _, _, c, _ = rec
    p = c + 8 + 8 + 8 + 4
    (n,) = struct.unpack_from("<I", data, p)
    p += 4 + n
    (size,) = struct.unpack_from("<Q", data, p)
    return p + 8, size


def zero_crcs(data):
    """The recording with the chunk, data-section and summary CRCs set to 0 ("not computed")."""
    b = bytearray(data)
    for rec in records(b, len(MAGIC), len(b) - len(MAGIC)):
        at, op, c, _ = rec
        if op == CHUNK:
            struct.pack_into("<I", b, c + 24, 0)
        elif op == DATA_END:
            struct.pack_into("<I", b, c, 0)
        elif op == FOOTER:
            struct.pack_into("<I", b, c + 16, 0)
    return bytes(b)


def record_variants(data, rec, where):
    """(label, bytes) variants of one record at rec in data."""
    at, op, c, length = rec
    end = c + length
    b = bytes(data)

    def with_length(n):
        m = bytearray(b)
        struct.pack_into("<Q", m, at + 1, n % (1 << 64))
        return bytes(m)

    def with_opcode(o):
        m = bytearray(b)
        m[at] = o
        return bytes(m)

    def filled(x):
        return b[:c] + bytes([x]) * length + b[end:]

    out = [(f"{where}:cut_at_start", b[:at]), (f"{where}:cut_after_opcode", b[:at + 1]),
           (f"{where}:cut_after_header", b[:c]), (f"{where}:cut_half", b[:c + length // 2]),
           (f"{where}:length_0", with_length(0)), (f"{where}:length_minus_1", with_length(length - 1)),
           (f"{where}:length_plus_1", with_length(length + 1)),
           (f"{where}:length_huge", with_length((1 << 63) + 5)),
           (f"{where}:opcode_unknown", with_opcode(0x7F)),
           (f"{where}:opcode_other", with_opcode(OPCODES[(OPCODES.index(op) + 4) % len(OPCODES)]
                                                if op in OPCODES else 0x05)),
           (f"{where}:zeroed", filled(0)), (f"{where}:all_ff", filled(0xFF)),
           (f"{where}:dropped", b[:at] + b[end:]), (f"{where}:repeated", b[:end] + b[at:])]
    return out


def variants(data, name, rng, flips):
    out = []
    top = records(data, len(MAGIC), len(data) - len(MAGIC))
    for rec in top:
        out += record_variants(data, rec, f"{name}@{rec[0]}(0x{rec[1]:02x})")
        if rec[1] == CHUNK:
            start, size = chunk_records(data, rec)
            for inner in records(data, start, start + size):
                out += record_variants(data, inner,
                                       f"{name}@{rec[0]}/{inner[0]}(0x{inner[1]:02x})")
    out += [(f"{name}:empty", b""), (f"{name}:magic_only", MAGIC),
            (f"{name}:no_trailing_magic", data[:-len(MAGIC)])]
    for k in range(flips):
        m = bytearray(data)
        at = rng.randrange(len(m))
        if k % 2 == 0:
            m[at] ^= 1 << rng.randrange(8)
            out.append((f"{name}:flip@{at}", bytes(m)))
        else:
            at = min(at, len(m) - 8)
            v = rng.choice(BOUNDARY_U64)
            struct.pack_into("<Q", m, at, v)
            out.append((f"{name}:u64={v}@{at}", bytes(m)))
    return out


def run(cmd, timeout, memory, path, report=None):
    """Class and reason of one run of a command reading the variant at `path`."""
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, errors="replace",
                           timeout=timeout, preexec_fn=limit_memory(memory))
    except subprocess.TimeoutExpired:
        return "hang", ""
    err = (p.stderr or "").strip()
    if p.returncode < 0 or p.returncode >= 128:
        return "crash", err[-400:]
    if p.returncode == 0:
        if report is None or finite_json(report):
            return "accepted", ""
        return "nonsense", "non-finite report"
    if p.returncode in (1, 3) and str(path) in err:
        return "clean error", err.split("\n")[-1]
    return "nonsense", f"exit {p.returncode} with message {err[-200:]!r}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--mixpilot", default="build/release/app/mixpilot")
    ap.add_argument("--scenarios", default="scenarios")
    ap.add_argument("--duration", type=float, default=0.045,
                    help="seconds flown for each base recording (default: 0.045)")
    ap.add_argument("--flips", type=int, default=200, help="random mutations per base recording")
    ap.add_argument("--timeout", type=float, default=20)
    ap.add_argument("--memory-gb", type=float, default=4,
                    help="address-space limit per run; 0: none (ASan builds reserve terabytes)")
    ap.add_argument("--sample", type=int, default=0, help="run only K random variants")
    ap.add_argument("--seed", type=int, default=12)
    ap.add_argument("--verbose", action="store_true", help="print every run's class")
    args = ap.parse_args()

    binary = Path(args.mixpilot).resolve()
    memory = int(args.memory_gb * (1 << 30))
    work = Path(tempfile.mkdtemp(prefix="mutate_recordings."))
    rng = random.Random(args.seed)
    cases = []
    for f in sorted(Path(args.scenarios).resolve().glob("*.toml")):
        rec = work / f"{f.stem}.mcap"
        p = subprocess.run([str(binary), "fly", "--scenario", str(f), "--headless", "--duration",
                            str(args.duration), "--record", str(rec)], capture_output=True,
                           text=True, timeout=120)
        if p.returncode != 0:
            print(f"{f.name} does not record: {p.stderr.strip()}")
            return 1
        data = rec.read_bytes()
        cases += variants(data, f.stem, rng, args.flips)
        cases += variants(zero_crcs(data), f"{f.stem}_nocrc", rng, args.flips)
    # A flight with an instructor's commands of every recorded kind (/instructor/command,
    # docs/recording-format.md), so mutations reach that topic's decoder and checks too.
    script = work / "commands.toml"
    script.write_text(COMMANDS)
    helix = Path(args.scenarios).resolve() / "mi_helix.toml"
    rec = work / "mi_helix_commands.mcap"
    p = subprocess.run([str(binary), "fly", "--scenario", str(helix), "--headless", "--duration",
                        str(args.duration), "--commands", str(script), "--record", str(rec)],
                       capture_output=True, text=True, timeout=120)
    if p.returncode != 0:
        print(f"mi_helix.toml with --commands does not record: {p.stderr.strip()}")
        return 1
    data = rec.read_bytes()
    cases += variants(data, "mi_helix_commands", rng, args.flips)
    cases += variants(zero_crcs(data), "mi_helix_commands_nocrc", rng, args.flips)
    if args.sample and args.sample < len(cases):
        cases = random.Random(args.seed).sample(cases, args.sample)

    tally = Tally(args.verbose)
    path = work / "variant.mcap"
    report = work / "report.json"
    recovered = work / "recovered.mcap"
    for label, data in cases:
        path.write_bytes(data)
        for cmd_name, cmd, rep in (
                ("score", [str(binary), "score", str(path), "--jobs", "1", "--json", str(report),
                           "--force"], report),
                ("recover", [str(binary), "recover", str(path), "-o", str(recovered), "--force"],
                 None)):
            for stale in (report, recovered):
                stale.unlink(missing_ok=True)
            kind, why = run(cmd, args.timeout, memory, path, rep)
            if cmd_name == "recover" and kind == "accepted":
                # What recover writes is a recording: `score` reads and replays it.
                p = subprocess.run([str(binary), "score", str(recovered), "--jobs", "1"],
                                   capture_output=True, text=True, errors="replace",
                                   timeout=args.timeout, preexec_fn=limit_memory(memory))
                if p.returncode not in (0, 3):
                    kind, why = "nonsense", ("recover wrote a file score refuses: " +
                                             p.stderr.strip().split("\n")[-1][:200])
            tally.add(kind, f"{cmd_name} {label}", why)
    shutil.rmtree(work, ignore_errors=True)
    return tally.report()


if __name__ == "__main__":
    sys.exit(main())
