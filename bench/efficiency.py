#!/usr/bin/env python3
"""Efficiency 1 / (MSE x CPU s) of pathex renderers against a long reference render, old binary
against new, interleaved in one run (issue 19).

    python3 bench/efficiency.py --old /work/old-b2af2de/build/pathex --new build/pathex \\
        --resolution 256x256 --max-bounces 64 --renderers pt-nee,bdpt,lt --spp 16,64 --rounds 5

For every scene (default: the embedded Cornell box), renderer and spp, each round runs every
variant once (the old binary, then the new one: with its default settings when no `--variant` is
given, else with each `--variant LABEL:ARGS` only — give `--variant "new:"` for its defaults beside
others — and each `--binary`), in an order that rotates from round to round, each with the round's seed,
one thread, default outputs (classes.exr and the PNGs). CPU time is the process's user + system
time (os.wait4): start-up, rendering and writing, what a user waits for; the time the shared host
gives to others is not counted. The error is the per-pixel MSE of the image's "total" layer
against the reference (bench/image_error), over the whole image and off the directly seen
emitters (pixels within --border of one the reference's "emission" layer lights; see
image_error.cpp), minus the variance the reference still has (it is the mean of two independent
halves, whose difference measures it).

The reference is rendered once by the --ref binary (default: --old) with --ref-renderer at
--ref-spp, and kept in --cache (default ~/.cache/pathex-efficiency, outside git), keyed by scene
text, resolution, bounce bound, renderer and spp. `--ref-renderer NAME=RENDERER` (repeatable) gives
the scene file NAME (its base name) a reference renderer of its own: a reference must sample every
path the measured renderers do (pt-nee's misses light bdpt renders on sun-window.json and
point-glass.json, and a ratio against it is then a CPU ratio), e.g.
    --ref-renderer sun-window.json=bdpt --ref-renderer point-glass.json=bdpt

Printed per (scene, renderer, spp): the median efficiency of each variant, and per round the ratio
of each variant to the first (the old binary) with its median and range over rounds: rounds are
paired, so a slow round on a busy host moves both sides alike.

Then the efficiency ratio as defined, 1 / (E[MSE] x T): the mean MSE over rounds (an expectation;
on scenes with heavy-tailed error, such as a caustic, the per-round ratios' median and range
describe single seeds, not the estimator) times the median CPU seconds (robust to a busy host's
slow rounds), old over variant, with a 95 % bootstrap interval (rounds resampled in pairs, fixed
seed). Its interval narrows as rounds are added; the per-round range does not.
"""
import argparse
import hashlib
import json
import os
import random
import shlex
import statistics
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cli_ab import cpu_run  # noqa: E402  (the one CPU-time runner: user + system time from os.wait4)


def scene_args(scene, resolution, max_bounces):
    args = [scene] if scene else []
    if resolution:
        args += ["--resolution", resolution]
    if max_bounces is not None:
        args += ["--max-bounces", str(max_bounces)]
    return args


def ref_renderers(values):
    """(the default reference renderer, {scene base name: its own}) from the --ref-renderer values."""
    default, own = "pt-nee", {}
    for v in [values] if isinstance(values, str) else values:
        name, sep, renderer = v.rpartition("=")
        if sep:
            own[name] = renderer
        else:
            default = renderer
    return default, own


def reference(args, scene, work):
    """Paths of the two cached reference halves (rendered now if missing), and the renderer."""
    default, own = ref_renderers(args.ref_renderer)
    renderer = own.get(os.path.basename(scene), default) if scene else default
    text = open(scene, "rb").read() if scene else b"embedded cornell"
    key = hashlib.sha256(text + repr((args.resolution, args.max_bounces, renderer, args.ref_spp)).encode()).hexdigest()[:16]
    name = (os.path.splitext(os.path.basename(scene))[0] if scene else "cornell") + "-" + key
    halves = [os.path.join(args.cache, f"{name}-{i}.exr") for i in (1, 2)]
    for i, path in enumerate(halves):
        if os.path.exists(path):
            continue
        os.makedirs(args.cache, exist_ok=True)
        out = os.path.join(work, f"ref{i}")
        cmd = ([args.ref, "trace"] + scene_args(scene, args.resolution, args.max_bounces) +
               ["--renderer", renderer, "--spp", str(args.ref_spp // 2), "--seed", str(900001 + i),
                "--threads", str(args.ref_threads), "--quiet", "--out", out])
        print(f"reference: {shlex.join(cmd)}", file=sys.stderr, flush=True)
        cpu_run(cmd)
        os.replace(os.path.join(out, "classes.exr"), path)
    return halves, renderer


def errors(image_error, halves, files, border, lamp_luminance=None):
    """(reference noise whole, off), and {file: (mse, mse_off)} with the noise subtracted. With
    lamp_luminance, "off" leaves out the pixels near a reference luminance above it (image_error)."""
    lamp = ["--lamp-luminance", str(lamp_luminance)] if lamp_luminance is not None else []
    out = subprocess.run([image_error, halves[0], "--second-ref", halves[1], "--border", str(border)] + lamp + files,
                         check=True, capture_output=True, text=True).stdout.splitlines()
    noise = json.loads(out[0])
    res = {}
    for line in out[1:]:
        r = json.loads(line)
        res[r["file"]] = (r["mse"] - noise["reference_noise"], r["mse_off"] - noise["reference_noise_off"])
    return (noise["reference_noise"], noise["reference_noise_off"]), res


def fmt_range(xs):
    return f"{statistics.median(xs):.3f} [{min(xs):.3f}, {max(xs):.3f}]"


def mean_ratio(base, rs, k, resamples=2000):
    """(median CPU x mean MSE) of base over that of rs (MSE at index k of each (cpu, mse, mse_off)
    round), with a 95 % bootstrap interval over the paired rounds."""
    def ratio(idx):
        b = statistics.median(base[i][0] for i in idx) * statistics.fmean(base[i][k] for i in idx)
        v = statistics.median(rs[i][0] for i in idx) * statistics.fmean(rs[i][k] for i in idx)
        return b / v if v > 0 else float("inf")
    n = len(rs)
    rng = random.Random(12345)
    boot = sorted(ratio([rng.randrange(n) for _ in range(n)]) for _ in range(resamples))
    return f"{ratio(range(n)):.3f} [{boot[int(0.025 * resamples)]:.3f}, {boot[int(0.975 * resamples) - 1]:.3f}]"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--old", required=True, help="today's pathex (the baseline)")
    ap.add_argument("--new", required=True, help="the pathex under test")
    ap.add_argument("--variant", action="append", default=[],
                    help="LABEL:ARGS, the new binary with extra trace arguments (repeatable); "
                         "without any, the new binary with its defaults")
    ap.add_argument("--binary", action="append", default=[],
                    help="LABEL:PATH, one more pathex with its defaults, e.g. an earlier build of the branch (repeatable)")
    ap.add_argument("--image-error", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "build", "bench", "image_error"))
    ap.add_argument("--scene", action="append", default=[], help="scene file (repeatable; default: the embedded Cornell box)")
    ap.add_argument("--resolution", default=None, help="WxH (default: the scene's)")
    ap.add_argument("--max-bounces", type=int, default=None)
    ap.add_argument("--renderers", default="pt-nee,bdpt,lt")
    ap.add_argument("--spp", default="16,64")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--border", type=int, default=2)
    ap.add_argument("--ref", default=None, help="binary for the reference (default: --old)")
    ap.add_argument("--ref-renderer", action="append", default=[],
                    help="the reference's renderer (default pt-nee), or NAME=RENDERER for scene file NAME alone (repeatable)")
    ap.add_argument("--ref-spp", type=int, default=2048)
    ap.add_argument("--ref-threads", type=int, default=2)
    ap.add_argument("--cache", default=os.path.expanduser("~/.cache/pathex-efficiency"))
    ap.add_argument("--json-out", default=None, help="write every run's figures here")
    args = ap.parse_args()
    args.ref = args.ref or args.old
    variants = [("old", args.old, [])]
    if not args.variant:
        variants.append(("new", args.new, []))
    for v in args.variant:
        label, _, extra = v.partition(":")
        variants.append((label, args.new, shlex.split(extra)))
    for b in args.binary:
        label, _, path = b.partition(":")
        variants.append((label, path, []))
    renderers = args.renderers.split(",")
    spps = [int(s) for s in args.spp.split(",")]
    scenes = args.scene or [None]
    records = []
    with tempfile.TemporaryDirectory(prefix="pathex-eff-") as work:
        for scene in scenes:
            halves, ref_renderer = reference(args, scene, work)
            sname = scene or "cornell (embedded)"
            for renderer in renderers:
                for spp in spps:
                    runs = {label: [] for label, _, _ in variants}  # per round: (cpu, mse, mse_off)
                    for r in range(args.rounds):
                        order = variants[r % len(variants):] + variants[:r % len(variants)]
                        files, cpus = {}, {}
                        for label, binary, extra in order:
                            out = os.path.join(work, f"{label}-{r}")
                            cmd = ([binary, "trace"] + scene_args(scene, args.resolution, args.max_bounces) +
                                   ["--renderer", renderer, "--spp", str(spp), "--seed", str(1 + r), "--threads", "1",
                                    "--quiet", "--out", out] + extra)
                            cpus[label] = cpu_run(cmd)
                            files[label] = os.path.join(out, "classes.exr")
                        noise, errs = errors(args.image_error, halves, list(files.values()), args.border)
                        for label in files:
                            mse, mse_off = errs[files[label]]
                            runs[label].append((cpus[label], mse, mse_off))
                            records.append({"scene": sname, "renderer": renderer, "spp": spp, "round": r, "variant": label,
                                            "cpu_s": cpus[label], "mse": mse, "mse_off": mse_off,
                                            "reference_noise": noise[0], "reference_noise_off": noise[1]})
                    base = runs[variants[0][0]]
                    print(f"\n{sname}, {renderer}, {spp} spp, {args.rounds} rounds "
                          f"(reference {ref_renderer} at {args.ref_spp} spp; noise {noise[0]:.3g} whole, {noise[1]:.3g} off)")
                    print(f"  {'variant':<14}{'CPU s':>8}{'MSE whole':>12}{'MSE off':>12}{'eff whole':>12}{'eff off':>12}"
                          f"   {'whole / ' + variants[0][0]:<26}{'off / ' + variants[0][0]}")
                    for label, _, _ in variants:
                        rs = runs[label]
                        eff = [1.0 / (m * c) if m > 0 else float("inf") for c, m, _ in rs]
                        eff_off = [1.0 / (m * c) if m > 0 else float("inf") for c, _, m in rs]
                        ratio = [(b[0] * b[1]) / (c * m) if m > 0 else float("inf") for (c, m, _), b in zip(rs, base)]
                        ratio_off = [(b[0] * b[2]) / (c * m) if m > 0 else float("inf") for (c, _, m), b in zip(rs, base)]
                        print(f"  {label:<14}{statistics.median(x[0] for x in rs):>8.3f}"
                              f"{statistics.median(x[1] for x in rs):>12.4g}{statistics.median(x[2] for x in rs):>12.4g}"
                              f"{statistics.median(eff):>12.4g}{statistics.median(eff_off):>12.4g}"
                              f"   {fmt_range(ratio):<26}{fmt_range(ratio_off)}", flush=True)
                    print("  efficiency 1 / (mean MSE x median CPU s), variant / old, 95 % bootstrap interval:")
                    print(f"  {'variant':<14}{'whole / old':<26}off / old")
                    for label, _, _ in variants[1:]:
                        print(f"  {label:<14}{mean_ratio(base, runs[label], 1):<26}{mean_ratio(base, runs[label], 2)}",
                              flush=True)
    if args.json_out:
        with open(args.json_out, "w") as f:
            json.dump(records, f, indent=1)


if __name__ == "__main__":
    main()
