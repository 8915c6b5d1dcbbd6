#!/usr/bin/env python3
"""How well a render's stderr describes its error, per class, over many seeds: for comparing two
builds whose standard errors differ (the stderr's pixel groups, stats/histogram.h "Batches"; the
twenty-fourth session's trial, bench/README.md).

For each binary: --seeds renders (one thread, the seed 1..N, --no-images) of --scene (the
embedded Cornell box without one) under --renderer at --spp, any extra trace arguments after
`--`. Per class (and the total) it prints:

  flagged   renders whose stderr `pathex trace` flags unstable (stderr_stability >= 0.7)
  median ε  the median of stderr_stability (about 0.35 for 16 groups of alike variance)
  dof       the stderr's degrees of freedom implied by its own spread over the seeds,
            2 / relvar(stderr²) (16 groups of two replicates: 16 when the groups are alike)
  sd(z)     the spread of (estimate - reference) / stderr (a t with 16 dof: 1.07)
  max |z|   the largest deviate

The reference is one --ref-spp render of the same renderer by the first binary, seed 999, two
threads (its luminances do not depend on the groups).

    python3 bench/stderr_groups.py --pathex OLD/pathex --pathex build/pathex --renderer pt-nee \\
        --spp 16 --seeds 60 -- --splits 1
"""
import argparse
import json
import math
import statistics as st
import subprocess
import tempfile


def render(binary, scene, renderer, spp, seed, out, threads, extra):
    cmd = [binary, "trace"] + ([scene] if scene else []) + [
        "--renderer", renderer, "--spp", str(spp), "--seed", str(seed), "--out", out,
        "--threads", str(threads), "--quiet", "--no-images"] + extra
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    d = json.load(open(out + "/histogram.json"))
    return [dict(d["total"], name="total")] + d["classes"]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--pathex", action="append", required=True)
    ap.add_argument("--scene", default="")
    ap.add_argument("--renderer", default="pt-nee")
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--seeds", type=int, default=40)
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("extra", nargs="*")
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        ref = {c["name"]: c["luminance"] for c in
               render(a.pathex[0], a.scene, a.renderer, a.ref_spp, 999, tmp + "/ref", 2, a.extra)}
        for binary in a.pathex:
            rows = {}
            for s in range(1, a.seeds + 1):
                for c in render(binary, a.scene, a.renderer, a.spp, s, f"{tmp}/r", 1, a.extra):
                    rows.setdefault(c["name"], []).append(c)
            print(binary)
            print(f"  {'class':10} {'flagged':>8} {'median ε':>9} {'dof':>6} {'sd(z)':>6} {'max |z|':>8}")
            for name, cs in rows.items():
                eps = [c["stderr_stability"] for c in cs if c.get("stderr_stability") is not None]
                v = [c["stderr"] ** 2 for c in cs]
                m = st.mean(v)
                dof = 2 * m * m / st.variance(v) if m > 0 and st.variance(v) > 0 else math.nan
                z = [(c["luminance"] - ref[name]) / c["stderr"] for c in cs if c["stderr"] > 0]
                print(f"  {name:10} {sum(e >= 0.7 for e in eps):4}/{len(cs):<3} "
                      f"{st.median(eps) if eps else math.nan:9.3f} {dof:6.1f} "
                      f"{st.pstdev(z) if len(z) > 1 else math.nan:6.2f} {max(map(abs, z)) if z else math.nan:8.1f}")


if __name__ == "__main__":
    main()
