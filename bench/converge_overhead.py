#!/usr/bin/env python3
"""converge's overhead against its ladder (issue 13: < 2 %).

Runs `pathex converge` ROUNDS times and reports, per run, the CPU time inside render() (the
ladder, and the reference run when it makes one) against the rest of the process: start-up,
scene and class setup, the reference, the statistics, the plot (cairo, SVG and PNG) and writing
the output set. converge.json's "timing" gives the render time; the whole process's CPU time is measured from
here (getrusage of the child), so the overhead includes everything converge adds to its renders.
CPU time, because the machine is shared: wall time there measures the neighbours (printed too).

    python3 bench/converge_overhead.py build/pathex [--rounds 5] [converge arguments...]
"""
import json, os, resource, subprocess, sys, tempfile, time, statistics

def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    pathex = sys.argv[1]
    args = sys.argv[2:]
    rounds = 5
    if args[:1] == ['--rounds']:
        rounds = int(args[1]); args = args[2:]
    if not args:
        args = ['samples/scenes/closed-sphere-point.json', '--renderer', 'pt-nee', '--renderer', 'bdpt',
                '--spp', '16,64,256,1024', '--threads', '1']
    pcts = []
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(rounds):
            out = os.path.join(tmp, 'run%d' % i)
            r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
            t0 = time.perf_counter()
            subprocess.run([pathex, 'converge', *args, '--quiet', '--out', out], check=True, stdout=subprocess.DEVNULL)
            wall = time.perf_counter() - t0
            r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
            total = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
            timing = json.load(open(os.path.join(out, 'converge.json')))['timing']
            render = timing['render_cpu_s']
            pct = 100.0 * (total - render) / render
            pcts.append(pct)
            print('round %d: process CPU %.3f s, inside render() %.3f s, overhead %.2f %% (wall: process %.3f s, render %.3f s)' %
                  (i + 1, total, render, pct, wall, timing['render_wall_s']))
    print('overhead: median %.2f %%, min %.2f %%, max %.2f %% of the ladder (target < 2 %%)' %
          (statistics.median(pcts), min(pcts), max(pcts)))

if __name__ == '__main__':
    main()
