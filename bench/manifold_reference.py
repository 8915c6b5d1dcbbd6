#!/usr/bin/env python3
"""The seen-through caustic's reference, by estimators independent of the manifold walk.

tests/trace/scenes/point-glass-through.json is the glass sphere, floor and point light of
samples/scenes/point-glass.json, framed on the caustic seen through the sphere, LSDSSDSSDSE.
Only the manifold connector samples that class under a point light. Two references:

--method quadrature (the default, the reference; seconds). The light lies on the axis through
the sphere's centre perpendicular to the floor, so the caustic's irradiance on the floor depends
only on the distance rho from that axis. A ray leaving the light at angle theta from the axis
crosses the sphere (Fresnel transmittances T1 T2, unpolarized, as bsdf::fresnel_dielectric) and
lands at signed rho(theta); the flux I T sin(theta) dtheta dphi lands on the ring rho drho dphi:

    E(rho) = sum over the rays with |rho(theta)| = rho of I T(theta) sin(theta) / (rho |drho/dtheta|).

A table of rho(theta) over the cone the sphere subtends (central differences for drho/dtheta)
splits into monotone branches, each inverted by interpolation. The image mean is then the
average over the film (box pixels, as pathex) of (albedo / pi) E(rho) T_eye, with T_eye the two
Fresnel transmittances of the eye ray through the sphere: a stratified grid, jittered; the
spread of independent jitters gives the standard error. It shares nothing with the walk but the
scene and the Fresnel formula, and refuses scenes it does not solve (any other shape or light).

--method lamp (a cross-check; hours). The point light becomes a spherical lamp of radius r
centred at its position, emitting Le = I / (pi r^2) outwards (intensity I in every direction,
the point light's); the class becomes LDDSSDSSDSE, which plain path tracing (`pt`, emitter hits)
renders with no connector. L(r) is fitted by weighted least squares and extrapolated to r = 0.
The lamp is symmetric about the light's point, so the series has even powers only; the radii a
run can afford (0.1 to 0.4 against the sphere's 0.5 at 1.5 from the light) are not small: L(0.4)
is 2.3 L(0), and the r^4 term matters. The fits printed: L0 + a r^2 + b r^4 (the lamp's
estimate), L0 + a r^2 and L0 + a r + b r^2 (checks of the form).

    python3 bench/manifold_reference.py [--pathex build/pathex] [--film 768x384] [--jitters 4] [--json out.json]
    python3 bench/manifold_reference.py --method lamp [--radii 0.4,0.2,0.1,0.05]
        [--seconds 60,240,480,600] [--seed 1] [--json out.json]
    python3 bench/manifold_reference.py --method lamp --combine seed1.json seed2.json   # fit earlier runs together

Each lamp radius renders `pathex trace SCENE --renderer pt --only LDDSSDSSDSE --spp 2^24 --time S`:
the render stops after S seconds with whole passes, and its batch-means standard error comes
from those passes.
"""
import argparse
import bisect
import json
import math
import os
import random
import statistics
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


# --- the quadrature ---

def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def add(a, b, s=1.0):
    return [a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def unit(a):
    n = math.sqrt(dot(a, a))
    return [a[0] / n, a[1] / n, a[2] / n]


def fresnel(cos_i, eta):
    """Unpolarized Fresnel reflectance of a smooth dielectric (bsdf::fresnel_dielectric)."""
    if cos_i < 0.0:
        eta, cos_i = 1.0 / eta, -cos_i
    sin2_t = (1.0 - cos_i * cos_i) / (eta * eta)
    if sin2_t >= 1.0:
        return 1.0
    cos_t = math.sqrt(1.0 - sin2_t)
    r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t)
    r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t)
    return 0.5 * (r_parl * r_parl + r_perp * r_perp)


def refract(d, n, eta):
    """d refracted at normal n (on d's side) with eta = index before / index after; None under total reflection."""
    cos_i = -dot(d, n)
    sin2_t = eta * eta * (1.0 - cos_i * cos_i)
    if sin2_t >= 1.0:
        return None
    return unit(add([eta * x for x in d], n, eta * cos_i - math.sqrt(1.0 - sin2_t)))


def sphere_exit(o, d, centre, radius, ior):
    """The ray o + t d refracted into the sphere and out again: (exit point, direction, T1 T2), or None if it misses."""
    oc = add(o, centre, -1.0)
    b = dot(oc, d)
    disc = b * b - (dot(oc, oc) - radius * radius)
    if disc <= 0.0 or -b - math.sqrt(disc) <= 0.0:
        return None
    p = add(o, d, -b - math.sqrt(disc))
    n = [(x - c) / radius for x, c in zip(p, centre)]
    transmit = 1.0 - fresnel(-dot(d, n), ior)
    d = refract(d, n, 1.0 / ior)
    p = add(p, d, -2.0 * dot(add(p, centre, -1.0), d))  # the far side of the chord
    n = [(x - c) / radius for x, c in zip(p, centre)]
    transmit *= 1.0 - fresnel(-dot(d, n), ior)  # from inside (cos < 0)
    d = refract(d, [-x for x in n], ior)
    return None if d is None else (p, d, transmit)


def caustic_table(distance, radius, ior, height, rows):
    """rho(theta), drho/dtheta and T(theta) over the cone the sphere subtends from the light, split into
    monotone branches: a list of (rho ascending, rows). `distance`: light to centre, `height`: light to floor."""
    def land(theta):  # the meridional plane: x radial, y along the axis from the light
        r = sphere_exit([0.0, 0.0, 0.0], [math.sin(theta), math.cos(theta), 0.0], [0.0, distance, 0.0], radius, ior)
        if r is None or not r[1][1] > 0.0:
            return None
        p, d, transmit = r
        return p[0] + (height - p[1]) / d[1] * d[0], transmit
    theta_max = math.asin(radius / distance)
    h = theta_max * 1e-7
    table = []
    for k in range(rows):
        theta = (k + 0.5) / rows * theta_max
        at, lo, hi = land(theta), land(theta - h), land(theta + h)
        if at and lo and hi:
            table.append((theta, at[0], (hi[0] - lo[0]) / (2.0 * h), at[1]))
    branches, current = [], [table[0]]
    for row in table[1:]:
        if (row[2] > 0.0) != (current[-1][2] > 0.0):
            branches.append(current)
            current = []
        current.append(row)
    branches.append(current)
    out = []
    for b in branches:
        if len(b) >= 2:
            b = b if b[0][1] < b[-1][1] else b[::-1]
            out.append(([row[1] for row in b], b))
    return out


def irradiance(branches, intensity, rho):
    """The caustic's irradiance at distance rho from the axis: the sum over the rays landing there."""
    e = 0.0
    for target in (rho, -rho):
        for keys, b in branches:
            if not keys[0] <= target <= keys[-1]:
                continue
            j = max(1, bisect.bisect_left(keys, target))
            f = (target - keys[j - 1]) / (keys[j] - keys[j - 1])
            theta, drho, transmit = ((1.0 - f) * b[j - 1][i] + f * b[j][i] for i in (0, 2, 3))
            e += intensity * transmit * math.sin(theta) / (rho * abs(drho))
    return e


def quadrature_setup(scene_path):
    """The scene's light, sphere, floor and camera, checked to be what the quadrature solves."""
    with open(scene_path) as f:
        s = json.load(f)
    where = f"{scene_path}: the quadrature needs "
    lights, shapes, cam = s.get("lights", []), s.get("shapes", []), s.get("camera", {})
    if len(lights) != 1 or lights[0].get("type") != "point":
        sys.exit(where + "one point light")
    spheres = [x for x in shapes if x.get("type") == "sphere"]
    quads = [x for x in shapes if x.get("type") == "quad"]
    if len(spheres) != 1 or len(quads) != 1 or len(shapes) != 2 or any("emission" in x for x in shapes):
        sys.exit(where + f"one sphere and one quad, no other shape and no emission (got {[x.get('type') for x in shapes]})")
    glass, floor = s["materials"][spheres[0]["material"]], s["materials"][quads[0]["material"]]
    if glass.get("type") != "dielectric" or "tint" in glass or floor.get("type") != "diffuse":
        sys.exit(where + "a dielectric sphere (no tint) and a diffuse quad")
    if cam.get("type", "pinhole") != "pinhole":
        sys.exit(where + "a pinhole camera")
    light, sphere, quad = lights[0], spheres[0], quads[0]
    axis = unit(add(sphere["center"], light["position"], -1.0))
    normal = unit(cross(quad["edge1"], quad["edge2"]))
    if abs(abs(dot(axis, normal)) - 1.0) > 1e-9:
        sys.exit(where + "the light on the axis through the sphere's centre perpendicular to the floor")
    height = dot(add(quad["corner"], light["position"], -1.0), axis)  # light to floor along the axis
    distance = math.sqrt(dot(add(sphere["center"], light["position"], -1.0), add(sphere["center"], light["position"], -1.0)))
    if not distance > sphere["radius"] or not height > distance + sphere["radius"]:
        sys.exit(where + "the light outside the sphere and the sphere between the light and the floor")
    return s, light, sphere, quad, axis, height, distance, glass.get("ior", 1.5), floor.get("albedo", [0.5] * 3)


def camera_frame(cam):
    """A pinhole camera's frame (forward, right, up) and the tangents of its half field of view (x, y)."""
    forward = unit(add(cam["look_at"], cam["position"], -1.0))
    right = unit(cross(forward, cam["up"]))
    up = cross(right, forward)
    tan_y = math.tan(math.radians(cam.get("fov", 45.0)) * 0.5)
    return forward, right, up, tan_y * cam["width"] / cam["height"], tan_y


def quadrature(scene_path, film, jitters, table_rows=40000):
    """The image mean of the class per colour channel (albedo / pi E(rho) T_eye over the film), and its standard error."""
    s, light, sphere, quad, axis, height, distance, ior, albedo = quadrature_setup(scene_path)
    branches = caustic_table(distance, sphere["radius"], ior, height, table_rows)
    cam = s["camera"]
    forward, right, up, tan_x, tan_y = camera_frame(cam)
    e1, e2 = quad["edge1"], quad["edge2"]
    normal = unit(cross(e1, e2))
    nx, ny = film
    means = []
    for jitter in range(jitters):
        rng = random.Random(jitter)
        total = 0.0  # of (1 / pi) E(rho) T_eye per unit intensity and albedo
        for iy in range(ny):
            for ix in range(nx):
                fx, fy = 2.0 * (ix + rng.random()) / nx - 1.0, 1.0 - 2.0 * (iy + rng.random()) / ny
                d = unit([f + fx * tan_x * r + fy * tan_y * u for f, r, u in zip(forward, right, up)])
                r = sphere_exit(cam["position"], d, sphere["center"], sphere["radius"], ior)
                if r is None:
                    continue
                p, d, t_eye = r
                denom = dot(d, normal)
                if denom == 0.0:
                    continue
                t = dot(add(quad["corner"], p, -1.0), normal) / denom
                if not t > 0.0:
                    continue
                x = add(add(p, d, t), quad["corner"], -1.0)
                a, b = dot(x, e1) / dot(e1, e1), dot(x, e2) / dot(e2, e2)
                if not (0.0 <= a <= 1.0 and 0.0 <= b <= 1.0):
                    continue
                off = add(add(x, quad["corner"]), light["position"], -1.0)
                rho = math.sqrt(max(0.0, dot(off, off) - dot(off, axis) ** 2))
                if rho > 0.0:
                    total += irradiance(branches, 1.0, rho) * t_eye / math.pi
        means.append(total / (nx * ny))
    scale = [i * a for i, a in zip(light["intensity"], albedo)]
    m, se = statistics.mean(means), statistics.stdev(means) / math.sqrt(len(means)) if len(means) > 1 else 0.0
    return [m * c for c in scale], [se * c for c in scale]


def luminance(rgb):
    return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--method", choices=("quadrature", "lamp"), default="quadrature")
    ap.add_argument("--scene", default=SCENE)
    ap.add_argument("--json", help="write the figures here")
    q = ap.add_argument_group("quadrature")
    q.add_argument("--film", default="768x384", help="film samples, columns x rows (one jittered sample per cell)")
    q.add_argument("--jitters", type=int, default=4, help="independent jitters of the grid (their spread: the stderr)")
    q.add_argument("--table", type=int, default=40000, help="rows of the table of rho(theta)")
    lamp = ap.add_argument_group("lamp")
    lamp.add_argument("--pathex", default=os.path.join(ROOT, "build", "pathex"))
    lamp.add_argument("--radii", default="0.4,0.2,0.1,0.05")
    lamp.add_argument("--seconds", default="60,240,480,600", help="render time per radius")
    lamp.add_argument("--seed", type=int, default=1)
    lamp.add_argument("--combine", nargs="+", metavar="JSON",
                      help="render nothing: fit the radii of these earlier --json outputs together (other seeds)")
    a = ap.parse_args()
    command = "python3 bench/manifold_reference.py " + " ".join(sys.argv[1:])
    scene = os.path.relpath(a.scene, ROOT)
    if a.method == "quadrature":
        try:
            film = tuple(int(v) for v in a.film.split("x"))
            if len(film) != 2 or min(film) < 1 or a.jitters < 2 or a.table < 100:
                raise ValueError
        except ValueError:
            sys.exit(f"--film: expected COLUMNSxROWS, --jitters at least 2, --table at least 100 (got {a.film}, {a.jitters}, {a.table})")
        rgb, se = quadrature(a.scene, film, a.jitters, a.table)
        print(f"quadrature {POINT_CLASS} {luminance(rgb):.6e} +- {luminance(se):.2e}   "
              f"({film[0]} x {film[1]} film samples, {a.jitters} jitters, {a.table} table rows)")
        if a.json:
            write_json(a.json, {"scene": scene, "class": POINT_CLASS, "method": "quadrature",
                                "reference": {"luminance": luminance(rgb), "stderr": luminance(se), "rgb": rgb},
                                "command": command, "film": list(film), "jitters": a.jitters, "table_rows": a.table})
        return

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
    model = "L0 + a r^2 + b r^4"  # even powers (the lamp is symmetric about the light's point), to r^4 (docstring)
    for name, powers in ((model, [0, 2, 4]), ("L0 + a r^2", [0, 2]), ("L0 + a r + b r^2", [0, 1, 2])):
        if len(usable) <= len(powers):
            continue
        coef, cov, chi2 = weighted_fit(xs, ys, ss, powers)
        fits[name] = {"L0": coef[0], "stderr": math.sqrt(cov[0][0]), "chi2": chi2, "dof": len(usable) - len(powers)}
        print(f"fit {name:<18} L0 = {coef[0]:.6e} +- {math.sqrt(cov[0][0]):.2e}   chi2 {chi2:.2f} / {len(usable) - len(powers)} dof")
    if a.json:
        reference = {"luminance": fits[model]["L0"], "stderr": fits[model]["stderr"], "fit": model} if model in fits else None
        write_json(a.json, {"scene": scene, "class": POINT_CLASS, "lamp_class": AREA_CLASS, "method": "lamp",
                            "reference": reference, "command": command, "seed": None if a.combine else a.seed,
                            "radii": rows, "fits": fits})


def write_json(path, value):
    with open(path, "w") as f:
        json.dump(value, f, indent=2)
        f.write("\n")


if __name__ == "__main__":
    main()
