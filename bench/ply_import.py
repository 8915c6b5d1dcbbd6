#!/usr/bin/env python3
"""Import at scale (issue 34): a generated pbrt-v4 scene of one binary PLY mesh of about 10 million
triangles (a planar grid of 2237 x 2238 vertices, 5,001,932 quads split in two), read by
`pathex query --scene` (the import alone: files, PLY, scene rules) and by `pathex trace` at
16 x 16 pixels and 1 spp (the import, Embree's build of the mesh, a tiny render). Each is run
ROUNDS times; printed: the best CPU seconds (user + system, from os.wait4) and wall seconds, and
the peak resident memory (ru_maxrss). The PLY is 160 MB, so both runs raise --max-file-size.

    python3 bench/ply_import.py build/pathex [WORK_DIR]
"""
import argparse
import array
import os
import subprocess
import sys
import time

W, H = 2237, 2238  # vertices per row, rows


def write_scene(work):
    os.makedirs(work, exist_ok=True)
    ply = os.path.join(work, "grid.ply")
    if not os.path.exists(ply):
        quads = (W - 1) * (H - 1)
        header = ("ply\nformat binary_little_endian 1.0\ncomment bench/ply_import.py\n"
                  f"element vertex {W * H}\nproperty float x\nproperty float y\nproperty float z\n"
                  f"element face {quads}\nproperty list uint uint vertex_indices\nend_header\n")
        positions = array.array("f")
        for j in range(H):
            y = 2.0 * j / (H - 1) - 1.0
            for i in range(W):
                positions.extend((2.0 * i / (W - 1) - 1.0, y, 0.0))
        faces = array.array("I")
        for j in range(H - 1):
            row = j * W
            for i in range(W - 1):
                a = row + i
                faces.extend((4, a, a + 1, a + 1 + W, a + W))
        if sys.byteorder != "little":
            positions.byteswap()
            faces.byteswap()
        with open(ply, "wb") as f:
            f.write(header.encode())
            positions.tofile(f)
            faces.tofile(f)
    scene = os.path.join(work, "grid.pbrt")
    with open(scene, "w") as f:
        f.write('Scale -1 1 1\nLookAt 0 0 3  0 0 0  0 1 0\nCamera "perspective" "float fov" 60\n'
                'Film "rgb" "integer xresolution" 16 "integer yresolution" 16\nWorldBegin\n'
                'LightSource "point" "rgb I" [5 5 5] "point3 from" [0 0 2]\n'
                'Shape "plymesh" "string filename" "grid.ply"\n')
    return scene, os.path.getsize(ply)


def run(args):
    start = time.monotonic()
    proc = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.monotonic() - start
    err = proc.stderr.read().decode()
    code = os.waitstatus_to_exitcode(status)
    if code != 0:
        sys.exit(f"{' '.join(args)}: exit {code}: {err}")
    return usage.ru_utime + usage.ru_stime, wall, usage.ru_maxrss / 1024.0


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("pathex")
    p.add_argument("work", nargs="?", default="build/bench-ply")
    p.add_argument("--rounds", type=int, default=3)
    a = p.parse_args()
    scene, size = write_scene(a.work)
    print(f"{scene}: {2 * (W - 1) * (H - 1):,} triangles, {W * H:,} vertices, PLY {size / 1e6:.0f} MB")
    big = ["--max-file-size", str(size + 1)]
    for name, args in (("query --scene (import)", [a.pathex, "query", "--scene", scene, *big, "L.*E"]),
                       ("trace 16x16, 1 spp", [a.pathex, "trace", scene, "--spp", "1", "--quiet", "--no-images", *big,
                                               "--out", os.path.join(a.work, "out")])):
        runs = [run(args) for _ in range(a.rounds)]
        cpu = min(r[0] for r in runs)
        wall = min(r[1] for r in runs)
        rss = max(r[2] for r in runs)
        print(f"{name}: {cpu:.2f} s CPU, {wall:.2f} s wall (best of {a.rounds}), peak resident {rss:.0f} MiB")


if __name__ == "__main__":
    main()
