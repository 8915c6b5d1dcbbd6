#!/usr/bin/env python3
"""The caustics of samples/scenes/lamp-glass.json by a quadrature independent of the manifold walk.

The scene (issue 40): a spherical lamp of radius r and radiance Le, a glass sphere (radius R,
index n) resting on a diffuse floor, a pinhole camera. Two classes are computed:

  LDDSSDSSDSE  the caustic seen through the sphere (eye ray refracted in and out, floor, lamp
               light refracted in and out);
  LDDSSDDSE    the caustic seen directly (eye ray to the floor, lamp light through the sphere;
               --direct; bdpt reaches it by light tracing, a better reference).

A point source at S, D from the sphere's centre C, lights the floor through the sphere with a
field symmetric about the axis S -> C: in the meridian plane a ray at angle theta from the axis
refracts in and out (Fresnel transmittances T1 T2, unpolarized, as bsdf::fresnel_dielectric) and
leaves from p(theta) along d(theta). At a point X (axial coordinate z, distance rho from the
axis) the rays with rho(theta; z) = rho land, each carrying I T sin|theta| dtheta dphi onto the
axial cross-section rho |drho/dtheta| dtheta dphi; on the floor (normal m) the irradiance is
that times |d.m| / |d.axis|. rho(theta; z) = p_x + (z - p_y) d_x / d_y is read from a table of
p and d over theta in (-theta_max, theta_max) (sign changes, then linear interpolation; the slope
is the secant's).

The lamp: a sphere of uniform radiance sends intensity I = Le pi r^2 in every direction, its
lines being those within r of its centre. Its light is the sum of point sources over a disk of
radius r at the lamp's centre perpendicular to the axis, each moved onto the sphere of radius D
about C (so that one table serves all: the field of a source rotated about C is the field
rotated), each of intensity I / (disk samples). Only what the disk's orientation changes is
neglected: points of the footprint move by r (1 - cos theta) <= 1e-3 r.

The image mean per class is the average over the film (box pixels, as pathex: a jittered grid)
of (albedo / pi) E(X) T_eye; the spread of independent jitters (film and lamp) is the stderr.
It shares nothing with the walk but the scene and the Fresnel formula.

    python3 bench/manifold_lamp_reference.py [--film 96x80] [--lamp 16] [--jitters 4] [--direct] [--json out.json]
"""
import argparse
import json
import math
import os
import random
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from manifold_reference import add, camera_frame, cross, dot, luminance, sphere_exit, unit, write_json  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENE = os.path.join(ROOT, "samples", "scenes", "lamp-glass.json")
THROUGH, DIRECT = "LDDSSDSSDSE", "LDDSSDDSE"


def setup(scene_path):
    with open(scene_path) as f:
        s = json.load(f)
    where = f"{scene_path}: the quadrature needs "
    shapes = s.get("shapes", [])
    if s.get("lights"):
        sys.exit(where + "no light entries (the lamp is an emitting sphere)")
    lamps = [x for x in shapes if x.get("type") == "sphere" and "emission" in x]
    glass = [x for x in shapes if x.get("type") == "sphere" and "emission" not in x]
    quads = [x for x in shapes if x.get("type") == "quad"]
    if len(lamps) != 1 or len(glass) != 1 or len(quads) != 1 or len(shapes) != 3:
        sys.exit(where + "one emitting sphere, one glass sphere and one quad")
    gm, fm = s["materials"][glass[0]["material"]], s["materials"][quads[0]["material"]]
    if gm.get("type") != "dielectric" or "tint" in gm or fm.get("type") != "diffuse" or lamps[0].get("two_sided"):
        sys.exit(where + "a dielectric sphere (no tint), a diffuse quad and a one-sided lamp")
    if s["camera"].get("type", "pinhole") != "pinhole":
        sys.exit(where + "a pinhole camera")
    return s, lamps[0], glass[0], quads[0], gm.get("ior", 1.5), fm.get("albedo", [0.5] * 3)


def table(distance, radius, ior, rows):
    """Rows (theta, p_x, p_y, d_x, d_y, T) over (-theta_max, theta_max) in the meridian plane (light at
    the origin, the sphere's centre at (0, distance))."""
    theta_max = math.asin(radius / distance)
    out = []
    for k in range(rows):
        theta = (2.0 * (k + 0.5) / rows - 1.0) * theta_max
        r = sphere_exit([0.0, 0.0, 0.0], [math.sin(theta), math.cos(theta), 0.0], [0.0, distance, 0.0], radius, ior)
        if r is not None:
            p, d, t = r
            out.append((theta, p[0], p[1], d[0], d[1], t))
    return out


def irradiance(rows, source, centre, x, normal, intensity):
    """Irradiance at floor point x (normal `normal`) from a point source at `source` through the sphere."""
    axis = unit(add(centre, source, -1.0))
    v = add(x, source, -1.0)
    z = dot(v, axis)
    radial = add(v, axis, -z)
    rho = math.sqrt(dot(radial, radial))
    if not rho > 0.0:
        return 0.0
    e_rho = [c / rho for c in radial]
    e = 0.0
    prev = None
    for row in rows:
        theta, px, py, dx, dy, t = row
        ok = dy != 0.0 and (z - py) / dy > 0.0
        f = px + (z - py) * dx / dy - rho if ok else None
        if prev is not None and f is not None and prev[1] is not None and (f > 0.0) != (prev[1] > 0.0):
            (r0, f0), (r1, f1) = prev, (row, f)
            w = f0 / (f0 - f1)
            th, ddx, ddy, tt = ((1.0 - w) * r0[i] + w * r1[i] for i in (0, 3, 4, 5))
            slope = (f1 - f0) / (r1[0] - r0[0])  # drho/dtheta at fixed z
            d3 = add([ddx * c for c in e_rho], axis, ddy)
            e += intensity * tt * math.sin(abs(th)) / (rho * abs(slope)) * abs(dot(d3, normal)) / abs(ddy)
        prev = (row, f)
    return e


def lamp_sources(lamp, centre, count, rng):
    """`count` point sources standing for the lamp (stratified over its disk), on the sphere about `centre`
    through the lamp's centre."""
    s, r = lamp["center"], lamp["radius"]
    axis = unit(add(centre, s, -1.0))
    distance = math.sqrt(dot(add(centre, s, -1.0), add(centre, s, -1.0)))
    u = unit(cross(axis, [0.0, 1.0, 0.0] if abs(axis[1]) < 0.9 else [1.0, 0.0, 0.0]))
    w = cross(axis, u)
    n = max(1, int(math.sqrt(count)))
    out = []
    for i in range(n):
        for j in range(n):
            a = r * math.sqrt((i + rng.random()) / n)
            phi = 2.0 * math.pi * (j + rng.random()) / n
            q = add(add(s, u, a * math.cos(phi)), w, a * math.sin(phi))
            out.append(add(centre, unit(add(q, centre, -1.0)), distance))
    return out, distance


def quadrature(scene_path, film, lamp_samples, jitters, rows, direct, first_jitter=0):
    s, lamp, sphere, quad, ior, albedo = setup(scene_path)
    centre, radius = sphere["center"], sphere["radius"]
    le = lamp["emission"]
    cam = s["camera"]
    forward, right, up, tan_x, tan_y = camera_frame(cam)
    e1, e2 = quad["edge1"], quad["edge2"]
    normal = unit(cross(e1, e2))
    lamp_centre = lamp["center"]
    d0 = math.sqrt(dot(add(centre, lamp_centre, -1.0), add(centre, lamp_centre, -1.0)))
    tab = table(d0, radius, ior, rows)
    intensity = math.pi * lamp["radius"] ** 2  # per unit radiance
    nx, ny = film
    means = {THROUGH: [], DIRECT: []}
    for jitter in range(jitters):
        rng = random.Random(first_jitter + jitter)
        totals = {THROUGH: 0.0, DIRECT: 0.0}
        for iy in range(ny):
            for ix in range(nx):
                fx, fy = 2.0 * (ix + rng.random()) / nx - 1.0, 1.0 - 2.0 * (iy + rng.random()) / ny
                d = unit([f + fx * tan_x * r + fy * tan_y * u for f, r, u in zip(forward, right, up)])
                o = cam["position"]
                through = sphere_exit(o, d, centre, radius, ior)
                oc = add(o, centre, -1.0)
                b = dot(oc, d)
                hits_sphere = b * b - (dot(oc, oc) - radius * radius) > 0.0 and -b > 0.0
                if through is not None:
                    o, d, t_eye, cls = through[0], through[1], through[2], THROUGH
                elif not hits_sphere and direct:
                    t_eye, cls = 1.0, DIRECT
                else:
                    continue  # total internal reflection inside (another class), or --direct not asked
                denom = dot(d, normal)
                if denom == 0.0:
                    continue
                t = dot(add(quad["corner"], o, -1.0), normal) / denom
                if not t > 0.0:
                    continue
                x = add(o, d, t)
                rel = add(x, quad["corner"], -1.0)
                a, c = dot(rel, e1) / dot(e1, e1), dot(rel, e2) / dot(e2, e2)
                if not (0.0 <= a <= 1.0 and 0.0 <= c <= 1.0):
                    continue
                sources, _ = lamp_sources(lamp, centre, lamp_samples, rng)
                e = sum(irradiance(tab, src, centre, x, normal, intensity / len(sources)) for src in sources)
                totals[cls] += e * t_eye / math.pi
        for cls in totals:
            means[cls].append(totals[cls] / (nx * ny))
    out = {}
    for cls, m in means.items():
        scale = [l * a for l, a in zip(le, albedo)]
        mu, se = statistics.mean(m), statistics.stdev(m) / math.sqrt(len(m))
        out[cls] = ([mu * c for c in scale], [se * c for c in scale])
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scene", default=SCENE)
    ap.add_argument("--film", default="96x80", help="film samples, columns x rows (one jittered sample per cell)")
    ap.add_argument("--lamp", type=int, default=16, help="point sources standing for the lamp (a square)")
    ap.add_argument("--jitters", type=int, default=4)
    ap.add_argument("--table", type=int, default=2000, help="rows of the table over theta")
    ap.add_argument("--first-jitter", type=int, default=0, help="the first jitter's seed (runs with disjoint seeds combine)")
    ap.add_argument("--direct", action="store_true", help="also the caustic seen directly (slow: most of the film)")
    ap.add_argument("--json", help="write the figures here")
    a = ap.parse_args()
    try:
        film = tuple(int(v) for v in a.film.split("x"))
        if len(film) != 2 or min(film) < 1 or a.jitters < 2 or a.table < 100 or a.lamp < 1:
            raise ValueError
    except ValueError:
        sys.exit(f"--film: expected COLUMNSxROWS, --jitters at least 2, --table at least 100, --lamp at least 1 "
                 f"(got {a.film}, {a.jitters}, {a.table}, {a.lamp})")
    res = quadrature(a.scene, film, a.lamp, a.jitters, a.table, a.direct, a.first_jitter)
    if not a.direct:
        del res[DIRECT]
    command = "python3 bench/manifold_lamp_reference.py " + " ".join(sys.argv[1:])
    for cls, (rgb, se) in res.items():
        print(f"quadrature {cls} {luminance(rgb):.6e} +- {luminance(se):.2e}   "
              f"({film[0]} x {film[1]} film samples, {a.lamp} lamp points, {a.jitters} jitters, {a.table} table rows)")
    if a.json:
        write_json(a.json, {"scene": os.path.relpath(a.scene, ROOT), "method": "quadrature", "command": command,
                            "classes": {cls: {"luminance": luminance(rgb), "stderr": luminance(se), "rgb": rgb}
                                        for cls, (rgb, se) in res.items()},
                            "film": list(film), "lamp_points": a.lamp, "jitters": a.jitters, "first_jitter": a.first_jitter, "table_rows": a.table})


if __name__ == "__main__":
    main()
