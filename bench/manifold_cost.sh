#!/bin/bash
# pt-nee+manifold's CPU time per sample against pt-nee's (issue 40), one thread pinned to CPU 1:
# each figure is the slope of CPU time (user + system) between two sample counts, so that loading
# and planning cancel; renderers interleaved within each round.
#
#   bash bench/manifold_cost.sh build/pathex [OLD/pathex] [ROUNDS]
#
# Prints per round, scene and configuration the milliseconds of CPU per sample per pixel of the
# whole image, then the medians and each manifold configuration's ratio to pt-nee.
set -euo pipefail
new=${1:?usage: manifold_cost.sh NEW/pathex [OLD/pathex] [ROUNDS]}
old=${2:-}
rounds=${3:-3}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
cpu() {  # binary scene renderer spp extra...
  local bin=$1 scene=$2 renderer=$3 spp=$4
  shift 4
  /usr/bin/time -f "%U %S" -o "$out/t" taskset -c 1 "$bin" trace "samples/scenes/$scene.json" --renderer "$renderer" \
    --spp "$spp" --threads 1 --out "$out/o" --no-images --quiet "$@" >/dev/null 2>&1
  awk '{print $1 + $2}' "$out/t"
}
configs=("new|$new|pt-nee+manifold|4|36|" "seeds1|$new|pt-nee+manifold|4|36|--manifold-seeds=1" "pt-nee|$new|pt-nee|16|400|")
[ -n "$old" ] && configs=("old|$old|pt-nee+manifold|4|36|" "${configs[@]}")
for round in $(seq "$rounds"); do
  for scene in point-glass lamp-glass; do
    for c in "${configs[@]}"; do
      IFS='|' read -r label bin renderer lo hi extra <<< "$c"
      a=$(cpu "$bin" "$scene" "$renderer" "$lo" $extra)
      b=$(cpu "$bin" "$scene" "$renderer" "$hi" $extra)
      echo "$round $scene $label $(python3 -c "print(f'{($b - $a) / ($hi - $lo) * 1e3:.3f}')")"
    done
  done
done | tee "$out/all"
python3 - "$out/all" <<'PY'
import statistics, sys
rows = [l.split() for l in open(sys.argv[1])]
med = {}
for scene in sorted({r[1] for r in rows}):
    for label in dict.fromkeys(r[2] for r in rows):
        v = [float(r[3]) for r in rows if r[1] == scene and r[2] == label]
        med[scene, label] = statistics.median(v)
    base = med[scene, "pt-nee"]
    print(scene, "  ".join(f"{l} {med[scene, l]:.3f} ms/spp ({med[scene, l] / base:.1f}x pt-nee)"
                          for l in dict.fromkeys(r[2] for r in rows) if l != "pt-nee"), f" pt-nee {base:.3f} ms/spp")
PY
