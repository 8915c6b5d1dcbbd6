#!/usr/bin/env python3
"""The seen-through caustic's reference, by an estimator independent of the manifold walk.

tests/trace/scenes/point-glass-through.json is samples/scenes/point-glass.json framed on the
caustic seen through the glass sphere, LSDSSDSSDSE. Only the manifold connector samples that
class under the point light. This script replaces the point light (intensity I at p) by a
spherical lamp of radius r centred at p, emitting the radiance Le = I / (pi r^2) outwards. Its
intensity is I in every direction, the point light's, and the class becomes LDDSSDSSDSE. Plain
path tracing (`pt`, emitter hits) renders that class with no connector at all. The script then
fits L(r) = L0 + a r^2 by weighted least squares and extrapolates to r -> 0. The fit's L0 and
its standard error are the reference. The script also fits L0 + a r + b r^2, to check the
model; README says which fit the reference uses.

    python3 bench/manifold_reference.py [--pathex build/pathex] [--radii 0.4,0.2,0.1,0.05]
        [--seconds 60,240,480,600] [--seed 1] [--json out.json]
    python3 bench/manifold_reference.py --combine seed1.json seed2.json   # fit earlier runs together

Each radius renders `pathex trace SCENE --renderer pt --only LDDSSDSSDSE --spp 2^24 --time S`:
the render stops after S seconds with whole passes, and its batch-means standard error comes
from those passes.
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
SCENE = os.path.join(ROOT, "tests", "trace", "scenes", "point-glass-through.json")
POINT_CLASS = "LSDSSDSSDSE"
AREA_CLASS = "LDDSSDSSDSE"


def lamp_scene(scene_path, radius):
    """The scene with its one point light replaced by a lamp sphere of the same intensity."""
    with open(scene_path) as f:
        s = json.load(f)
    lights = s.pop("lights")
    if len(lights) != 1 or lights[0]["type"] != "point":
        sys.exit(f"{scene_path}: expected one point light")
    light = lights[0]
    base = os.path.dirname(os.path.abspath(scene_path))
    for shape in s["shapes"]:
        if "file" in shape:
            shape["file"] = os.path.normpath(os.path.join(base, shape["file"]))
    s["materials"]["lamp"] = {"type": "diffuse", "albedo": [0, 0, 0]}  # black: it only emits
    le = [i / (math.pi * radius * radius) for i in light["intensity"]]
    s["shapes"].append({"type": "sphere", "center": light["position"], "radius": radius, "material": "lamp",
                        "emission": le})
    return s


def render(pathex, scene, renderer, cls, seconds, seed, spp=1 << 24):
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "out")
        cmd = [pathex, "trace", scene, "--renderer", renderer, "--only", cls, "--spp", str(spp), "--seed", str(seed),
               "--no-images", "--quiet", "--json", "--out", out]
        if seconds > 0:
            cmd += ["--time", str(seconds)]
        p = subprocess.run(cmd, capture_output=True, text=True)
        if p.returncode not in (0, 1):  # 1: stopped by --time, the passes done are written
            sys.exit(" ".join(cmd) + " failed:\n" + p.stderr)
        d = json.loads(p.stdout)
        c = [c for c in d["classes"] if c["expr"] == cls][0]
        return {"luminance": c["luminance"], "stderr": c["stderr"], "samples": c["samples"], "spp": d["spp"],
                "nonfinite": d["nonfinite_samples"]}


def weighted_fit(xs, ys, sigmas, powers):
    """Least squares of y = sum_k c_k x^p_k weighted by 1/sigma^2: the coefficients and their covariance."""
    n = len(powers)
    a = [[0.0] * n for _ in range(n)]
    b = [0.0] * n
    for x, y, s in zip(xs, ys, sigmas):
        row = [x ** p for p in powers]
        w = 1.0 / (s * s)
        for i in range(n):
            b[i] += w * row[i] * y
            for j in range(n):
                a[i][j] += w * row[i] * row[j]
    inv = invert(a)
    coef = [sum(inv[i][j] * b[j] for j in range(n)) for i in range(n)]
    chi2 = sum(((y - sum(c * x ** p for c, p in zip(coef, powers))) / s) ** 2 for x, y, s in zip(xs, ys, sigmas))
    return coef, inv, chi2


def invert(m):
    n = len(m)
    a = [row[:] + [1.0 if i == j else 0.0 for j in range(n)] for i, row in enumerate(m)]
    for c in range(n):
        p = max(range(c, n), key=lambda r: abs(a[r][c]))
        a[c], a[p] = a[p], a[c]
        piv = a[c][c]
        a[c] = [v / piv for v in a[c]]
        for r in range(n):
            if r != c:
                f = a[r][c]
                a[r] = [v - f * w for v, w in zip(a[r], a[c])]
    return [row[n:] for row in a]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--pathex", default=os.path.join(ROOT, "build", "pathex"))
    ap.add_argument("--scene", default=SCENE)
    ap.add_argument("--radii", default="0.4,0.2,0.1,0.05")
    ap.add_argument("--seconds", default="60,240,480,600", help="render time per radius")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--json", help="write the figures here")
    ap.add_argument("--combine", nargs="+", metavar="JSON",
                    help="render nothing: fit the radii of these earlier --json outputs together (other seeds)")
    a = ap.parse_args()
    radii = [float(r) for r in a.radii.split(",")]
    seconds = [float(s) for s in a.seconds.split(",")]
    if len(seconds) != len(radii):
        sys.exit("--seconds needs one time per radius")

    rows = []
    if a.combine:
        radii, seconds = [], []
        for path in a.combine:
            with open(path) as f:
                for row in json.load(f)["radii"]:
                    rows.append(row)
                    print(f"r = {row['radius']:<6} {AREA_CLASS} {row['luminance']:.6e} +- {row['stderr']:.2e}   "
                          f"({row['samples']} hits, {row['spp']} spp, {path})")
    with tempfile.TemporaryDirectory() as tmp:
        for r, t in zip(radii, seconds):
            path = os.path.join(tmp, f"lamp-{r}.json")
            with open(path, "w") as f:
                json.dump(lamp_scene(a.scene, r), f)
            res = render(a.pathex, path, "pt", AREA_CLASS, t, a.seed)
            res["radius"] = r
            rows.append(res)
            print(f"r = {r:<6} {AREA_CLASS} {res['luminance']:.6e} +- {res['stderr']:.2e}   "
                  f"({res['samples']} hits, {res['spp']} spp, {t:.0f} s, non-finite {res['nonfinite']})", flush=True)
    usable = [x for x in rows if x["stderr"] > 0]
    xs = [x["radius"] for x in usable]
    ys = [x["luminance"] for x in usable]
    ss = [x["stderr"] for x in usable]
    fits = {}
    for name, powers in (("L0 + a r^2", [0, 2]), ("L0 + a r + b r^2", [0, 1, 2])):
        if len(usable) <= len(powers):
            continue
        coef, cov, chi2 = weighted_fit(xs, ys, ss, powers)
        fits[name] = {"L0": coef[0], "stderr": math.sqrt(cov[0][0]), "chi2": chi2, "dof": len(usable) - len(powers)}
        print(f"fit {name:<18} L0 = {coef[0]:.6e} +- {math.sqrt(cov[0][0]):.2e}   chi2 {chi2:.2f} / {len(usable) - len(powers)} dof")
    if a.json:
        model = "L0 + a r^2"  # the lamp is symmetric about the light's point: no term in r (README)
        reference = {"luminance": fits[model]["L0"], "stderr": fits[model]["stderr"], "fit": model} if model in fits else None
        with open(a.json, "w") as f:
            json.dump({"scene": os.path.relpath(a.scene, ROOT), "class": POINT_CLASS, "lamp_class": AREA_CLASS,
                       "reference": reference, "command": "python3 bench/manifold_reference.py " + " ".join(sys.argv[1:]),
                       "seed": None if a.combine else a.seed, "radii": rows, "fits": fits}, f, indent=2)
            f.write("\n")


if __name__ == "__main__":
    main()
