#!/usr/bin/env python3
"""Efficiency 1 / (sigma^2 T) of renderers on one path class, measured in one interleaved run.

For each round and each renderer (in rotating order), runs
`pathex trace SCENE --renderer R --spp N --classes <CLASS> --threads 1 --no-images --quiet --json`
with its own seed, takes the class's standard error (batch means) from the JSON and the process's
CPU time (user + system, os.wait4: time the shared host gives to others is not counted), and
prints per renderer the median estimate, standard error, CPU time and efficiency, then each
renderer's median efficiency over the first one's (DESIGN §8: Veach's efficiency).

    python3 bench/connector_efficiency.py build/pathex samples/scenes/sun-window.json LDSDDSE \\
        --renderer pt-nee+distant --renderer lt --spp 16 --rounds 5
    python3 bench/connector_efficiency.py build/pathex samples/scenes/point-mirror-caustic.json LSDSDDSE \\
        --renderer pt-nee+mirror --renderer bdpt --renderer lt --spp 64 --rounds 5

The last line says how many times more efficient the first renderer is than the best of the others.

With --reference VALUE (the class's luminance computed another way), the efficiency is
1 / (MSE T) instead: MSE the mean over the rounds (seeds) of (estimate - VALUE)^2, T the mean CPU
time, so that a heavy-tailed estimator's understated stderr, or a rare-hit one's stderr of 0 when
it misses every hit, cannot flatter it (issue 40). A renderer may carry its own sample count as
NAME:SPP, so that each gets about the same CPU time, and options of its own as NAME:SPP:OPTIONS
(`bdpt+manifold:16:--manifold-seeds=1`). Several classes (each with its --reference, in order) are
read from the same full renders, each reported as above:

    python3 bench/connector_efficiency.py build/pathex samples/scenes/lamp-glass.json LDDSSDDSE LDDSSDSSDSE 'L[SD]{4,}E' \\
        --reference 8.555e-3 --reference 1.034e-3 --reference 0.13708 --rounds 96 \\
        --renderer bdpt:64 --renderer bdpt+manifold:48 --renderer pt-nee+manifold:24

    python3 bench/connector_efficiency.py build/pathex samples/scenes/lamp-glass.json LDDSSDSSDSE \\
        --reference 1.1e-3 --only --rounds 8 \\
        --renderer pt-nee+manifold:16 --renderer pt:1024 --renderer pt-nee:1024 --renderer bdpt:512

A renderer given at several sample counts (NAME:64, NAME:1024; the same NAME and options) also
gets the exponent with which its RMSE against --reference falls with the sample count (-0.5 for
an estimator of finite variance; slower for a heavy tail, whose efficiency then falls with the
budget; docs/manifold.md):

    python3 bench/connector_efficiency.py build/pathex samples/scenes/lamp-glass.json LDDSSDSSDSE \\
        --reference 1.0575e-3 --only --rounds 64 --renderer pt:4096 --renderer pt-nee+manifold:64 \\
        --renderer pt-nee+manifold:1024 --renderer bdpt+manifold:64 --renderer bdpt+manifold:1024

Round i (from 0) renders with seed 1 + i, or FIRST + i with --first-seed FIRST (another set of seeds
for the same command).

With --baseline OLD/pathex every renderer also runs with that binary, in the same rounds (labelled
`@baseline`), and each line compares the renderer with its baseline; --only renders the class
alone (`--only CLASS`) instead of taking it from a full render (`--classes`).

    python3 bench/connector_efficiency.py build/pathex samples/scenes/point-glass.json LSDSSDDSE \\
        --renderer pt-nee+manifold --baseline /work/old-8eebe78/build/pathex --only --spp 16 --rounds 5
"""
import argparse
import math
import json
import os
import random
import statistics
import subprocess
import sys
import tempfile


def run(cmd):
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    out = proc.stdout.read()
    _, status, usage = os.wait4(proc.pid, 0)
    err = proc.stderr.read().decode()
    if os.waitstatus_to_exitcode(status) != 0:
        sys.exit(f"{' '.join(cmd)} failed: {err}")
    return json.loads(out), usage.ru_utime + usage.ru_stime


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("pathex")
    ap.add_argument("scene")
    ap.add_argument("path_class", nargs="+", help="a full-notation class, e.g. LDSDDSE; several: each from the same renders")
    ap.add_argument("--renderer", action="append", required=True, help="repeat; the first is the reference")
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--first-seed", type=int, default=1, help="round i renders with seed FIRST + i (another set of seeds)")
    ap.add_argument("--max-bounces", type=int, default=8)
    ap.add_argument("--baseline", help="another pathex binary: every renderer also runs with it")
    ap.add_argument("--only", action="store_true", help="render with --only CLASS (default: the class of a full render)")
    ap.add_argument("--reference", type=float, action="append",
                    help="the class's value: efficiency 1 / (MSE T) over the rounds (repeat: one per class, in order)")
    args = ap.parse_args()
    classes_of = args.path_class
    if args.reference is not None and len(args.reference) != len(classes_of):
        sys.exit("give one --reference per class")
    if args.only and len(classes_of) > 1:
        sys.exit("--only renders one class")
    # (label, binary, renderer) per run
    spp_of = {r: int(r.split(":")[1]) if ":" in r else args.spp for r in args.renderer}
    extra_of = {r: r.split(":", 2)[2].split() if r.count(":") >= 2 else [] for r in args.renderer}
    runs = [(r, args.pathex, r) for r in args.renderer]
    if args.baseline:
        runs = [x for r in args.renderer for x in ((r, args.pathex, r), (r + " @baseline", args.baseline, r))]
    with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as f:
        json.dump({"classes": [{"name": f"c{i}", "expr": e} for i, e in enumerate(classes_of)]}, f)
        classes = f.name
    # per class, per label: (estimate, stderr, cpu, efficiency) per round; one render gives every class
    results = [{label: [] for label, _, _ in runs} for _ in classes_of]
    select = ["--only", classes_of[0]] if args.only else ["--classes", classes]
    try:
        for rnd in range(args.rounds):
            order = runs[rnd % len(runs):] + runs[:rnd % len(runs)]
            for label, binary, r in order:
                with tempfile.TemporaryDirectory() as out:  # each binary writes its own folder
                    doc, cpu = run([binary, "trace", args.scene, "--renderer", r.split(":")[0], "--spp", str(spp_of[r]), *extra_of[r], *select,
                                    "--seed", str(args.first_seed + rnd), "--threads", "1", "--max-bounces", str(args.max_bounces),
                                    "--no-images", "--quiet", "--json", "--out", os.path.join(out, "o")])
                for i, expr in enumerate(classes_of):
                    c = [c for c in doc["classes"] if c["expr"] == expr or c.get("name") == f"c{i}"][0]
                    se = c["stderr"]
                    results[i][label].append((c["luminance"], se, cpu, 1.0 / (se * se * cpu) if se else float("inf")))
    finally:
        os.unlink(classes)
    for i, expr in enumerate(classes_of):
        report(args, runs, expr, results[i], args.reference[i] if args.reference else None)


def report(args, runs, path_class, results, reference):
    print(f"class {path_class} in {args.scene}, {args.spp} spp, {args.rounds} interleaved rounds, 1 thread")
    if reference is not None:  # 1 / (MSE T) against the reference, the same for every round of a renderer
        for label in results:
            mse = statistics.mean((x[0] - reference) ** 2 for x in results[label])
            t = statistics.mean(x[2] for x in results[label])
            results[label] = [(x[0], x[1], x[2], 1.0 / (mse * t) if mse else float("inf")) for x in results[label]]
            print(f"  {label:16s} mean {statistics.mean(x[0] for x in results[label]):.6g}  RMSE {math.sqrt(mse):.3g} "
                  f"({math.sqrt(mse) / reference:.1%})  mean CPU {t:.3f} s")
    ref = statistics.median(x[3] for x in results[args.renderer[0]])
    for label, _, r in runs:
        med = lambda i: statistics.median(x[i] for x in results[label])
        eff = med(3)
        print(f"  {label:16s} estimate {med(0):.6g} ± {med(1):.3g}  CPU {med(2):.3f} s  efficiency {eff:.4g}"
              f"  ({eff / ref:.3g} × {args.renderer[0]})")
        if label.endswith(" @baseline"):
            ratios = [n[3] / b[3] for n, b in zip(results[r], results[label])]
            print(f"  {r} against its baseline: {statistics.median(ratios):.3g} × (median of the rounds' ratios, "
                  f"{min(ratios):.3g}–{max(ratios):.3g})")
    if reference is not None:
        decay(args, results, reference)
    if len(args.renderer) > 1:
        best = max(args.renderer[1:], key=lambda r: statistics.median(x[3] for x in results[r]))
        best_eff = statistics.median(x[3] for x in results[best])
        print(f"  {args.renderer[0]} against the best of the others ({best}): {ref / best_eff:.3g} ×")


def decay(args, results, reference):
    """How a renderer's RMSE falls with its sample count, where it ran at several (NAME:SPP with the
    same NAME and options): the exponent of spp between its smallest and largest count, -0.5 for an
    estimator of finite variance; a heavy tail (a variance infinite, or finite only beyond the
    budgets measured) falls slower. A 90 % interval from 2,000 resamplings of the rounds (seeds)."""
    groups = {}
    for r in args.renderer:
        if ":" in r:
            parts = r.split(":", 2)
            groups.setdefault((parts[0], parts[2] if len(parts) > 2 else ""), []).append((int(parts[1]), r))
    rng = random.Random(1)
    for (name, extra), members in groups.items():
        if len(members) < 2:
            continue
        (lo, r_lo), (hi, r_hi) = min(members), max(members)
        a = [x[0] for x in results[r_lo]]
        b = [x[0] for x in results[r_hi]]
        def slope(xs, ys):
            mse_lo = statistics.mean((x - reference) ** 2 for x in xs)
            mse_hi = statistics.mean((y - reference) ** 2 for y in ys)
            return 0.5 * math.log(mse_hi / mse_lo) / math.log(hi / lo) if mse_lo > 0 and mse_hi > 0 else float("nan")
        n = min(len(a), len(b))
        draws = (slope([a[k] for k in idx], [b[k] for k in idx])
                 for idx in ([rng.randrange(n) for _ in range(n)] for _ in range(2000)))
        boot = sorted(x for x in draws if not math.isnan(x)) or [float("nan")]
        label = name + (":" + extra if extra else "")
        print(f"  {label}: RMSE falls as spp^{slope(a, b):.2f} from {lo} to {hi} spp "
              f"(90 % of resampled rounds {boot[len(boot) // 20]:.2f} to {boot[len(boot) - 1 - len(boot) // 20]:.2f}; "
              f"-0.5 for a finite variance)")


if __name__ == "__main__":
    main()
