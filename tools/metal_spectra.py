#!/usr/bin/env python3
"""Turn pbrt-v4's measured metal spectra (complex index eta + i k) into linear-sRGB triples.

Usage: tools/metal_spectra.py [--plain] SPECTRUM_CPP > src/scene/metal_spectra.h
  SPECTRUM_CPP is pbrt-v4's src/pbrt/util/spectrum.cpp (github.com/mmp/pbrt-v4, Apache License
  2.0), which holds the measured tables (*_eta, *_k), the CIE 1931 2-degree matching functions
  (CIE_X, CIE_Y, CIE_Z at 1 nm, 360..830 nm) and the CIE D65 illuminant (CIE_Illum_D6500).
  Python 3 standard library only.

Conversion, per linear-sRGB channel c ("reflectance-matched"):
  eta_c is the plain CIE-weighted average: eta(lambda), as pbrt-v4 interpolates it (piecewise
  linear, held constant beyond the measured range), integrated against D65(lambda) times the CIE
  1931 matching functions over 360..830 nm, divided by the integral of D65 times y-bar, and turned
  into linear sRGB with the matrix of the sRGB primaries and the D65 white computed from the same
  tables (so that a constant 1 maps to exactly (1, 1, 1)). D65 weights the channels because
  pbrt-v4 renders an "rgb L [1 1 1]" light as the D65 spectrum, which its film records as
  sRGB (1, 1, 1).
  k_c is then chosen (bisection) so that the smooth metal's cosine-weighted hemispherical albedo
  in channel c, with the exact Fresnel of eta_c + i k_c, equals channel c of the spectral albedo
  (the albedo at each wavelength from eta(lambda), k(lambda), converted as above) clamped to
  [0, 0.999], searched above a quarter of the plain k_c; where even that reflects more than the
  target (the nearly transparent MgO and TiO2), k_c is the plain average (clamped to >= 0).
  Why: the plain average of k as well (--plain prints it) makes a rough gold sphere's red 1.6 %
  darker than pbrt-v4 renders it spectrally (the issue-35 furnace figure 0.930, 0.843, 0.682;
  pathex with the plain table: 0.915, 0.850, 0.686); matching the albedo brings each channel within
  0.7 % (README, "Materials"). The spectral albedo of gold in red is 1.012 (outside the sRGB gamut),
  which no RGB Fresnel reaches: hence the clamp.
"""
import cmath
import math
import re
import sys

NAMES = ["Ag", "Al", "Au", "Cu", "CuZn", "MgO", "TiO2"]  # every metal-* name pbrt-v4 defines


def arrays(text):
    out = {}
    for m in re.finditer(r"const Float (\w+)\[\w*\]\s*=\s*\{([^}]*)\}", text):
        body = re.sub(r"//[^\n]*", "", m.group(2))
        try:
            out[m.group(1)] = [float(x) for x in body.split(",") if x.strip()]
        except ValueError:
            pass  # an array of something else (not needed here)
    return out


def piecewise(interleaved):
    lam = interleaved[0::2]
    val = interleaved[1::2]

    def f(x):
        if x <= lam[0]:
            return val[0]
        if x >= lam[-1]:
            return val[-1]
        lo, hi = 0, len(lam) - 1
        while hi - lo > 1:
            mid = (lo + hi) // 2
            if lam[mid] <= x:
                lo = mid
            else:
                hi = mid
        t = (x - lam[lo]) / (lam[hi] - lam[lo])
        return val[lo] * (1 - t) + val[hi] * t
    return f


def inverse3(m):
    (a, b, c), (d, e, f), (g, h, i) = m
    det = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g)
    return [[(e * i - f * h) / det, (c * h - b * i) / det, (b * f - c * e) / det],
            [(f * g - d * i) / det, (a * i - c * g) / det, (c * d - a * f) / det],
            [(d * h - e * g) / det, (b * g - a * h) / det, (a * e - b * d) / det]]


def mul(m, v):
    return [sum(m[r][k] * v[k] for k in range(3)) for r in range(3)]


def fresnel_complex(c, eta, k):
    n = complex(eta, k)
    sin2_t = (1 - c * c) / (n * n)
    cos_t = cmath.sqrt(1 - sin2_t)
    rp = (n * c - cos_t) / (n * c + cos_t)
    rs = (c - n * cos_t) / (c + n * cos_t)
    return 0.5 * (abs(rp) ** 2 + abs(rs) ** 2)


def albedo(eta, k, steps=256):
    """Cosine-weighted hemispherical albedo: the integral of F(sqrt(t)) over t = cos^2 in [0, 1]."""
    return sum(fresnel_complex(math.sqrt((i + 0.5) / steps), eta, k) for i in range(steps)) / steps


def fit_k(eta, target, k_plain):
    # The albedo grows with k from a quarter of the plain k on (below, an index under 1 reflects
    # totally at k = 0 and the albedo is not monotonic); a target below that keeps the plain k.
    target = min(max(target, 0.0), 0.999)
    lo, hi = 0.25 * max(0.0, k_plain), 100.0
    if albedo(eta, lo) >= target:
        return max(0.0, k_plain)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if albedo(eta, mid) < target:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def main():
    plain = "--plain" in sys.argv[1:]
    path = [a for a in sys.argv[1:] if a != "--plain"][0]
    text = open(path, encoding="utf-8").read()
    t = arrays(text)
    lam = t["CIE_lambda"]
    cmf = [t["CIE_X"], t["CIE_Y"], t["CIE_Z"]]
    d65 = piecewise(t["CIE_Illum_D6500"])
    w = [d65(l) for l in lam]
    y_norm = sum(w[i] * cmf[1][i] for i in range(len(lam)))

    def xyz(spec):
        return [sum(spec(lam[i]) * w[i] * cmf[c][i] for i in range(len(lam))) / y_norm for c in range(3)]

    white = xyz(lambda _: 1.0)
    prim = [(0.64, 0.33), (0.30, 0.60), (0.15, 0.06)]
    cols = [[x / y, 1.0, (1 - x - y) / y] for x, y in prim]
    m = [[cols[c][r] for c in range(3)] for r in range(3)]
    s = mul(inverse3(m), white)
    rgb_to_xyz = [[m[r][c] * s[c] for c in range(3)] for r in range(3)]
    xyz_to_rgb = inverse3(rgb_to_xyz)

    def rgb(spec):
        return mul(xyz_to_rgb, xyz(spec))

    print("// Generated by tools/metal_spectra.py from pbrt-v4's src/pbrt/util/spectrum.cpp")
    print("// (github.com/mmp/pbrt-v4 at 5f7a606, Copyright (c) 2020 Matt Pharr, Wenzel Jakob and Greg")
    print("// Humphreys, Apache License 2.0): its measured complex indices of refraction eta + i k of")
    print("// metals, named as pbrt-v4 names them (\"metal-Au-eta\", \"metal-Au-k\", ...), each turned into")
    print("// linear sRGB: eta by the plain CIE-weighted average under D65, k matched to the spectral albedo")
    print("// (the script's docstring says how and why)." if not plain else "// (--plain: k by the same average).")
    print("// Physical data: do not edit by hand, rerun the script.")
    print("#pragma once")
    print()
    print("#include <string_view>")
    print()
    print("namespace pathex {")
    print()
    print("struct MetalSpectrum {")
    print("  std::string_view name;  // pbrt-v4's metal name: metal-<name>-eta, metal-<name>-k")
    print("  float eta[3];           // linear sRGB")
    print("  float k[3];")
    print("};")
    print()
    print("inline constexpr MetalSpectrum kMetalSpectra[] = {")
    for n in NAMES:
        fe, fk = piecewise(t[n + "_eta"]), piecewise(t[n + "_k"])
        e = [max(0.0, x) for x in rgb(fe)]
        k = [max(0.0, x) for x in rgb(fk)]
        if not plain:
            spectral = [albedo(fe(l), fk(l), 64) for l in lam]
            target = mul(xyz_to_rgb, [sum(spectral[i] * w[i] * cmf[c][i] for i in range(len(lam))) / y_norm for c in range(3)])
            k = [fit_k(e[c], target[c], k[c]) for c in range(3)]
        f = lambda v: ", ".join("%.6ff" % x for x in v)
        print('    {"%s", {%s}, {%s}},' % (n, f(e), f(k)))
    print("};")
    print()
    print('inline constexpr const char* kMetalNames = "%s";' % ", ".join(NAMES))
    print()
    print("// The metal of that name (\"Au\", not \"metal-Au-eta\"), or nullptr.")
    print("inline const MetalSpectrum* find_metal(std::string_view name) {")
    print("  for (const MetalSpectrum& m : kMetalSpectra)")
    print("    if (m.name == name) return &m;")
    print("  return nullptr;")
    print("}")
    print()
    print("}  // namespace pathex")


if __name__ == "__main__":
    main()
