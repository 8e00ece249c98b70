#!/usr/bin/env python3
"""RGB tables for pbrt-v4's named spectra that this renderer cannot compute from its own data.

    tools/metal-rgb.py PBRT_V4/src/pbrt/util/spectrum.cpp [--ours host/scene/pbrt/spectra.cpp]

reads pbrt-v4's measured spectra (the named metals' eta and k, the named glasses' indices, the
CIE's fluorescent illuminants F1-F12) from pbrt-v4's source, the CIE matching functions and
D65 from this repository's host/scene/pbrt/spectra.cpp, and prints on standard output the
C++ tables that spectra.cpp holds (kNamedMetals, kGlassEta, kFluorescentRgb). On standard
error it prints how well the RGB metals reproduce the spectral metals' reflectance, angle
by angle, against other ways of making them RGB. The repository depends on pbrt-v4's source
only here, offline: its numbers are published measurements, and only the RGB results are
kept. Plain Python 3, no packages.

How each becomes RGB (docs/pbrt-format.md, Spectra, says why):

- Everything is integrated as pbrt-v4 integrates: at every whole nanometre from 360 to
  830 nm, each named spectrum extended beyond its ends by its end values (pbrt-v4's
  PiecewiseLinearSpectrum::FromInterleaved), into pbrt-v4's sRGB, whose XYZ-to-RGB matrix
  M makes the D65 table white.
- A named metal, eta(lambda) + i k(lambda): the colour pbrt-v4's spectral render shows where
  the metal reflects a white (D65) light at incidence angle theta is, per channel c,
  R_c(theta) = sum over lambda of w_c(lambda) F(theta; eta(lambda), k(lambda)), with the
  channel's weights w_c = (M (x-bar, y-bar, z-bar))_c D65 / Y(D65) (signed: they sum to 1)
  and F pbrt-v4's FrComplex, the unpolarized Fresnel reflectance of a conductor. This
  renderer evaluates the same F per channel with one eta_c + i k_c. Per channel, the pair is
  chosen so that F(0; eta_c, k_c) = R_c(0) exactly (the colour at normal incidence, what a
  viewer notices first) and, along the one-parameter family of pairs that do, so that the
  mean squared difference F(theta; eta_c, k_c) - R_c(theta) over the incident hemisphere
  (uniform in cos theta: every incident direction counts the same) is least. R_c is capped
  at 0.999 first: gold's red channel is 1.022 at normal incidence (its colour lies outside
  sRGB's cube of reflectances), which no Fresnel reflectance reaches, and F = 1 would need
  eta = 0.
- A named glass: per channel, the average of its index with the same signed weights w_c
  (spectra.h's unboundedToRgb: the inverse of pbrt-v4's RGBUnboundedSpectrum, whose RGB is
  its colour under D65). The renderer takes the mean of the three (dispersion is not
  simulated).
- A fluorescent illuminant F: a light's colour, M XYZ(s) / Y(s) (spectra.h's emissionToRgb).

The report compares, per metal, the largest difference over the channels between the RGB
Fresnel reflectance and R_c at a few angles (degrees), the largest at any angle (every half
degree) and the RMS over the hemisphere (uniform in cos theta), for: the fit; "signed", eta
and k each averaged with w_c (unboundedToRgb, what a metal given as inline pairs gets);
"positive", each averaged with the positive parts of w_c; "tungsten", the table of
Tungsten's ComplexIorData this renderer used before.
"""

import argparse
import cmath
import math
import os
import re
import sys

LAMBDA_MIN, LAMBDA_MAX = 360, 830
GRID = list(range(LAMBDA_MIN, LAMBDA_MAX + 1))


def arrays(text, pattern):
    """name -> list of numbers for every `<pattern> name[...] = { numbers };` in C++ text."""
    text = re.sub(r"//[^\n]*", "", text)
    found = {}
    for m in re.finditer(pattern + r"\s+(\w+)\s*\[[^\]]*\]\s*=\s*\{(.*?)\};", text, re.S):
        numbers = m.group(2).replace("\n", " ").split(",")
        found[m.group(1)] = [float(t) for t in numbers if t.strip()]
    return found


def interleaved(pairs):
    """pbrt-v4's FromInterleaved on the grid: linear between pairs, the end values beyond."""
    lambdas, values = pairs[0::2], pairs[1::2]
    out, j = [], 0
    for lam in GRID:
        if lam <= lambdas[0]:
            out.append(values[0])
            continue
        if lam >= lambdas[-1]:
            out.append(values[-1])
            continue
        while lambdas[j + 1] < lam:
            j += 1
        t = (lam - lambdas[j]) / (lambdas[j + 1] - lambdas[j])
        out.append(values[j] * (1 - t) + values[j + 1] * t)
    return out


def inverse3(m):
    a, b, c = m[0]
    d, e, f = m[1]
    g, h, i = m[2]
    det = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g)
    return [
        [(e * i - f * h) / det, (c * h - b * i) / det, (b * f - c * e) / det],
        [(f * g - d * i) / det, (a * i - c * g) / det, (c * d - a * f) / det],
        [(d * h - e * g) / det, (b * g - a * h) / det, (a * e - b * d) / det],
    ]


def mul3(m, v):
    return [sum(m[r][c] * v[c] for c in range(3)) for r in range(3)]


def fr_complex(cos_i, eta, k):
    """pbrt-v4's FrComplex: unpolarized Fresnel reflectance of a conductor eta + i k."""
    cos_i = min(max(cos_i, 0.0), 1.0)
    n = complex(eta, k)
    sin2_t = (1 - cos_i * cos_i) / (n * n)
    cos_t = cmath.sqrt(1 - sin2_t)
    r_parl = (n * cos_i - cos_t) / (n * cos_i + cos_t)
    r_perp = (cos_i - n * cos_t) / (cos_i + n * cos_t)
    return (abs(r_parl) ** 2 + abs(r_perp) ** 2) / 2


class Colour:
    """The CIE functions, D65 and pbrt-v4's sRGB matrix, from spectra.cpp's tables."""

    def __init__(self, ours):
        a = arrays(ours, r"constexpr double")
        self.x, self.y, self.z = a["kCieX"], a["kCieY"], a["kCieZ"]
        assert len(self.x) == len(GRID)
        d65_5nm = a["kD65"]
        self.d65 = interleaved([v for i, d in enumerate(d65_5nm) for v in (360 + 5 * i, d)])
        self.y_integral = sum(self.y)
        white = self.xyz(self.d65)
        white = [w / white[1] for w in white]

        def from_xy(x, y):
            return [x / y, 1.0, (1 - x - y) / y]

        prim = [from_xy(0.64, 0.33), from_xy(0.30, 0.60), from_xy(0.15, 0.06)]
        rgb = [[prim[c][r] for c in range(3)] for r in range(3)]  # columns: the primaries
        scale = mul3(inverse3(rgb), white)
        xyz_from_rgb = [[rgb[r][c] * scale[c] for c in range(3)] for r in range(3)]
        self.m = inverse3(xyz_from_rgb)
        d65_y = self.xyz(self.d65)[1]
        # Per channel, the signed weights of a reflectance's colour under D65 (sum 1), and
        # their positive parts renormalized (for the comparison).
        self.signed = [[0.0] * len(GRID) for _ in range(3)]
        self.positive = [[0.0] * len(GRID) for _ in range(3)]
        for i in range(len(GRID)):
            bar = mul3(self.m, [self.x[i], self.y[i], self.z[i]])
            for c in range(3):
                self.signed[c][i] = bar[c] * self.d65[i] / self.y_integral / d65_y
                self.positive[c][i] = max(bar[c], 0.0) * self.d65[i]
        for c in range(3):
            total = sum(self.positive[c])
            self.positive[c] = [w / total for w in self.positive[c]]

    def xyz(self, s):
        return [sum(cmf[i] * s[i] for i in range(len(GRID))) / self.y_integral
                for cmf in (self.x, self.y, self.z)]

    def emission_rgb(self, s):
        xyz = self.xyz(s)
        return mul3(self.m, [v / xyz[1] for v in xyz])

    def weighted(self, weights, s):
        return [sum(w[i] * s[i] for i in range(len(GRID))) for w in weights]

    def unbounded(self, s):
        return [max(v, 0.0) for v in self.weighted(self.signed, s)]


# Incident directions, uniform in cos theta (midpoints of equal steps).
MUS = [(j + 0.5) / 128 for j in range(128)]
# The most a channel's reflectance is fitted to (see above).
R_MAX = 0.999


def channel_reflectance(colour, eta, k, cos_i):
    f = [fr_complex(cos_i, eta[i], k[i]) for i in range(len(GRID))]
    return colour.weighted(colour.signed, f)


def fit_channel(r0, target):
    """eta, k with F(normal) = r0 and the least mean squared difference from target(mu)."""
    s = math.sqrt(r0)
    lo, hi = (1 - s) / (1 + s), (1 + s) / (1 - s)  # k = 0 at both ends

    def k_of(eta):
        return math.sqrt(max(0.0, (r0 * (eta + 1) ** 2 - (eta - 1) ** 2) / (1 - r0)))

    def cost(u):  # u in [0, 1]: eta from lo to hi on a log scale
        eta = lo * (hi / lo) ** u
        k = k_of(eta)
        return sum((fr_complex(mu, eta, k) - t) ** 2 for mu, t in zip(MUS, target)) / len(MUS)

    us = [i / 400 for i in range(401)]
    costs = [cost(u) for u in us]
    best = min(range(len(us)), key=lambda i: costs[i])
    a, b = us[max(best - 1, 0)], us[min(best + 1, len(us) - 1)]
    golden = (math.sqrt(5) - 1) / 2
    for _ in range(60):  # golden-section search in the bracket
        c, d = b - golden * (b - a), a + golden * (b - a)
        if cost(c) < cost(d):
            b = d
        else:
            a = c
    u = (a + b) / 2
    # A dielectric (k = 0, eta = hi) where that is as good to 1e-4 in RMS: MgO and TiO2 are
    # transparent in the visible, and a k of 0.01 that gains nothing would only mislead.
    if cost(1.0) <= cost(u) + 1e-8:
        u = 1.0
    if u == 1.0:
        return hi, 0.0
    eta = lo * (hi / lo) ** u
    return eta, k_of(eta)


# Tungsten's ComplexIorData table, which this renderer used before (for the comparison).
TUNGSTEN = {
    "Ag": ([0.1552646489, 0.1167232965, 0.1383806959], [4.8283433224, 3.1222459278, 2.1469504455]),
    "Al": ([1.6574599595, 0.8803689579, 0.5212287346], [9.2238691996, 6.2695232477, 4.8370012281]),
    "Au": ([0.1431189557, 0.3749570432, 1.4424785571], [3.9831604247, 2.3857207478, 1.6032152899]),
    "Cu": ([0.2004376970, 0.9240334304, 1.1022119527], [3.9129485033, 2.4528477015, 2.1421879552]),
    "MgO": ([2.0895885542, 1.6507224525, 1.5948759692], [0.0, 0.0, 0.0]),
    "TiO2": ([3.4566203131, 2.8017076558, 2.9051485020], [0.0001026662, 0.0, 0.0006356902]),
}
REPORT_ANGLES = [0, 30, 45, 60, 70, 80, 85, 89]


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("pbrt_spectrum_cpp", help="pbrt-v4's src/pbrt/util/spectrum.cpp")
    parser.add_argument("--ours", default=os.path.join(here, "..", "host", "scene", "pbrt",
                                                       "spectra.cpp"))
    args = parser.parse_args()
    colour = Colour(open(args.ours).read())
    pbrt = open(args.pbrt_spectrum_cpp).read()
    data = arrays(pbrt, r"const Float")
    # pbrt-v4's names: "name" -> variable -> array (its Spectra::Init).
    variable = dict(re.findall(
        r"Spectrum\s+(\w+)\s*=\s*PiecewiseLinearSpectrum::FromInterleaved\(\s*(\w+)\s*,", pbrt))
    named = {n: data[variable[v]] for n, v in re.findall(r'\{"([^"]+)",\s*(\w+)\}', pbrt)
             if v in variable}

    err = sys.stderr
    print("CIE y-bar sum: %.6f; M (XYZ to linear sRGB):" % colour.y_integral, file=err)
    for row in colour.m:
        print("  " + " ".join("%10.6f" % v for v in row), file=err)

    metals = []
    for name in ["Ag", "Al", "Au", "Cu", "CuZn", "MgO", "TiO2"]:
        eta = interleaved(named["metal-%s-eta" % name])
        k = interleaved(named["metal-%s-k" % name])
        target = {mu: channel_reflectance(colour, eta, k, mu) for mu in MUS + [1.0]}
        for deg in REPORT_ANGLES:
            mu = math.cos(math.radians(deg))
            target.setdefault(mu, channel_reflectance(colour, eta, k, mu))
        fit = [fit_channel(min(target[1.0][c], R_MAX), [min(target[mu][c], R_MAX) for mu in MUS])
               for c in range(3)]
        methods = {
            "fit": ([f[0] for f in fit], [f[1] for f in fit]),
            "signed": (colour.unbounded(eta), colour.unbounded(k)),
            "positive": (colour.weighted(colour.positive, eta),
                         colour.weighted(colour.positive, k)),
        }
        if name in TUNGSTEN:
            methods["tungsten"] = TUNGSTEN[name]
        metals.append((name, methods["fit"]))
        print("\nmetal-%s: spectral R(0) = (%.4f %.4f %.4f)" % ((name,) + tuple(target[1.0])),
              file=err)
        print("  %-9s %s  max     rms" % ("method", " ".join("%6d" % a for a in REPORT_ANGLES)),
              file=err)
        for method, (e, kk) in methods.items():
            if min(e) <= 0:
                print("  %-9s (an eta <= 0: %s)" % (method, e), file=err)
                continue
            worst = []
            for deg in REPORT_ANGLES:
                mu = math.cos(math.radians(deg))
                worst.append(max(abs(fr_complex(mu, e[c], kk[c]) - target[mu][c])
                                 for c in range(3)))
            dense = [math.cos(math.radians(a / 2)) for a in range(181)]
            most = max(abs(fr_complex(mu, e[c], kk[c]) - channel_reflectance(colour, eta, k, mu)[c])
                       for mu in dense for c in range(3))
            rms = math.sqrt(sum((fr_complex(mu, e[c], kk[c]) - target[mu][c]) ** 2
                                for mu in MUS for c in range(3)) / (3 * len(MUS)))
            print("  %-9s %s  %.4f  %.4f  eta (%.4f %.4f %.4f) k (%.4f %.4f %.4f)"
                  % ((method, " ".join("%6.4f" % w for w in worst), most, rms) + tuple(e)
                     + tuple(kk)),
                  file=err)

    def f(v):  # a C++ float literal
        text = "%.6g" % v
        return text + ("f" if "." in text or "e" in text else ".0f")

    print("// tools/metal-rgb.py's output: pbrt-v4's named metals, eta and k per channel.")
    print("constexpr NamedMetal kNamedMetals[] = {")
    for name, (eta, k) in metals:
        print('    {"%s", {%s}, {%s}},' % (name, ", ".join(map(f, eta)), ", ".join(map(f, k))))
    print("};")
    print("// pbrt-v4's named glasses: each channel's index (unboundedToRgb).")
    print("constexpr NamedRgb kGlassEta[] = {")
    for name in sorted(n for n in named if n.startswith("glass-")):
        rgb = colour.unbounded(interleaved(named[name]))
        print('    {"%s", {%s}},' % (name, ", ".join(map(f, rgb))))
    print("};")
    print("// The CIE's fluorescent illuminants as lights of luminance 1 (emissionToRgb).")
    print("constexpr NamedRgb kFluorescentRgb[] = {")
    for i in range(1, 13):
        rgb = colour.emission_rgb(interleaved(named["stdillum-F%d" % i]))
        print('    {"stdillum-F%d", {%s}},' % (i, ", ".join(map(f, rgb))))
    print("};")
    print("\nFor comparison, pbrt-v4's tables of the illuminants spectra.cpp computes:", file=err)
    for name in ["stdillum-A", "stdillum-D50", "stdillum-D65", "illum-acesD60"]:
        rgb = colour.emission_rgb(interleaved(named[name]))
        print("  %-14s (%.6f %.6f %.6f)" % ((name,) + tuple(rgb)), file=err)


if __name__ == "__main__":
    main()
