#!/bin/bash
# Renders 25 scene/profile pairs with two pathex binaries and compares their histogram.json byte
# for byte: a refactoring of the tracer must leave every output as it was. The pairs cover every
# light kind (area, point, spot, laser, distant, image infinite), every sensor kind (pinhole, thin
# lens, orthographic, spot meter), the mirror, projection and manifold connectors, a textured pbrt
# scene and a Mitsuba scene (issue 37, eighth session).
#
#   bash bench/identical_outputs.sh OLD/pathex build/pathex
set -eu
[ $# -eq 2 ] || { echo "usage: $0 OLD/pathex NEW/pathex" >&2; exit 2; }
S=$(cd "$(dirname "$0")/../samples/scenes" && pwd)
W=$(mktemp -d /tmp/identical-XXXXXX)
trap 'rm -rf "$W"' EXIT
cp -r "$S/include" "$S/meshes" "$W/"
# The variants no sample scene has: the Cornell box with a spot light, with a thin lens, and
# with a checkerboard-textured white.
python3 - "$S" "$W" <<'PY'
import json, sys
s, w = sys.argv[1], sys.argv[2]
d = json.load(open(f"{s}/cornell.json"))
spot = json.loads(json.dumps(d))
spot.setdefault("lights", []).append({"type": "spot", "position": [0, 1.8, 0.5], "direction": [0, -1, -0.2],
                                      "intensity": [3, 3, 3], "cone": 40, "falloff_start": 25})
json.dump(spot, open(f"{w}/cornell-spot.json", "w"))
d["camera"].update({"type": "lens", "aperture_radius": 0.05, "focus_distance": 3.0})
json.dump(d, open(f"{w}/cornell-lens.json", "w"))
pbrt = open(f"{s}/cornell.pbrt").read().replace(
    'Include "include/cornell-materials.pbrt"',
    'Include "include/cornell-materials.pbrt"\n'
    'Texture "checks" "spectrum" "checkerboard" "float uscale" 8 "float vscale" 8 "rgb tex1" [0.8 0.8 0.8] "rgb tex2" [0.2 0.3 0.6]\n'
    'MakeNamedMaterial "white" "string type" "diffuse" "texture reflectance" "checks"')
open(f"{w}/textured.pbrt", "w").write(pbrt)
PY
pairs=(
  "cornell:$S/cornell.json:bdpt:16" "cornell-ptnee:$S/cornell.json:pt-nee:16" "cornell-lt:$S/cornell.json:lt:16"
  "cornell-pt:$S/cornell.json:pt:16" "cornell-spot:$W/cornell-spot.json:bdpt:8" "cornell-spot-ptnee:$W/cornell-spot.json:pt-nee:8"
  "cornell-lens:$W/cornell-lens.json:bdpt:8" "cornell-lens-lt:$W/cornell-lens.json:lt:8" "point-plane:$S/point-plane.json:bdpt:8"
  "laser:$S/laser.json:bdpt:8" "sun-window:$S/sun-window.json:bdpt:8" "sun-window-distant:$S/sun-window.json:pt-nee+distant:8"
  "sky-image:$S/sky-image.json:bdpt:4" "sky-glass:$S/sky-glass.json:pt-nee:4" "mirror-ortho:$S/mirror-ortho.json:bdpt+ortho:8"
  "spotmeter:$S/spotmeter-caustic.json:bdpt:64" "mirror-caustic:$S/point-mirror-caustic.json:pt-nee+mirror:8"
  "mirror-caustic-bdpt:$S/point-mirror-caustic.json:bdpt+mirror:8" "point-glass-manifold:$S/point-glass.json:pt-nee+manifold:4"
  "lamp-glass-bdpt-manifold:$S/lamp-glass.json:bdpt+manifold:2" "materials:$S/materials.json:bdpt:4"
  "closed-sphere-point:$S/closed-sphere-point.json:bdpt:8" "textured:$W/textured.pbrt:bdpt:8"
  "textured-ptnee:$W/textured.pbrt:pt-nee:8" "cornell-xml:$S/cornell.xml:bdpt:8")
differ=0
for p in "${pairs[@]}"; do
  IFS=: read -r name scene renderer spp <<< "$p"
  for side in old new; do
    bin=$1; [ $side = new ] && bin=$2
    "$bin" trace "$scene" --renderer "$renderer" --spp "$spp" --threads 2 --no-images --quiet --out "$W/$side-$name" > /dev/null
  done
  cmp -s "$W/old-$name/histogram.json" "$W/new-$name/histogram.json" || { echo "differs: $name"; differ=$((differ + 1)); }
done
echo "${#pairs[@]} pairs, $differ differ"
[ $differ -eq 0 ]
