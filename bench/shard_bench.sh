#!/usr/bin/env bash
# Scale-out figures (issue 16), from the build in ./build:
#   merge    `pathex merge` of 16 shards of a 512 x 512 render with the twenty classes
#            (samples/classes/twenty.json), median wall and CPU time of 3 merges (target < 2 s);
#   size     the shard files against the outputs of the same render (target <= 2x): the
#            single render's render.shard against its histogram.json + classes.exr + PNGs, and
#            the 16 shards' files against theirs;
#   mpi      `mpirun -n 2 pathex-mpi trace --threads 1` against `pathex trace --threads 1`, the
#            two run alternately ROUNDS times, wall time including process start; the speedup of
#            each pair and their median (target >= 1.8x). Skipped without build/pathex-mpi.
# Usage: bash bench/shard_bench.sh [merge|size|mpi|all] (default all). Scratch: $TMPDIR/pathex-shard-bench.
set -euo pipefail
cd "$(dirname "$0")/.."
what=${1:-all}
P=build/pathex
MPI=build/pathex-mpi
scene=bench/scenes/cornell-512.json
classes=samples/classes/twenty.json
work=${TMPDIR:-/tmp}/pathex-shard-bench
rounds=${ROUNDS:-5}
mkdir -p "$work"

now() { date +%s.%N; }
median() { sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}'; }
outputs_bytes() { (cd "$1" && cat histogram.json classes.exr ./*.png | wc -c); }

if [ "$what" = merge ] || [ "$what" = size ] || [ "$what" = all ]; then
  if [ ! -f "$work/s15/render.shard" ]; then
    echo "rendering 16 shards of $scene, 16 spp, 20 classes (one pass each) ..."
    for i in $(seq 0 15); do
      "$P" trace "$scene" --classes "$classes" --spp 16 --shard "$i/16" --quiet --out "$work/s$i" > /dev/null
    done
  fi
  if [ "$what" != size ]; then
    times=(); cpus=()
    for r in 1 2 3; do
      rm -rf "$work/merged"
      /usr/bin/time -f '%e %U %S' -o "$work/time.txt" "$P" merge "$work"/s{0..15} --quiet --out "$work/merged"
      read -r wall user sys < "$work/time.txt"
      times+=("$wall"); cpus+=("$(echo "$user + $sys" | bc -l)")
    done
    printf 'merge of 16 shards (512x512, 20 classes, 16 spp): wall %s s, CPU (user + sys) %s s (medians of 3; load average %s)\n' \
      "$(printf '%s\n' "${times[@]}" | median)" "$(printf '%s\n' "${cpus[@]}" | median)" "$(cut -d' ' -f1-3 /proc/loadavg)"
  fi
  if [ "$what" != merge ]; then
    [ -f "$work/merged/render.shard" ] || "$P" merge "$work"/s{0..15} --quiet --out "$work/merged"
    shard=$(wc -c < "$work/merged/render.shard")
    out=$(outputs_bytes "$work/merged")
    echo "render.shard of the 16-spp render: $shard bytes; its outputs: $out bytes; ratio $(echo "scale=3; $shard / $out" | bc -l)"
    shards=0; outs=0
    for i in $(seq 0 15); do
      shards=$((shards + $(wc -c < "$work/s$i/render.shard")))
      outs=$((outs + $(outputs_bytes "$work/s$i")))
    done
    echo "the 16 shards' files: $shards bytes; their outputs: $outs bytes; ratio $(echo "scale=3; $shards / $outs" | bc -l)"
  fi
fi

if [ "$what" = mpi ] || [ "$what" = all ]; then
  if [ ! -x "$MPI" ]; then
    echo "mpi: skipped ($MPI is not built: MPI was not found at configure time)"
  else
    args=(trace samples/scenes/cornell.json --spp "${SPP:-256}" --threads 1 --quiet)
    speedups=()
    for r in $(seq 1 "$rounds"); do
      t0=$(now); "$P" "${args[@]}" --out "$work/one" > /dev/null; t1=$(now)
      mpirun --oversubscribe --allow-run-as-root -n 2 "$MPI" "${args[@]}" --out "$work/two" > /dev/null; t2=$(now)
      one=$(echo "$t1 - $t0" | bc -l); two=$(echo "$t2 - $t1" | bc -l)
      cmp -s "$work/one/histogram.json" "$work/two/histogram.json" || { echo "mpi: outputs differ"; exit 1; }
      speedups+=("$(echo "$one / $two" | bc -l)")
      printf 'round %d: 1 process %.2f s, 2 ranks %.2f s, speedup %.3f\n' "$r" "$one" "$two" "${speedups[-1]}"
    done
    printf 'mpi 2 ranks x 1 thread against 1 process x 1 thread: median speedup %.3f (load average %s)\n' \
      "$(printf '%s\n' "${speedups[@]}" | median)" "$(cut -d' ' -f1-3 /proc/loadavg)"
  fi
fi
