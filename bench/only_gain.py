#!/usr/bin/env python3
"""Efficiency gain of rendering one class alone (pathex trace --only, issue 14), interleaved.

    python3 bench/only_gain.py build/pathex --rounds 5

For each case (scene, renderer, class), each round runs the full render (every strategy, every
path, the class measured as one class of the render) and the --only render of that class alone
(the cheapest cover of its paths, trace/prune.h: other strategies, so another σ), in an order that
alternates between rounds, each with the round's seed, one thread, no images. The efficiency of a
render on the class is 1 / (σ² T): σ the class's standard error (batch means, histogram.json) and
T the process's CPU seconds (user + system, os.wait4: start-up, checker, rendering, writing).
Printed per case: per round each side's estimate, σ and T and the gain (efficiency of --only over
the full render's); then the median gain, its range, and the medians of σ² and T of each side
(the gain of the medians, σ²_full T_full / (σ²_only T_only), is printed too: σ of one round is
itself noisy, ~1/sqrt(2 × batches) relative).

With --baseline OLD it also measures the cost of the hooks when nothing is pruned: a render whose
profile the checker leaves whole (the Cornell box with pt), OLD (pathex before issue 14) against
the given binary, interleaved: the median ratio of CPU seconds.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cli_ab import cpu_run  # noqa: E402  (the one CPU-time runner)

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = os.path.join(ROOT, "samples", "scenes")
# (label, scene, renderer, class expression, spp, resolution)
CASES = [
    ("caustic of point-glass", "point-glass.json", "bdpt", "$caustic", 64, "128x128"),
    ("$direct on the Cornell box", "cornell.json", "bdpt", "$direct", 16, "128x128"),
    ("L.{8,}E on the Cornell box", "cornell.json", "bdpt", "L.{8,}E", 16, "128x128"),
    # Classes the cover reduces (trace/prune.h): caustics seen on a diffuse surface (light tracing
    # alone samples them), long all-diffuse paths (NEE alone).
    ("caustic on a diffuse surface, point-glass", "point-glass.json", "bdpt", "L..S+D.*DDSE", 64, "128x128"),
    ("LD{7,}SE on the Cornell box", "cornell.json", "bdpt", "LD{7,}SE", 16, "128x128"),
]


def render(binary, scene, renderer, classes, spp, resolution, seed, out, only):
    cmd = [binary, "trace", os.path.join(SCENES, scene), "--renderer", renderer, "--classes", classes, "--spp", str(spp),
           "--resolution", resolution, "--seed", str(seed), "--threads", "1", "--no-images", "--quiet", "--out", out]
    if only:
        cmd += ["--only", "$target"]
    t = cpu_run(cmd, ROOT)
    with open(os.path.join(out, "histogram.json")) as f:
        doc = json.load(f)
    c = next(c for c in doc["classes"] if c["name"] == "target")
    return c["luminance"], c["stderr"], t


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("binary")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--baseline", help="pathex before issue 14, for the cost when nothing is pruned")
    ap.add_argument("--case", action="append", default=[], help="only the cases whose label holds this (repeatable)")
    args = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="pathex-only-")
    for label, scene, renderer, expr, spp, res in CASES:
        if args.case and not any(c in label for c in args.case):
            continue
        classes = os.path.join(tmp, "classes.json")
        with open(classes, "w") as f:
            json.dump({"classes": [{"name": "target", "expr": expr}]}, f)
        gains, tf, to, vf, vo = [], [], [], [], []
        for r in range(args.rounds):
            seed = 100 + r
            sides = [False, True] if r % 2 == 0 else [True, False]
            got = {}
            for only in sides:
                got[only] = render(args.binary, scene, renderer, classes, spp, res, seed, os.path.join(tmp, "out"), only)
            (lf, sf, cf), (lo, so, co) = got[False], got[True]
            gain = (sf * sf * cf) / (so * so * co)
            gains.append(gain)
            tf.append(cf)
            to.append(co)
            vf.append(sf * sf)
            vo.append(so * so)
            print(f"  {label}, round {r}: full {lf:.5f} ± {sf:.5f} in {cf:.2f} s, only {lo:.5f} ± {so:.5f} in {co:.2f} s,"
                  f" gain {gain:.2f}x", flush=True)
        med = statistics.median
        print(f"{label} ({renderer}, {spp} spp, {res}): gain in 1/(sigma^2 T) median {med(gains):.2f}x"
              f" (range {min(gains):.2f}-{max(gains):.2f}); sigma^2 full {med(vf):.3g}, only {med(vo):.3g}"
              f" (ratio {med(vf) / med(vo):.2f}); CPU s full {med(tf):.2f}, only {med(to):.2f} (ratio {med(tf) / med(to):.2f});"
              f" gain of the medians {med(vf) * med(tf) / (med(vo) * med(to)):.2f}x", flush=True)
    if args.baseline:
        ratios = []
        for r in range(args.rounds):
            cmd = ["trace", os.path.join(SCENES, "cornell.json"), "--renderer", "pt", "--spp", "64", "--resolution", "128x128",
                   "--threads", "1", "--no-images", "--quiet", "--out", os.path.join(tmp, "out")]
            order = [args.baseline, args.binary] if r % 2 == 0 else [args.binary, args.baseline]
            t = {b: cpu_run([b] + cmd, ROOT) for b in order}
            ratios.append(t[args.binary] / t[args.baseline])
            print(f"  nothing pruned, round {r}: old {t[args.baseline]:.3f} s, new {t[args.binary]:.3f} s", flush=True)
        print(f"nothing pruned (Cornell box, pt, 64 spp, 128x128): new / old CPU s median {statistics.median(ratios):.3f}"
              f" (range {min(ratios):.3f}-{max(ratios):.3f})")


if __name__ == "__main__":
    main()
