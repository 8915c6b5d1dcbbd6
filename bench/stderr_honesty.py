#!/usr/bin/env python3
"""Is the reported stderr honest? Reported stderr / seed-to-seed spread (issue 36).

    nice python3 bench/stderr_honesty.py --pathex build/pathex
    nice python3 bench/stderr_honesty.py --pathex build/pathex --arg=--sampler --arg=independent

For every scene, renderer and spp, renders seeds 1..--seeds (default 16) with
`pathex trace SCENE --renderer R --spp N --seed s --resolution RES --threads 1 --no-images --json`
and compares, for the whole image's luminance ("total"), the reported standard error with the
spread of the estimates over the seeds:

    ratio = sqrt(mean over seeds of stderr²) / sample standard deviation of the estimates.

An honest stderr gives 1. The spread of --seeds seeds is itself an estimate: with 16 seeds its
relative standard error is about 1/sqrt(2·15) = 18 %, so even an exactly honest stderr reads
outside [0.75, 1.25] in 18.7 % of cells (honest_outside(); 1.2 % at --seeds 64, the seed count that
can judge a cell) (the 90 % interval of the ratio for an exactly honest
stderr is printed as "honest 90 %"). The pooled row per renderer (all scenes and spp) divides
the summed mean stderr² by the summed spread² (each relative to its cell's own scale, i.e. the
mean of stderr²/spread² is taken as 1/ratio²'s estimate... pooled as sqrt(Σ stderr² / Σ spread²)
with every cell normalised by its spread²'s expectation under honesty), which is what the target
is judged on when single cells are noisy. Also printed: the ratio for each user class whose
estimate varies over the seeds (median over the classes).
"""
import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile

SCENES = ["samples/scenes/cornell.json", "samples/scenes/closed-sphere-emitting.json", "samples/scenes/point-glass.json"]


def chi2_quantile(p, k):
    """Wilson–Hilferty approximation of the chi-square quantile (good to ~1 % at k >= 10)."""
    z = statistics.NormalDist().inv_cdf(p)
    return k * (1 - 2 / (9 * k) + z * math.sqrt(2 / (9 * k))) ** 3


def chi2_cdf(x, k):
    """Wilson–Hilferty approximation of P(chi-square with k degrees of freedom <= x)."""
    return statistics.NormalDist().cdf(((x / k) ** (1 / 3) - (1 - 2 / (9 * k))) / math.sqrt(2 / (9 * k)))


def honest_outside(k, lo=0.75, hi=1.25):
    """The probability that an exactly honest stderr's cell reads outside [lo, hi]: with k + 1
    normal seeds the spread² is σ² χ²_k / k, and the ratio σ / spread leaves [lo, hi] when
    χ²_k / k > 1 / lo² or < 1 / hi² (k = 15: 18.7 %, a cell in five or six; k = 63: 1.2 %)."""
    return (1 - chi2_cdf(k / lo ** 2, k)) + chi2_cdf(k / hi ** 2, k)


def run(pathex, scene, renderer, spp, seed, resolution, extra, work):
    cmd = [pathex, "trace", scene, "--renderer", renderer, "--spp", str(spp), "--seed", str(seed),
           "--resolution", resolution, "--threads", "1", "--no-images", "--quiet", "--json",
           "--out", os.path.join(work, "out")] + extra
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    h = json.loads(out)
    classes = {c["name"]: (c["luminance"], c["stderr"]) for c in h["classes"]}
    return (h["total"]["luminance"], h["total"]["stderr"]), classes


def ratio(pairs):
    est = [e for e, _ in pairs]
    spread = statistics.stdev(est)
    rep = math.sqrt(statistics.fmean(s * s for _, s in pairs))
    return (rep / spread if spread > 0 else float("nan")), rep, spread


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--pathex", default="build/pathex")
    ap.add_argument("--scene", action="append", help="scene file (repeatable); default: " + ", ".join(SCENES))
    ap.add_argument("--renderers", default="pt,pt-nee,lt,bdpt")
    ap.add_argument("--spp", default="16,64,256")
    ap.add_argument("--seeds", type=int, default=16)
    ap.add_argument("--resolution", default="16x16")
    ap.add_argument("--arg", action="append", default=[], help="an extra argument for every trace (repeatable)")
    ap.add_argument("--json", help="also write every cell's figures to this file")
    args = ap.parse_args()
    scenes = args.scene or SCENES
    k = args.seeds - 1
    lo, hi = math.sqrt(k / chi2_quantile(0.95, k)), math.sqrt(k / chi2_quantile(0.05, k))
    print(f"# {args.pathex} {' '.join(args.arg)}; {args.seeds} seeds, {args.resolution}; honest 90 %: [{lo:.2f}, {hi:.2f}]")
    print("| scene | renderer | spp | total: stderr / spread | classes: median ratio (n) | mean estimate | spread |")
    print("|---|---|---|---|---|---|---|")
    work = tempfile.mkdtemp(prefix="stderr_honesty-")
    cells = []
    pooled = {}
    for scene in scenes:
        for renderer in args.renderers.split(","):
            for spp in [int(s) for s in args.spp.split(",")]:
                totals, per_class = [], {}
                for seed in range(1, args.seeds + 1):
                    t, cl = run(args.pathex, scene, renderer, spp, seed, args.resolution, args.arg, work)
                    totals.append(t)
                    for name, v in cl.items():
                        per_class.setdefault(name, []).append(v)
                r, rep, spread = ratio(totals)
                class_ratios = [ratio(v)[0] for v in per_class.values() if statistics.stdev([e for e, _ in v]) > 0]
                class_ratios = [c for c in class_ratios if math.isfinite(c)]
                cr = f"{statistics.median(class_ratios):.2f} ({len(class_ratios)})" if class_ratios else "–"
                mean = statistics.fmean(e for e, _ in totals)
                print(f"| {os.path.basename(scene)} | {renderer} | {spp} | {r:.2f} | {cr} | {mean:.5g} | {spread:.3g} |",
                      flush=True)
                cells.append({"scene": scene, "renderer": renderer, "spp": spp, "ratio": r, "stderr": rep,
                              "spread": spread, "class_ratios": class_ratios})
                if math.isfinite(r):
                    pooled.setdefault(renderer, []).append(1 / (r * r))
    print()
    print("| renderer | pooled stderr / spread (cells) | cells in [0.75, 1.25] |")
    print("|---|---|---|")
    for renderer, inv in pooled.items():
        # Each cell's spread² / stderr² estimates 1/ratio² with 15 degrees of freedom; their mean
        # over m cells has about 15·m, so the pooled ratio's honest interval is narrower.
        rs = [c["ratio"] for c in cells if c["renderer"] == renderer and math.isfinite(c["ratio"])]
        inside = sum(1 for x in rs if 0.75 <= x <= 1.25)
        print(f"| {renderer} | {1 / math.sqrt(statistics.fmean(inv)):.2f} ({len(inv)}) | {inside} of {len(rs)} |")
    n_cells = sum(1 for c in cells if math.isfinite(c["ratio"]))
    print(f"\nAn exactly honest stderr reads outside [0.75, 1.25] in a cell with probability "
          f"{100 * honest_outside(k):.1f} % at {args.seeds} seeds: about {honest_outside(k) * n_cells:.1f} of these "
          f"{n_cells} cells by chance (bench/README.md, issue 36, eighth session).")
    km = k * max(1, len(cells) // max(1, len(pooled)))
    print(f"\n(pooled over {km // k} cells: honest 90 % [{math.sqrt(km / chi2_quantile(0.95, km)):.2f}, "
          f"{math.sqrt(km / chi2_quantile(0.05, km)):.2f}])")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(cells, f, indent=1)


if __name__ == "__main__":
    main()
