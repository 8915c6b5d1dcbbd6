#!/usr/bin/env bash
# bench/fuzz.sh SECONDS [HARNESS...]: installs clang-14 and builds the libFuzzer harnesses
# (`setup.sh --fuzz`, fuzz/), then runs each in
# turn, one at a time, SECONDS in total split evenly (default: all ten harnesses: expression,
# class_file, profile, check_file, scene, obj, pbrt, mitsuba, ply, serialized). Each starts from its seed corpus
# (made here from grammar/corpus/, tests/scene/bad/, tests/reach/checks/, samples/, issue 42's
# hostile scenes and PLY files generated here in each format) and its dictionary
# (fuzz/dict/). Each harness runs under small limits (fuzz_support.h), so that one input costs
# milliseconds and an input past 5 s (-timeout) is a hang the work budget missed; a process over
# 1 GiB (-rss_limit_mb) is a finding too. libFuzzer runs in fork mode and keeps going after a
# finding; findings (crash-*, timeout-*, oom-*, leak-*) land in build-fuzz/findings/HARNESS/, the
# grown corpora in build-fuzz/corpus/HARNESS/, libFuzzer's log in build-fuzz/findings/HARNESS.log.
# Prints each harness's executions and exits 1 when there are findings.
#   bash bench/fuzz.sh 3600
set -euo pipefail
cd "$(dirname "$0")/.."
total=${1:?usage: bench/fuzz.sh SECONDS [HARNESS...]}
shift
harnesses=("$@")
[ ${#harnesses[@]} -gt 0 ] || harnesses=(expression class_file profile check_file scene obj pbrt mitsuba ply serialized)
per=$(( total / ${#harnesses[@]} ))
[ "$per" -ge 1 ] || per=1

[ -f build-fuzz/CMakeCache.txt ] || bash setup.sh --fuzz  # the first run installs clang-14 and configures
cmake --build build-fuzz -j2 --target $(printf 'fuzz_%s ' "${harnesses[@]}") >/dev/null

# --- seed corpora ---
seeds=build-fuzz/seeds
rm -rf "$seeds"
mkdir -p "$seeds"/{expression,class_file,profile,check_file,scene,obj,pbrt,mitsuba,ply,serialized}
python3 - "$seeds" <<'PY'
import json, pathlib, sys
seeds = pathlib.Path(sys.argv[1])
exprs = []
for f in ("grammar/corpus/valid.json", "grammar/corpus/invalid.json"):
    exprs += [e["expr"] for e in json.loads(pathlib.Path(f).read_text())]
for i, e in enumerate(exprs):
    (seeds / "expression" / f"corpus-{i}").write_text(e)
    entry = {"classes": [{"name": f"c{i}", "expr": e}, {"name": "h", "expr": "LSDE", "notation": "heckbert"}]}
    (seeds / "class_file" / f"corpus-{i}.json").write_text(json.dumps(entry))
# Issue 42's reproducers, small (tests/scene/hostile_test.cpp has them all).
head = 'LookAt 0 1 3  0 1 0  0 1 0\nCamera "perspective" "float fov" 40\nWorldBegin\nLightSource "point"\n'
pbrt = {
    "brackets": "WorldBegin\n" + "[" * 1000,
    "include-dot": head + 'Include "."\n',
    "include-zero": head + 'Include "/dev/zero"\n',
    "projective": head + 'Transform [1 0 0 0  0 1 0 0  0 0 1 1  0 0 0 1]\nShape "sphere"\n',
    "negative-k": head + 'Material "conductor" "rgb eta" [1 1 1] "rgb k" [-1 0 0]\nShape "sphere"\n',
    "two-cameras": 'Camera "perspective"\nCamera "orthographic"\nWorldBegin\nLightSource "point"\nShape "sphere"\n',
    "mix": head + 'MakeNamedMaterial "m2" "string type" "diffuse"\n' + "".join(
        f'MakeNamedMaterial "m{i}" "string type" "mix" "string materials" ["m{i + 1}" "m{i + 1}"]\n' for i in (1, 0))
        + 'NamedMaterial "m0"\nShape "sphere"\n',
}
xml = {
    "self-ref": '<scene version="3.0.0"><bsdf type="twosided" id="a"><ref id="a"/></bsdf><shape type="sphere"><ref id="a"/></shape></scene>',
    "nested": '<scene version="3.0.0"><shape type="sphere">' + '<bsdf type="twosided">' * 70 + '<bsdf type="diffuse"/>' + '</bsdf>' * 70 + '</shape></scene>',
    "duplicates": '<scene version="3.0.0"><bsdf type="diffuse" id="a"/><shape type="sphere" type="disk" id="a"/></scene><scene/>',
    "blend": '<scene version="3.0.0"><emitter type="point"/><bsdf type="diffuse" id="b2"/>'
             '<bsdf type="blendbsdf" id="b1"><ref id="b2"/><ref id="b2"/></bsdf><bsdf type="blendbsdf" id="b0"><ref id="b1"/><ref id="b1"/></bsdf>'
             '<shape type="sphere"><ref id="b0"/><transform name="to_world"><matrix value="1 0 0 0 0 1 0 0 0 0 1 0 0 0 1 1"/></transform></shape></scene>',
}
for name, text in pbrt.items():
    (seeds / "pbrt" / f"{name}.pbrt").write_text(text)
for name, text in xml.items():
    (seeds / "mitsuba" / f"{name}.xml").write_text(text)
# PLY: a triangle and a quad in each format, with and without normals, uv and skipped properties.
import gzip, struct
for fmt in ("ascii", "binary_little_endian", "binary_big_endian"):
    for extras in (False, True):
        head = f"ply\nformat {fmt} 1.0\nelement vertex 5\n" + "".join(f"property float {c}\n" for c in "xyz")
        if extras:
            head += "property float nx\nproperty float ny\nproperty float nz\nproperty float u\nproperty float v\nproperty list uchar int junk\n"
            head += "element edge 1\nproperty int a\nproperty list ushort double w\n"
        head += "element face 2\nproperty list uchar int vertex_indices\n" + ("property short flag\n" if extras else "") + "end_header\n"
        verts = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0.5, 0.5, 0)]
        rows = []
        for v in verts:
            rows.append([("f", x) for x in v] + ([("f", 0), ("f", 0), ("f", 1), ("f", v[0]), ("f", v[1]), ("B", 1), ("i", 7)] if extras else []))
        if extras:
            rows.append([("i", 3), ("H", 2), ("d", 0.5), ("d", 1e300)])
        for face in ((0, 1, 2), (0, 2, 3, 4)):
            rows.append([("B", len(face))] + [("i", i) for i in face] + ([("h", -1)] if extras else []))
        if fmt == "ascii":
            body = "".join(" ".join(repr(x) for _, x in r) + "\n" for r in rows).encode()
        else:
            e = "<" if fmt == "binary_little_endian" else ">"
            body = b"".join(struct.pack(e + t, x) for r in rows for t, x in r)
        data = head.encode() + body
        name = f"{fmt}{'-extras' if extras else ''}"
        (seeds / "ply" / f"{name}.ply").write_bytes(data)
        (seeds / "ply" / f"{name}.ply.gz").write_bytes(gzip.compress(data))
# Mitsuba serialized (scene/serialized.h): versions 3 and 4, one and two shapes, single and double
# precision, with normals, uv and colours.
import zlib
def shape(version, double, extras):
    flags = (0x2000 if double else 0x1000) | (0x000B if extras else 0)
    f = "d" if double else "f"
    d = struct.pack("<I", flags) + (b"quad\0" if version == 4 else b"") + struct.pack("<QQ", 4, 2)
    d += struct.pack("<12" + f, 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0)
    if extras:
        d += struct.pack("<12" + f, *([0, 0, 1] * 4)) + struct.pack("<8" + f, 0, 0, 1, 0, 1, 1, 0, 1) + struct.pack("<12" + f, *([1] * 12))
    d += struct.pack("<6I", 0, 1, 2, 0, 2, 3)
    return struct.pack("<HH", 0x041C, version) + zlib.compress(d)
for version in (3, 4):
    for double in (False, True):
        for count in (1, 2):
            shapes = [shape(version, double, i % 2 == 1) for i in range(count)]
            offsets, body = [], b""
            for s in shapes:
                offsets.append(len(body))
                body += s
            table = b"".join(struct.pack("<Q" if version == 4 else "<I", o) for o in offsets) + struct.pack("<I", count)
            (seeds / "serialized" / f"v{version}-{'double' if double else 'single'}-{count}.serialized").write_bytes(body + table)
PY
cp samples/classes/*.json "$seeds/class_file/"
cp samples/renderers/*.json "$seeds/profile/"
cp samples/checks/*.json tests/reach/checks/*.json "$seeds/check_file/"
cp samples/scenes/*.json tests/scene/bad/*.json "$seeds/scene/"
cp tests/scene/bad/*.obj samples/scenes/meshes/*.obj "$seeds/obj/"
cp samples/scenes/*.pbrt samples/scenes/include/*.pbrt "$seeds/pbrt/"
cp samples/scenes/*.xml samples/scenes/include/*.xml "$seeds/mitsuba/"
cp samples/scenes/meshes/*.ply "$seeds/ply/"

# --- runs ---
status=0
for h in "${harnesses[@]}"; do
  mkdir -p "build-fuzz/corpus/$h" "build-fuzz/findings/$h"
  echo "fuzz_$h: $per s"
  before=$(find "build-fuzz/findings/$h" -type f | wc -l)  # earlier runs' findings stay
  TIMEFORMAT='%U+%S'  # the CPU seconds it got (user + system), fork-mode children included
  cpu=$( { time build-fuzz/fuzz/fuzz_$h -fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1 \
    -max_total_time="$per" -timeout=5 -close_fd_mask=1 -rss_limit_mb=1024 -dict="fuzz/dict/$h.dict" \
    -artifact_prefix="build-fuzz/findings/$h/" "build-fuzz/corpus/$h" "$seeds/$h" \
    > "build-fuzz/findings/$h.log" 2>&1 || true; } 2>&1 )
  n=$(( $(find "build-fuzz/findings/$h" -type f | wc -l) - before ))
  # fork mode's status lines: "#EXECS: cov: C ft: F corp: N exec/s R oom/timeout/crash: …"
  last=$(grep -E '^#[0-9]+: cov:' "build-fuzz/findings/$h.log" | tail -1)
  echo "fuzz_$h: $(sed -E 's/^#([0-9]+): cov: ([0-9]+).* exec\/s:? ([0-9]+).*/\1 executions (\3 per second), coverage \2/' <<<"$last"), $(awk -F+ '{printf "%.0f", $1 + $2}' <<<"$cpu") s of CPU, $n findings"
  [ "$n" -eq 0 ] || status=1
done
exit $status
