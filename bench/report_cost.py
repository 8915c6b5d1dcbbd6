#!/usr/bin/env python3
"""report.html of the default scene: its size (target < 2 MB) and the time it takes against the
default render's (target < 10 %), issue 41.

Each round runs the default `pathex trace --report` (the embedded Cornell box, 16 spp) and reads
  - the time trace spent writing report.html (the "wrote DIR/report.html in N ms" line: the report
    built from what trace holds, inside the output set) against the render's time (run.json's
    time_s, the wall time of render()), and
  - `pathex report DIR` on the same folder, the whole process (start-up, reading histogram.json,
    classes.exr, render.shard, asking the checker, writing) against the whole `pathex trace` process,
both wall time (the rounds interleave the two commands, so a busy neighbour slows both), and the
size of report.html.

    python3 bench/report_cost.py build/pathex [--rounds 7] [trace arguments...]
"""
import json, os, re, statistics, subprocess, sys, tempfile, time


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    pathex = sys.argv[1]
    args = sys.argv[2:]
    rounds = 7
    if args[:1] == ['--rounds']:
        rounds = int(args[1])
        args = args[2:]
    inproc, standalone, sizes = [], [], []
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, 'out')
        for i in range(rounds):
            t0 = time.perf_counter()
            r = subprocess.run([pathex, 'trace', *args, '--quiet', '--report', '--out', out], check=True,
                               capture_output=True, text=True)
            trace_wall = time.perf_counter() - t0
            m = re.search(r'wrote .*/report\.html in ([0-9.]+) ms', r.stdout)
            if not m:
                sys.exit('no report line in:\n' + r.stdout)
            report_ms = float(m.group(1))
            render_s = json.load(open(os.path.join(out, 'run.json')))['time_s']
            size = os.path.getsize(os.path.join(out, 'report.html'))
            t0 = time.perf_counter()
            subprocess.run([pathex, 'report', out], check=True, stdout=subprocess.DEVNULL)
            report_wall = time.perf_counter() - t0
            a = 100.0 * report_ms / (1000.0 * render_s)
            b = 100.0 * report_wall / trace_wall
            inproc.append(a)
            standalone.append(b)
            sizes.append(size)
            print('round %d: trace --report wrote it in %.1f ms, render %.1f ms: %.1f %%; pathex report %.1f ms, '
                  'pathex trace %.1f ms: %.1f %%; report.html %d bytes' %
                  (i + 1, report_ms, 1000 * render_s, a, 1000 * report_wall, 1000 * trace_wall, b, size))
    print('trace --report: the report takes median %.1f %% (min %.1f, max %.1f) of the render\'s time (target < 10 %%)' %
          (statistics.median(inproc), min(inproc), max(inproc)))
    print('pathex report, whole process: median %.1f %% (min %.1f, max %.1f) of pathex trace\'s' %
          (statistics.median(standalone), min(standalone), max(standalone)))
    print('report.html: %d bytes (%.2f MB; target < 2 MB)' % (max(sizes), max(sizes) / 1e6))


if __name__ == '__main__':
    main()
