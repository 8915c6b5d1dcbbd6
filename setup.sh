#!/usr/bin/env bash
# Installs what pathex needs on a fresh Debian 12 machine (Debian packages only) and configures
# ./build (Release) and builds `pathex` in it (not the tests). Safe to run again: apt skips what is already there.
# `setup.sh --fuzz` also installs clang-14 with its runtimes (libFuzzer, ASan, UBSan) and
# configures the fuzz harnesses in ./build-fuzz (bench/fuzz.sh builds and runs them).
set -euo pipefail
cd "$(dirname "$0")"
fuzz=false
[ "${1:-}" = "--fuzz" ] && fuzz=true
packages=(build-essential cmake pkg-config
  libembree-dev libtbb-dev libglm-dev libcli11-dev nlohmann-json3-dev
  libtinyobjloader-dev libopenexr-dev libpng-dev zlib1g-dev libzstd-dev libopenmpi-dev openmpi-bin libcairo2-dev
  libopenimageio-dev
  libgtest-dev libgmock-dev libbenchmark-dev librapidcheck-dev libpugixml-dev
  groff-base
  chromium)  # the browser test of report.html (tests/output/report_browser_test.cpp)
if $fuzz; then packages+=(clang-14 libclang-rt-14-dev python3); fi
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
# The library, `pathex`, its man page and completion only, so that the first render comes early; the
# README's test command builds the rest (tests, benchmarks, pathex-mpi) with `cmake --build build`.
cmake --build build -j"$(nproc)" --target pathex pathex_docs
if $fuzz; then
  cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++-14 \
    -DCMAKE_CXX_FLAGS="-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer" \
    -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
    -DPATHEX_FUZZ=ON -DPATHEX_BUILD_TESTS=OFF -DPATHEX_BUILD_BENCH=OFF >/dev/null
fi
