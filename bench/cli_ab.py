#!/usr/bin/env python3
"""Interleaved A/B timing of two pathex binaries (e.g. a commit against its parent).

Runs `pathex trace SCENE --renderer R --spp N --threads 1 --no-images --quiet --json` with each
binary in turn, ROUNDS times, alternating which goes first, and measures each process's CPU time
(user + system, from os.wait4), so that time the shared host gives to other work is not counted.
Prints samples per CPU-second for each side and the median of the per-round ratios B / A (above
1: B is faster). More than one B may be given: every round then runs them all, in an order that
rotates from round to round, and each is compared with A (--b-arg goes to every B).

    python3 bench/cli_ab.py OLD/pathex build/pathex --renderer pt-nee --spp 32 --rounds 9
    python3 bench/cli_ab.py OLD/pathex MAIN/pathex build/pathex --renderer bdpt --spp 32 --rounds 15
"""
import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile


def cpu_run(cmd, cwd=None, cpu=None):
    pin = (lambda: os.sched_setaffinity(0, {cpu})) if cpu is not None else None
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, cwd=cwd, preexec_fn=pin)
    _, status, usage = os.wait4(proc.pid, 0)
    err = proc.stderr.read().decode()
    proc.stderr.close()
    if os.waitstatus_to_exitcode(status) != 0:
        sys.exit(f"{' '.join(cmd)} failed: {err}")
    return usage.ru_utime + usage.ru_stime


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("a", help="binary A (the baseline)")
    ap.add_argument("b", nargs="+", help="binary B (the change), or several")
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
    ap.add_argument("--cpu", type=int, default=max(os.sched_getaffinity(0)),
                    help="run every process on this one CPU (default: the highest this process may use; -1: "
                         "let the scheduler choose). The vCPUs of a shared VM can differ in speed by 30 %% "
                         "for minutes at a time, so a side that lands on the faster one more often wins")
    args = ap.parse_args()
    cpu = None if args.cpu < 0 else args.cpu
    tail = (["trace"] + ([os.path.abspath(args.scene)] if args.scene else []) +
            ["--renderer", args.renderer, "--spp", str(args.spp), "--threads", "1", "--no-images", "--quiet", "--json"])
    samples = 64 * 64 * args.spp if args.scene is None else None
    # Each binary writes its outputs (pathex-out/) in a folder of its own: pathex refuses to replace
    # outputs another version wrote.
    work = tempfile.mkdtemp(prefix="cli_ab-")
    sides = [("a", args.a)] + [(f"b{i}", b) for i, b in enumerate(args.b)]
    dirs = {name: os.path.join(work, name) for name, _ in sides}
    for d in dirs.values():
        os.mkdir(d)
    times = {name: [] for name, _ in sides}
    for r in range(args.rounds):
        # Two sides alternate which goes first; more rotate, so that each takes every place in turn.
        k = r % len(sides)
        order = sides[k:] + sides[:k] if len(sides) > 2 else (sides if r % 2 == 0 else sides[::-1])
        for name, binary in order:
            times[name].append(cpu_run([os.path.abspath(binary)] + tail + (args.a_arg if name == "a" else args.b_arg),
                                       dirs[name], cpu))
    shutil.rmtree(work)
    rate = (lambda t: f"{samples / t / 1e6:.3f} M samples/CPU-s") if samples else (lambda t: f"{t:.3f} CPU-s")
    where = f"on CPU {cpu}" if cpu is not None else "on any CPU"
    print(f"{args.renderer}, {args.spp} spp, {args.rounds} interleaved rounds, {where}")
    print(f"  A {args.a}: median {rate(statistics.median(times['a']))}")
    for name, binary in sides[1:]:
        ratios = [a / b for a, b in zip(times["a"], times[name])]
        label = "B" if len(sides) == 2 else f"B{name[1:]}"
        print(f"  {label} {binary}: median {rate(statistics.median(times[name]))}")
        print(f"  speed {label} / A: median {statistics.median(ratios):.4f} (rounds: {' '.join(f'{x:.3f}' for x in ratios)})")


if __name__ == "__main__":
    main()
