#!/usr/bin/env bash
# Installs what pathex needs on a fresh Debian 12 machine (Debian packages only) and configures
# and builds it in ./build (Release). Safe to run again: apt skips what is already there.
set -euo pipefail
cd "$(dirname "$0")"
packages=(build-essential cmake pkg-config
  libembree-dev libtbb-dev libglm-dev libcli11-dev nlohmann-json3-dev
  libtinyobjloader-dev libopenexr-dev libpng-dev zlib1g-dev libopenmpi-dev openmpi-bin
  libgtest-dev libgmock-dev libbenchmark-dev librapidcheck-dev libpugixml-dev libassimp-dev)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  sudo_cmd=(); [ "$(id -u)" = 0 ] || sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq "${missing[@]}" >/dev/null
fi
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)"
