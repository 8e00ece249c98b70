// Spectra as RGB: pbrt-v4 renders with wavelengths, this renderer with linear sRGB, so the
// pbrt-v4 reader turns each spectrum a scene gives (sampled values, a blackbody, a named
// illuminant or metal) into the RGB that pbrt-v4's spectral render of it would show. Both
// integrate on pbrt-v4's grid: every whole nanometre from 360 to 830 nm, against the CIE 1931
// 2-degree colour matching functions, into pbrt-v4's sRGB (whose white is the CIE's D65
// table integrated on that grid). How each kind becomes RGB, the data's sources and where
// the result differs from pbrt-v4: docs/pbrt-format.md (Spectra).
#pragma once

#include <array>
#include <optional>
#include <string_view>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

namespace pt::spectra {

inline constexpr int kLambdaMin = 360;  // nm: pbrt-v4's Lambda_min and Lambda_max, the ends
inline constexpr int kLambdaMax = 830;  // of the CIE's tables
inline constexpr int kSamples = kLambdaMax - kLambdaMin + 1;

// A spectrum at every whole nanometre from kLambdaMin to kLambdaMax (element i at
// kLambdaMin + i nm): pbrt-v4's DenselySampledSpectrum, on which it takes every inner product.
using Dense = std::array<double, kSamples>;

// The CIE 1931 standard observer's x-bar, y-bar, z-bar at `lambda` nm (kLambdaMin to
// kLambdaMax).
glm::dvec3 cmf(int lambda);
// The sum of y-bar over the grid: the CIE's 1 nm integral of y-bar, 106.8569 (pbrt-v4's
// CIE_Y_integral). Emission of luminance Y = 1 integrates y-bar to this.
double cieYIntegral();

// The piecewise-linear spectrum through (wavelength in nm, value) pairs, whose wavelengths
// increase: zero outside the first and last wavelength, as pbrt-v4's PiecewiseLinearSpectrum
// (which spectra given in a scene, inline or from a file, are).
Dense piecewiseLinear(const std::vector<double>& pairs);
// Planck's law at `kelvin` (> 0), scaled to 1 at its peak wavelength: pbrt-v4's
// BlackbodySpectrum. The scale matters only where it is not a light (lights are normalized).
Dense blackbody(double kelvin);
// CIE standard illuminant D65: the CIE's table, interpolated linearly between its 5 nm rows.
Dense illuminantD65();
// CIE standard illuminant A: Planck's law with the CIE's defining constants (2848 K with
// c2 = 1.435e-2 m K, i.e. 2855.5 K with today's c2).
Dense illuminantA();
// The CIE daylight illuminant of correlated colour temperature `cct` (4000 to 25000 K) from
// the CIE's daylight basis S0, S1, S2 (CIE 15, section 3.1), M1 and M2 rounded to three
// decimals as the CIE prescribes. D50 is 5000 * 1.4388 / 1.4380 K (5003 K).
Dense daylight(double cct);

// Linear sRGB from CIE XYZ: pbrt-v4's RGBColorSpace matrix for the sRGB primaries with the
// white of illuminantD65() on this grid (not the rounded xy 0.3127, 0.3290), so that D65 is
// exactly white. It agrees with IEC 61966-2-1's (rounded) matrix to 4e-4.
const glm::dmat3& xyzToLinearSrgb();
// Sum over the grid of the matching functions times s, over cieYIntegral(): pbrt-v4's
// SpectrumToXYZ (an emission of luminance 1 has Y = 1).
glm::dvec3 toXyz(const Dense& s);

// A light's emission: pbrt-v4 divides a light's scale by the spectrum's luminance
// (SpectrumToPhotometric), so a light of spectrum s renders as XYZ(s) / Y(s): linear sRGB
// of luminance 1 with s's chromaticity, which may lie outside sRGB (a negative component).
// nullopt when s has no luminance (pbrt-v4 would divide by zero).
std::optional<glm::dvec3> emissionToRgb(const Dense& s);
// A reflectance: the RGB pbrt-v4's render shows where a surface of reflectance s is lit by
// its colour space's illuminant, D65 (the spectrum an "rgb L" [1 1 1] light emits):
// M * XYZ(s * D65) / Y(D65). A constant r gives (r, r, r).
glm::dvec3 reflectanceToRgb(const Dense& s);
// An unbounded spectrum (an index of refraction, an absorption coefficient): its colour
// under D65 as reflectanceToRgb computes it, without the bound of 1, negative components
// clamped to 0. This inverts pbrt-v4's RGBUnboundedSpectrum, which makes an "rgb eta" the
// spectrum whose colour under D65 is that RGB; it is each channel's average of s with weights
// that sum to 1 (a constant c gives (c, c, c)), signed where the channel's sensitivity is.
glm::dvec3 unboundedToRgb(const Dense& s);

// A blackbody light of `kelvin`: emissionToRgb(blackbody(kelvin)).
glm::dvec3 blackbodyRgb(double kelvin);

// pbrt-v4's named illuminants ("stdillum-A", "stdillum-D50", "stdillum-D65",
// "stdillum-F1" to "stdillum-F12", "illum-acesD60") as lights, emissionToRgb of each;
// nullopt for any other name.
std::optional<glm::dvec3> namedIlluminantRgb(std::string_view name);

// pbrt-v4's named metals ("Ag", "Al", "Au", "Cu", "CuZn", "MgO", "TiO2" of "metal-Au-eta"
// and "metal-Au-k") as an RGB complex index of refraction, eta + i k per channel: computed
// offline by tools/metal-rgb.py from pbrt-v4's measured spectra (spectra.cpp says how).
struct NamedMetal {
  std::string_view name;
  glm::vec3 eta, k;
};
const NamedMetal* namedMetal(std::string_view name);

// pbrt-v4's named glasses ("glass-BK7", "glass-BAF10", "glass-FK51A", "glass-LASF9",
// "glass-F5", "glass-F10", "glass-F11") as unboundedToRgb of their dispersion curves,
// computed offline by tools/metal-rgb.py; nullopt for any other name.
std::optional<glm::vec3> namedGlassEta(std::string_view name);

}  // namespace pt::spectra
