#!/usr/bin/env python3
"""pathex against Tungsten on Tungsten's Cornell box (issue 39): off-lamp and whole-image
efficiency 1 / (MSE x CPU s) of pt-nee, and its ratio to Tungsten's fixed figures.

    taskset -c 1 python3 bench/tungsten.py --pathex build/pathex --spp 16,64 --rounds 3 \\
        [--variant "LABEL:ARGS" ...] [--binary LABEL:PATH ...]

The scene is bench/scenes/tungsten-cornell-box.json (Tungsten's data/example-scenes/cornell-box,
256 x 256), 64 bounces. The reference is a --ref-spp pt-nee render by --ref (two independent
halves, cached as bench/efficiency.py caches them). The lamp is the pixels whose reference
luminance is above 5, dilated by 2 pixels (image_error --lamp-luminance 5 --border 2); "off" is
the rest. Every run is one process, one thread, the round's seed; CPU time is user + system
(os.wait4), start-up and writing included; "render" is the render's own CPU seconds as pathex
reports them in run.json's "cpu_s" (the scene's Embree build, the render, not reading the scene,
planning or writing the outputs). Tungsten's figure is samples per CPU-second of its render, so
the render-to-render ratio is the like-for-like one; both are printed. A variant may set its own
--max-bounces (else 64). Tungsten's figures were measured on this machine kind (issue 39) and are
fixed here:

    spp   off-lamp MSE   M samples / CPU s
    16    7.546e-5       2.33
    64    1.901e-5       2.40

Printed per spp and variant: median CPU s (process, render), M samples per CPU-second (process),
mean MSE (whole, off), the efficiency 1 / (mean MSE x median CPU s) whole and off, and off /
Tungsten's with the process's CPU and with the render's. Pin the whole run
to one CPU (taskset -c 1): the variants of a round run back to back, in an order that rotates.

The rate in the table above moves with the machine's state (issue 39: the same pathex read 2.20x
and 1.95x against it on two machines of the kind). --tungsten BIN runs Tungsten itself in every
round too, beside the variants on the same CPU (its own scene at 256 x 256, --spp, one thread, the
round's seed), and adds its rate in this run and pathex's off-lamp ratio against Tungsten's fixed
MSE at that rate ("same run"): only the speed is measured again, the MSE a sample is Tungsten's
algorithm's. Tungsten is built from its source, never committed here (bench/README.md, "Issue 39,
seventeenth session: Tungsten beside pathex in the same run"):

    taskset -c 1 python3 bench/tungsten.py ... --tungsten TUNGSTEN/build/tungsten \
        --tungsten-scene TUNGSTEN/data/example-scenes/cornell-box/scene.json
"""
import argparse
import json
import os
import re
import shlex
import statistics
import subprocess
import sys
import tempfile
from types import SimpleNamespace

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cli_ab import cpu_run  # noqa: E402
from efficiency import errors, reference, scene_args  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE = os.path.join(HERE, "scenes", "tungsten-cornell-box.json")
PIXELS = 256 * 256
# spp: (off-lamp MSE, samples per CPU-second), issue 39.
TUNGSTEN = {16: (7.546e-5, 2.33e6), 64: (1.901e-5, 2.40e6)}


def tungsten_efficiency(spp):
    mse, rate = TUNGSTEN[spp]
    return 1.0 / (mse * PIXELS * spp / rate)


def summary(rounds):
    """A variant's rounds (cpu, render cpu, mse, mse_off) as median CPU s, median render CPU s, mean MSE, mean MSE off."""
    return (statistics.median(x[0] for x in rounds), statistics.median(x[1] for x in rounds),
            statistics.fmean(x[2] for x in rounds), statistics.fmean(x[3] for x in rounds))


def tungsten_scene(source, work):
    """Tungsten's Cornell box as issue 39 measured it: 256 x 256, its output in the work folder."""
    with open(source) as f:
        scene = json.load(f)
    scene["camera"]["resolution"] = [256, 256]
    scene["renderer"].update(output_file=os.path.join(work, "tungsten.png"), overwrite_output_files=True,
                             enable_resume_render=False, checkpoint_interval="0", timeout="0")
    path = os.path.join(work, "tungsten-scene.json")
    with open(path, "w") as f:
        json.dump(scene, f)
    return path


def run_tungsten(binary, scene, spp, seed):
    """(process CPU s, render s as Tungsten prints it: one worker thread, so its render's CPU)."""
    proc = subprocess.Popen([binary, "-t", "1", "--spp", str(spp), "--seed", str(seed), scene],
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    out = proc.stdout.read().decode()
    _, status, usage = os.wait4(proc.pid, 0)
    proc.stdout.close()
    m = re.search(r"Render time (.*)", out)
    if os.waitstatus_to_exitcode(status) != 0 or not m:
        sys.exit(f"{binary} {scene}: failed or printed no render time:\n{out}")
    return usage.ru_utime + usage.ru_stime, tungsten_duration(m.group(1))


def tungsten_duration(text):
    """Seconds from Tungsten's StringUtils::durationToString: "0.41s" under a second, else
    "[Nd ][Nh ][Nm ]Ns Nms" (tungsten_duration("1s 628ms") == 1.628)."""
    units = {"d": 86400.0, "h": 3600.0, "m": 60.0, "s": 1.0, "ms": 1e-3}
    parts = re.findall(r"([0-9.eE+-]+)(ms|d|h|m|s)\b", text)
    if not parts:
        sys.exit(f"Tungsten's render time {text!r}: not a duration")
    return sum(float(n) * units[u] for n, u in parts)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--pathex", default=os.path.join(HERE, "..", "build", "pathex"))
    ap.add_argument("--variant", action="append", default=[],
                    help="LABEL:ARGS, --pathex with extra trace arguments (repeatable); without any, its defaults")
    ap.add_argument("--binary", action="append", default=[], help="LABEL:PATH, one more pathex with its defaults")
    ap.add_argument("--renderer", default="pt-nee")
    ap.add_argument("--spp", default="16,64")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--ref", default=None, help="binary for the reference (default: --pathex)")
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("--ref-threads", type=int, default=1)
    ap.add_argument("--image-error", default=os.path.join(HERE, "..", "build", "bench", "image_error"))
    ap.add_argument("--cache", default=os.path.expanduser("~/.cache/pathex-efficiency"))
    ap.add_argument("--tungsten", default=None, help="Tungsten's binary: run it in every round too (see above)")
    ap.add_argument("--tungsten-scene", default=None,
                    help="Tungsten's data/example-scenes/cornell-box/scene.json (with --tungsten)")
    args = ap.parse_args()
    if args.tungsten and not args.tungsten_scene:
        ap.error("--tungsten needs --tungsten-scene (Tungsten's data/example-scenes/cornell-box/scene.json)")
    variants = [(label, args.pathex, shlex.split(extra)) for label, _, extra in (v.partition(":") for v in args.variant)]
    if not variants:
        variants = [("pathex", args.pathex, [])]
    variants += [(label, path, []) for label, _, path in (b.partition(":") for b in args.binary)]
    ref_args = SimpleNamespace(resolution=None, max_bounces=64, ref_renderer="pt-nee", ref_spp=args.ref_spp,
                               cache=args.cache, ref=args.ref or args.pathex, ref_threads=args.ref_threads)
    with tempfile.TemporaryDirectory(prefix="pathex-tungsten-") as work:
        halves, _ = reference(ref_args, SCENE, work)
        t_scene = tungsten_scene(args.tungsten_scene, work) if args.tungsten else None
        for spp in (int(s) for s in args.spp.split(",")):
            runs = {label: [] for label, _, _ in variants}  # per round: (cpu, render cpu, mse, mse_off)
            t_runs = []  # per round: Tungsten's (process CPU, render s)
            for r in range(args.rounds):
                if t_scene and r % 2 == 0:  # before the variants in even rounds, after them in odd ones
                    t_runs.append(run_tungsten(args.tungsten, t_scene, spp, 1 + r))
                order = variants[r % len(variants):] + variants[:r % len(variants)]
                files, cpus = {}, {}
                for label, binary, extra in order:
                    out = os.path.join(work, f"{label}-{r}")
                    bounces = None if "--max-bounces" in extra else 64
                    cmd = ([binary, "trace"] + scene_args(SCENE, None, bounces) +
                           ["--renderer", args.renderer, "--spp", str(spp), "--seed", str(1 + r), "--threads", "1",
                            "--quiet", "--out", out] + extra)
                    cpus[label] = cpu_run(cmd)
                    with open(os.path.join(out, "run.json")) as f:
                        cpus[label] = (cpus[label], json.load(f)["cpu_s"])
                    files[label] = os.path.join(out, "classes.exr")
                if t_scene and r % 2 == 1:
                    t_runs.append(run_tungsten(args.tungsten, t_scene, spp, 1 + r))
                noise, errs = errors(args.image_error, halves, list(files.values()), 2, lamp_luminance=5)
                for label in files:
                    runs[label].append(cpus[label] + errs[files[label]])
            t = TUNGSTEN.get(spp)
            print(f"\nTungsten's Cornell box, {args.renderer}, {spp} spp, {args.rounds} rounds (reference noise "
                  f"{noise[0]:.3g} whole, {noise[1]:.3g} off)" +
                  (f"; Tungsten: off MSE {t[0]:.4g}, {t[1] / 1e6:.2f} M samples/CPU s, eff off "
                   f"{tungsten_efficiency(spp):.4g}" if t else ""))
            print(f"  {'variant':<16}{'CPU s':>7}{'render':>8}{'M smp/s':>9}{'MSE whole':>12}{'MSE off':>12}"
                  f"{'eff whole':>12}{'eff off':>12}{'off / Tungsten':>16}{'render / T.':>13}")
            for label, _, _ in variants:
                cpu, render, mse, mse_off = summary(runs[label])
                eff_off = 1.0 / (mse_off * cpu)
                vs = f"{eff_off / tungsten_efficiency(spp):.2f}x" if t else "-"
                vs_render = f"{1.0 / (mse_off * render) / tungsten_efficiency(spp):.2f}x" if t else "-"
                print(f"  {label:<16}{cpu:>7.3f}{render:>8.3f}{PIXELS * spp / cpu / 1e6:>9.3f}{mse:>12.4g}"
                      f"{mse_off:>12.4g}{1.0 / (mse * cpu):>12.4g}{eff_off:>12.4g}{vs:>16}{vs_render:>13}", flush=True)
            if t_runs and t:
                t_cpu = statistics.median(x[0] for x in t_runs)
                t_render = statistics.median(x[1] for x in t_runs)
                print(f"  Tungsten in this run: CPU s {t_cpu:.3f} (render {t_render:.3f}), "
                      f"{PIXELS * spp / t_cpu / 1e6:.3f} M samples/CPU s ({PIXELS * spp / t_render / 1e6:.3f} its render)"
                      f" against the fixed {t[1] / 1e6:.2f}; off / Tungsten at its MSE {t[0]:.4g} and this run's speed:")
                for label, _, _ in variants:
                    cpu, render, _, mse_off = summary(runs[label])
                    print(f"    {label:<16} process / process {t[0] * t_cpu / (mse_off * cpu):.2f}x, "
                          f"render / render {t[0] * t_render / (mse_off * render):.2f}x", flush=True)


if __name__ == "__main__":
    main()
