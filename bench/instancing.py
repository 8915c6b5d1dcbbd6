#!/usr/bin/env python3
"""Instancing's memory (issue 34): one binary PLY mesh of 100,000 triangles (a planar grid of 251 x 201
vertices), placed N times by pbrt-v4 ObjectInstance (one copy of the mesh, N Embree instances) and,
for comparison, N times as its own Shape (N copies: the flattened scene). Each scene is rendered by
`pathex trace` at 16 x 16 pixels and 1 spp (the import, Embree's build, a tiny render); printed: the
peak resident memory (ru_maxrss) and CPU seconds of each. The flattened scenes stop at 100 copies
(1,000 would be 100 million triangles, beyond --max-mesh-elements' default and this machine's share).

    python3 bench/instancing.py build/pathex [WORK_DIR]
"""
import argparse
import array
import os
import subprocess
import sys

W, H = 251, 201  # vertices per row, rows: 250 x 200 quads, 100,000 triangles


def write_mesh(work):
    os.makedirs(work, exist_ok=True)
    ply = os.path.join(work, "grid.ply")
    if not os.path.exists(ply):
        header = ("ply\nformat binary_little_endian 1.0\ncomment bench/instancing.py\n"
                  f"element vertex {W * H}\nproperty float x\nproperty float y\nproperty float z\n"
                  f"element face {2 * (W - 1) * (H - 1)}\nproperty list uchar uint vertex_indices\nend_header\n")
        positions = array.array("f")
        for j in range(H):
            for i in range(W):
                positions.extend((i / (W - 1) - 0.5, j / (H - 1) - 0.5, 0.0))
        with open(ply, "wb") as f:
            f.write(header.encode())
            if sys.byteorder != "little":
                positions.byteswap()
            positions.tofile(f)
            for j in range(H - 1):
                for i in range(W - 1):
                    a = j * W + i
                    for tri in ((a, a + 1, a + 1 + W), (a, a + 1 + W, a + W)):
                        f.write(bytes([3]))
                        idx = array.array("I", tri)
                        if sys.byteorder != "little":
                            idx.byteswap()
                        idx.tofile(f)
    return ply


def write_scene(work, n, instanced):
    path = os.path.join(work, f"{'instanced' if instanced else 'flat'}-{n}.pbrt")
    with open(path, "w") as f:
        f.write('Scale -1 1 1\nLookAt 0 0 30  0 0 0  0 1 0\nCamera "perspective" "float fov" 60\n'
                'Film "rgb" "integer xresolution" 16 "integer yresolution" 16\nWorldBegin\n'
                'LightSource "point" "rgb I" [50 50 50] "point3 from" [0 0 25]\n')
        if instanced:
            f.write('ObjectBegin "grid"\nShape "plymesh" "string filename" "grid.ply"\nObjectEnd\n')
        for k in range(n):  # a 10 x 10 x 10 block of places
            x, y, z = k % 10, (k // 10) % 10, k // 100
            f.write(f"AttributeBegin\nTranslate {1.1 * x - 5} {1.1 * y - 5} {-z}\n")
            f.write('ObjectInstance "grid"\n' if instanced else 'Shape "plymesh" "string filename" "grid.ply"\n')
            f.write("AttributeEnd\n")
    return path


def run(args):
    proc = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    err = proc.stderr.read().decode()
    code = os.waitstatus_to_exitcode(status)
    if code != 0:
        sys.exit(f"{' '.join(args)}: exit {code}: {err}")
    return usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024.0


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("pathex")
    p.add_argument("work", nargs="?", default="build/bench-instancing")
    a = p.parse_args()
    write_mesh(a.work)
    print("scene: N x a 100,000-triangle mesh; pathex trace 16x16, 1 spp")
    for instanced, counts in ((True, (1, 100, 1000)), (False, (1, 10, 100))):
        for n in counts:
            scene = write_scene(a.work, n, instanced)
            cpu, rss = run([a.pathex, "trace", scene, "--spp", "1", "--quiet", "--no-images", "--out", os.path.join(a.work, "out")])
            print(f"{'instanced' if instanced else 'flattened'} N = {n:4d}: peak resident {rss:7.0f} MiB, {cpu:6.2f} s CPU")


if __name__ == "__main__":
    main()
