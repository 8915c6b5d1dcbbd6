#!/usr/bin/env bash
# Start-up: what one `pathex` command costs before and besides its work. Runs each command N times
# (default 20) and prints the mean wall time per run:
#   --version                       the process alone (dynamic loading, static initialisers)
#   trace point-plane --spp 1       a scene with no image: the image decoder is not loaded
#   trace sky-image   --spp 1       a scene with an image: loads libpathex_image.so (OpenImageIO)
# The difference between the last two, less their renders' difference, is what OpenImageIO's
# libraries cost a process that needs them (src/io/image_file.h); the first is what every other
# command pays. Usage: bench/startup.sh [build/pathex] [N]
set -euo pipefail
cd "$(dirname "$0")/.."
exe=${1:-build/pathex}
n=${2:-20}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
mean_ms() {  # the mean wall time of n runs of "$@", in milliseconds
  local start end
  start=$(date +%s%N)
  for _ in $(seq "$n"); do "$@" >/dev/null 2>&1; done
  end=$(date +%s%N)
  echo $(( (end - start) / n / 1000000 ))
}
version=$(mean_ms "$exe" --version)
plain=$(mean_ms "$exe" trace samples/scenes/point-plane.json --spp 1 --quiet --no-images --out "$out/a")
image=$(mean_ms "$exe" trace samples/scenes/sky-image.json --spp 1 --quiet --no-images --out "$out/b")
echo "pathex --version                           ${version} ms a run (mean of $n)"
echo "trace point-plane.json --spp 1 (no image)  ${plain} ms"
echo "trace sky-image.json --spp 1 (an image)    ${image} ms"
