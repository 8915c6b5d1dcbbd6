#!/usr/bin/env python3
"""The hang reproducers of issues 17 and 42, each run through the pathex binary under default limits.

Every input here once ran for 10 to 110 s, grew to gigabytes, or crashed (issue 42's scene
importers: a stack overflow, a bad_alloc). Each must now finish with its answer or stop with a
message naming the option that bounds it, within 1 s. What is measured is each process's CPU time
(user + system, from os.wait4, the best of ROUNDS runs), not its wall time: on a shared machine
the wall time counts what the other processes do. Prints one row per reproducer and exits 1 if any
of them takes 1 s or more, or answers other than expected.

    python3 bench/hangs.py build/pathex
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

LIMIT_S = 1.0


def cases(tmp):
    """(name, pathex arguments, expected exit code, text the output or error must contain)."""
    def file(name, text):
        path = os.path.join(tmp, name)
        with open(path, "w") as f:
            f.write(text)
        return path

    many = {"name": "many", "strategies": [{"s": i, "t": "0.."} for i in range(400)]}
    chain = {"name": "long", "strategies": [{"s": 1, "chain": "D" + "S" * 4998 + "D", "t": "1..",
                                             "connector": "manifold"}]}
    cornell = json.load(open(os.path.join(os.path.dirname(__file__), "..", "samples", "scenes", "cornell.json")))
    base = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "samples", "scenes"))
    for s in cornell["shapes"]:  # the scene moves to tmp: its meshes stay where they are
        if s.get("type") == "mesh" and not os.path.isabs(s["file"]):
            s["file"] = os.path.join(base, s["file"])
    face = "".join(f"v {i} 0 {i % 7}\n" for i in range(2000)) + "f" + "".join(f" {1 + i % 2000}" for i in range(200000))
    big_face = dict(cornell, shapes=[{"type": "mesh", "file": file("big-face.obj", face + "\n"),
                                      "material": cornell["shapes"][0]["material"]}] + cornell["shapes"][1:])
    zero_mesh = dict(cornell, shapes=[{"type": "mesh", "file": "/dev/zero",
                                       "material": cornell["shapes"][0]["material"]}] + cornell["shapes"][1:])
    literal = "L" + "D" * 30000 + "E"
    # Issue 42: the pbrt-v4 and Mitsuba 3 importers under hostile input.
    head = 'LookAt 0 1 3  0 1 0  0 1 0\nCamera "perspective" "float fov" 40\nWorldBegin\nLightSource "point" "point3 from" [0 2 2]\n'
    sensor = ('<sensor type="perspective"><float name="fov" value="40"/><transform name="to_world">'
              '<lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform></sensor>'
              '<emitter type="point"><point name="position" x="0" y="3" z="3"/></emitter>')

    def mix_levels(n):
        return (head + f'MakeNamedMaterial "m{n}" "string type" "diffuse"\n' +
                "".join(f'MakeNamedMaterial "m{i}" "string type" "mix" "string materials" ["m{i + 1}" "m{i + 1}"]\n'
                        for i in range(n - 1, -1, -1)) + 'NamedMaterial "m0"\nShape "sphere"\n')
    blend40 = ('<scene version="3.0.0">' + sensor + '<bsdf type="diffuse" id="b40"/>' +
               "".join(f'<bsdf type="blendbsdf" id="b{i}"><ref id="b{i + 1}"/><ref id="b{i + 1}"/></bsdf>' for i in range(39, -1, -1)) +
               '<shape type="sphere"><ref id="b0"/></shape></scene>')
    scene = lambda path: ["query", "--scene", path, "L.*E"]
    issue42 = [
        ("pbrt: 16 Mi [ after WorldBegin", scene(file("brackets.pbrt", "WorldBegin\n" + "[" * (16 << 20))), 2,
         "expected a directive, found '['"),
        ("pbrt: Include \"/dev/zero\"", scene(file("zero.pbrt", head + 'Include "/dev/zero"\n')), 2, "--max-file-size"),
        ("Mitsuba: <include> /dev/zero", scene(file("zero.xml", '<scene version="3.0.0"><include filename="/dev/zero"/></scene>')), 2,
         "--max-file-size"),
        ("Mitsuba: a bsdf that refers to itself", scene(file("self.xml", '<scene version="3.0.0"><bsdf type="twosided" id="a"><ref id="a"/>'
                                                              '</bsdf><shape type="sphere"><ref id="a"/></shape></scene>')), 2,
         "cannot contain itself"),
        ("Mitsuba: 50,000 nested twosided", scene(file("twosided.xml", '<scene version="3.0.0"><shape type="sphere">' +
                                                          '<bsdf type="twosided">' * 50000 + '<bsdf type="diffuse"/>' + '</bsdf>' * 50000 +
                                                          '</shape></scene>')), 2, "--max-scene-depth"),
        ("Mitsuba: 100,000 nested blendbsdf", scene(file("blend.xml", '<scene version="3.0.0"><shape type="sphere">' +
                                                            '<bsdf type="blendbsdf"><bsdf type="diffuse"/>' * 100000 + '<bsdf type="diffuse"/>' +
                                                            '</bsdf>' * 100000 + '</shape></scene>')), 2, "--max-scene-depth"),
        ("pbrt: 40 levels of shared mix", scene(file("mix40.pbrt", mix_levels(40))), 0, "reachable"),
        ("pbrt: 10,000 levels of shared mix", scene(file("mix10000.pbrt", mix_levels(10000))), 0, "reachable"),
        ("Mitsuba: 40 levels of shared blendbsdf", scene(file("blend40.xml", blend40)), 0, "reachable"),
        ("pbrt: a 16 MiB directive name", scene(file("name.pbrt", "A" * (16 << 20) + "\n")), 2, "…' is not supported"),
    ]
    return [
        ("(S{1000}&D*){1000}", ["explain", "(S{1000}&D*){1000}"], 0, "language      empty"),
        ("L(.{7}){1000}E", ["explain", "--members", "0", "L(.{7}){1000}E"], 0, "language      finite"),
        ("$direct{1000}", ["explain", "$direct{1000}"], 0, "language      empty"),
        ("S{1000} (corpus seed)", ["explain", "S{1000}"], 0, "language      empty"),
        ("99 nested ~ (corpus seed)", ["explain", "~" * 99 + "S"], 0, "language      infinite"),
        ("100 nested ~ (corpus seed)", ["explain", "~" * 100 + "S"], 2, "--max-depth"),
        ("10,000 ( at the depth ceiling", ["explain", "--max-depth", "1000", "(" * 10000 + "S"], 2, "--max-depth"),
        ("100,000 * at the depth ceiling", ["explain", "--max-depth", "1000", "S" + "*" * 100000], 2, "--max-depth"),
        ("30,000-letter literal, explain", ["explain", literal], 0, "language      finite"),
        ("30,000-letter literal, match", ["match", literal, literal], 0, ""),
        ("profile of 400 strategies", ["query", "--renderer", file("many.json", json.dumps(many)), "L.*DD.*E"], 0,
         "partial"),
        ("5,000-letter chain", ["query", "--renderer", file("chain.json", json.dumps(chain)), "L.*E"], 2,
         "--max-work"),
        ("/dev/zero as a check file", ["check", "/dev/zero"], 2, "--max-file-size"),
        ("/dev/zero as a mesh", ["query", "--scene", file("zero-mesh.json", json.dumps(zero_mesh)), "L.*E"], 2,
         "--max-file-size"),
        ("OBJ face of 200,000 corners", ["query", "--scene", file("big-face.json", json.dumps(big_face)), "L.*E"], 2,
         "exceeds the limit of 1024"),
    ] + issue42


def run(cmd):
    """Exit code, output and error text, CPU seconds (user + system) and wall seconds of cmd."""
    before = os.times()
    proc = subprocess.run(cmd, capture_output=True)
    after = os.times()
    cpu = (after.children_user - before.children_user) + (after.children_system - before.children_system)
    text = proc.stdout.decode(errors="replace") + proc.stderr.decode(errors="replace")
    return proc.returncode, text, cpu, after.elapsed - before.elapsed


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("pathex", help="the pathex binary (build/pathex)")
    ap.add_argument("--rounds", type=int, default=3, help="runs of each reproducer; the best CPU time counts")
    args = ap.parse_args()
    failed = 0
    with tempfile.TemporaryDirectory(prefix="pathex-hangs-") as tmp:
        print(f"{'reproducer':38} {'exit':>4} {'CPU s':>7} {'wall s':>7}  stops with")
        for name, argv, code, expect in cases(tmp):
            runs = [run([args.pathex] + argv) for _ in range(args.rounds)]
            rc, text = runs[-1][0], runs[-1][1]
            best_cpu = min(r[2] for r in runs)
            best_wall = min(r[3] for r in runs)
            ok = rc == code and expect in text and best_cpu < LIMIT_S
            failed += not ok
            said = "(answers)" if rc == 0 else text.strip().splitlines()[0][:90] if text.strip() else ""
            print(f"{name:38} {rc:>4} {best_cpu:7.3f} {best_wall:7.3f}  {said}{'' if ok else '   <-- FAIL'}")
    print(f"{failed} of the reproducers over {LIMIT_S:g} s of CPU or not as expected" if failed else
          f"every reproducer within {LIMIT_S:g} s of CPU")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
