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
"""
import argparse
import json
import os
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
    ap.add_argument("path_class", help="a full-notation class, e.g. LDSDDSE")
    ap.add_argument("--renderer", action="append", required=True, help="repeat; the first is the reference")
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--max-bounces", type=int, default=8)
    args = ap.parse_args()
    with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as f:
        json.dump({"classes": [{"name": "c", "expr": args.path_class}]}, f)
        classes = f.name
    results = {r: [] for r in args.renderer}
    try:
        for rnd in range(args.rounds):
            order = args.renderer[rnd % len(args.renderer):] + args.renderer[:rnd % len(args.renderer)]
            for r in order:
                doc, cpu = run([args.pathex, "trace", args.scene, "--renderer", r, "--spp", str(args.spp), "--classes",
                                classes, "--seed", str(rnd + 1), "--threads", "1", "--max-bounces", str(args.max_bounces),
                                "--no-images", "--quiet", "--json"])
                c = doc["classes"][0]
                se = c["stderr"]
                results[r].append((c["luminance"], se, cpu, 1.0 / (se * se * cpu) if se else float("inf")))
    finally:
        os.unlink(classes)
    print(f"class {args.path_class} in {args.scene}, {args.spp} spp, {args.rounds} interleaved rounds, 1 thread")
    ref = statistics.median(x[3] for x in results[args.renderer[0]])
    for r in args.renderer:
        med = lambda i: statistics.median(x[i] for x in results[r])
        eff = med(3)
        print(f"  {r:16s} estimate {med(0):.6g} ± {med(1):.3g}  CPU {med(2):.3f} s  efficiency {eff:.4g}"
              f"  ({eff / ref:.3g} × {args.renderer[0]})")
    if len(args.renderer) > 1:
        best = max(args.renderer[1:], key=lambda r: statistics.median(x[3] for x in results[r]))
        best_eff = statistics.median(x[3] for x in results[best])
        print(f"  {args.renderer[0]} against the best of the others ({best}): {ref / best_eff:.3g} ×")


if __name__ == "__main__":
    main()
