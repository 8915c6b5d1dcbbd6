#!/usr/bin/env python3
"""Interleaved A/B timing of two pathex binaries (e.g. a commit against its parent).

Runs `pathex trace SCENE --renderer R --spp N --threads 1 --no-images --quiet --json` with each
binary in turn, ROUNDS times, alternating which goes first, and measures each process's CPU time
(user + system, from os.wait4), so that time the shared host gives to other work is not counted.
Prints samples per CPU-second for each side and the median of the per-round ratios B / A (above
1: B is faster).

    python3 bench/cli_ab.py OLD/pathex build/pathex --renderer pt-nee --spp 32 --rounds 9
"""
import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile


def cpu_run(cmd, cwd=None):
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, cwd=cwd)
    _, status, usage = os.wait4(proc.pid, 0)
    err = proc.stderr.read().decode()
    proc.stderr.close()
    if os.waitstatus_to_exitcode(status) != 0:
        sys.exit(f"{' '.join(cmd)} failed: {err}")
    return usage.ru_utime + usage.ru_stime


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("a", help="binary A (the baseline)")
    ap.add_argument("b", help="binary B (the change)")
    ap.add_argument("--scene", default=None, help="scene file (default: the embedded Cornell box)")
    ap.add_argument("--renderer", default="bdpt")
    ap.add_argument("--spp", type=int, default=32)
    ap.add_argument("--rounds", type=int, default=9)
    ap.add_argument("--b-arg", action="append", default=[],
                    help="an extra argument for binary B only (repeatable), e.g. --b-arg=--sampler --b-arg=independent "
                         "when A predates the option and its default")
    ap.add_argument("--a-arg", action="append", default=[],
                    help="an extra argument for binary A only (repeatable), e.g. to compare two samplers or two builds "
                         "with the same non-default option")
    args = ap.parse_args()
    tail = (["trace"] + ([os.path.abspath(args.scene)] if args.scene else []) +
            ["--renderer", args.renderer, "--spp", str(args.spp), "--threads", "1", "--no-images", "--quiet", "--json"])
    samples = 64 * 64 * args.spp if args.scene is None else None
    # Each binary writes its outputs (pathex-out/) in a folder of its own: pathex refuses to replace
    # outputs another version wrote.
    work = tempfile.mkdtemp(prefix="cli_ab-")
    dirs = {name: os.path.join(work, name) for name in ("a", "b")}
    for d in dirs.values():
        os.mkdir(d)
    ratios, ta, tb = [], [], []
    for r in range(args.rounds):
        order = [("a", args.a), ("b", args.b)] if r % 2 == 0 else [("b", args.b), ("a", args.a)]
        t = {}
        for name, binary in order:
            t[name] = cpu_run([os.path.abspath(binary)] + tail + (args.b_arg if name == "b" else args.a_arg), dirs[name])
        ta.append(t["a"])
        tb.append(t["b"])
        ratios.append(t["a"] / t["b"])
    shutil.rmtree(work)
    med_a, med_b = statistics.median(ta), statistics.median(tb)
    rate = (lambda t: f"{samples / t / 1e6:.3f} M samples/CPU-s") if samples else (lambda t: f"{t:.3f} CPU-s")
    print(f"{args.renderer}, {args.spp} spp, {args.rounds} interleaved rounds")
    print(f"  A {args.a}: median {rate(med_a)}")
    print(f"  B {args.b}: median {rate(med_b)}")
    print(f"  speed B / A: median {statistics.median(ratios):.4f} (rounds: {' '.join(f'{x:.3f}' for x in ratios)})")


if __name__ == "__main__":
    main()
