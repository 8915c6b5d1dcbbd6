#!/usr/bin/env python3
"""Per-run overhead of `pathex trace`: start-up to exit, excluding rendering (issue 19).

    python3 bench/overhead.py build/pathex [OLD/pathex] --resolution 256x256 --spp 1 --rounds 15

Runs `pathex trace [SCENE] --resolution R --spp N --threads T --quiet --json --out DIR` (T: --threads,
default 1; 0 runs without the option, on every core as a user's default run does) with the default outputs (histogram.json, classes.exr, the PNGs), binaries interleaved, ROUNDS times. The
render's own time is the JSON's `time_s` (wall clock) and, where the binary reports it,
`efficiency.cpu_s` (CPU seconds); the process's come from os.wait4 and the wall clock around it.
Overhead = process - render, as CPU seconds (what the shared host cannot steal) and wall seconds
(which also holds file-system waits, but on a busy host also other processes' time). Prints the
median and range over rounds of each, and the CPU of a bare `pathex --version` (the process start:
loading and relocating the linked libraries), the part of the overhead no output setting changes.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time


def run(cmd, out_dir):
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    out = proc.stdout.read()
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    err = proc.stderr.read().decode()
    if os.waitstatus_to_exitcode(status) != 0:
        sys.exit(f"{' '.join(cmd)} failed: {err}")
    doc = json.loads(out)
    # The render's own times: run.json beside the outputs (older binaries: the --json output).
    run_json = os.path.join(out_dir, "run.json")
    if os.path.exists(run_json):
        with open(run_json) as f:
            doc = json.load(f)
        os.remove(run_json)
    render_cpu = doc.get("cpu_s", doc.get("efficiency", {}).get("cpu_s"))
    return usage.ru_utime + usage.ru_stime, wall, render_cpu, doc["time_s"]


def fmt(xs, scale=1000.0):
    return f"{statistics.median(xs) * scale:7.1f} ms [{min(xs) * scale:.1f}, {max(xs) * scale:.1f}]"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("binaries", nargs="+")
    ap.add_argument("--scene", default=None)
    ap.add_argument("--resolution", default="256x256")
    ap.add_argument("--spp", type=int, default=1)
    ap.add_argument("--rounds", type=int, default=15)
    ap.add_argument("--threads", type=int, default=1, help="--threads of the runs; 0: no --threads (every core)")
    ap.add_argument("--extra", default="", help="more trace arguments, e.g. '--renderer pt-nee'")
    args = ap.parse_args()
    res = {b: [] for b in args.binaries}
    with tempfile.TemporaryDirectory(prefix="pathex-overhead-") as work:
        for r in range(args.rounds):
            order = args.binaries[r % len(args.binaries):] + args.binaries[:r % len(args.binaries)]
            for i, b in enumerate(order):
                out_dir = os.path.join(work, f"out{args.binaries.index(b)}")
                cmd = ([b, "trace"] + ([args.scene] if args.scene else []) +
                       ["--resolution", args.resolution, "--spp", str(args.spp)] +
                       (["--threads", str(args.threads)] if args.threads > 0 else []) + ["--quiet", "--json", "--out", out_dir] + args.extra.split())
                res[b].append(run(cmd, out_dir))
    # The process start alone (dynamic loading of the linked libraries): a bare --version, as many times.
    start = {b: [] for b in args.binaries}
    for r in range(args.rounds):
        for b in args.binaries:
            proc = subprocess.Popen([b, "--version"], stdout=subprocess.DEVNULL)
            _, _, usage = os.wait4(proc.pid, 0)
            start[b].append(usage.ru_utime + usage.ru_stime)
    for b, rs in res.items():
        threads = f"{args.threads} thread(s)" if args.threads > 0 else "every core"
        print(f"{b}: {len(rs)} runs, {args.resolution}, {args.spp} spp, {threads}")
        print(f"  process CPU        {fmt([x[0] for x in rs])}")
        print(f"  process wall       {fmt([x[1] for x in rs])}")
        if all(x[2] is not None for x in rs):
            print(f"  overhead CPU       {fmt([x[0] - x[2] for x in rs])}   (process CPU - render CPU)")
        print(f"  overhead wall      {fmt([x[1] - x[3] for x in rs])}   (process wall - render wall)")
        print(f"  --version CPU      {fmt(start[b])}   (process start alone)")


if __name__ == "__main__":
    main()
