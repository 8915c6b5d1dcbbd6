#!/usr/bin/env python3
"""Splits a perf profile of build/bench/layers_ab_bench by its PHASE lines into the runs with and
without class layers and prints, per function, the samples each side spent there (see the
header of layers_ab_bench.cpp). Usage: phase_perf.py PERF_DATA PHASES_TXT [ROWS]"""
import bisect
import collections
import subprocess
import sys


def main():
    data, phases_file = sys.argv[1], sys.argv[2]
    rows = int(sys.argv[3]) if len(sys.argv) > 3 else 25
    phases = []
    with open(phases_file) as f:
        for line in f:
            if line.startswith('PHASE '):
                _, side, start, end = line.split()
                phases.append((float(start), float(end), int(side)))
    if not phases:
        sys.exit('no PHASE lines in %s (run layers_ab_bench with --phases)' % phases_file)
    phases.sort()
    starts = [p[0] for p in phases]
    script = subprocess.run(['perf', 'script', '-i', data, '-F', 'time,ip,sym', '--ns'],
                            capture_output=True, text=True, check=True).stdout
    counts = [collections.Counter(), collections.Counter()]
    totals = [0, 0]
    for line in script.splitlines():
        stamp, _, rest = line.strip().partition(':')
        try:
            t = float(stamp)
        except ValueError:
            continue
        i = bisect.bisect_right(starts, t) - 1
        if i < 0 or t > phases[i][1]:
            continue  # between renders
        parts = rest.split(None, 1)
        symbol = parts[1] if len(parts) > 1 else '[unknown]'
        side = phases[i][2]
        counts[side][symbol] += 1
        totals[side] += 1
    if not totals[0]:
        sys.exit('no samples inside the renders without layers')
    print('samples: without layers %d, with %d (%+.2f %%)' %
          (totals[0], totals[1], 100.0 * (totals[1] - totals[0]) / totals[0]))
    print('difference (% of the side without)  without  with  function')
    symbols = set(counts[0]) | set(counts[1])
    for s in sorted(symbols, key=lambda s: -abs(counts[1][s] - counts[0][s]))[:rows]:
        print('%+8.2f %%  %8d %8d  %s' % (100.0 * (counts[1][s] - counts[0][s]) / totals[0], counts[0][s],
                                          counts[1][s], s[:100]))


if __name__ == '__main__':
    main()
