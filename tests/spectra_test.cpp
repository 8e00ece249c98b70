// Spectra into RGB (host/scene/pbrt/spectra.h) against the CIE's published figures, and the
// pbrt-v4 reader's use of it: blackbodies, sampled spectra, named metals, glasses and
// illuminants in scene files.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include <glm/matrix.hpp>

#include "common/check.h"
#include "scene/pbrt/pbrt_scene.h"
#include "scene/pbrt/spectra.h"
#include "scene/scene.h"

namespace pt {
namespace {

using spectra::Dense;

Dense constant(double value) {
  Dense s;
  s.fill(value);
  return s;
}

glm::dvec2 chromaticity(glm::dvec3 xyz) {
  return glm::dvec2(xyz.x, xyz.y) / (xyz.x + xyz.y + xyz.z);
}

// Luminance of a linear sRGB colour: Y of its XYZ.
double rgbLuminance(glm::dvec3 rgb) {
  return (glm::inverse(spectra::xyzToLinearSrgb()) * rgb).y;
}

void expectRgbNear(glm::dvec3 a, glm::dvec3 b, double tolerance, const std::string& what) {
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], tolerance) << what << " [" << c << "]";
}

// pbrt-v4's FrComplex (the renderer's frComplex1) in double: the unpolarized Fresnel
// reflectance of a conductor eta + i k at normal incidence.
double normalReflectance(double eta, double k) {
  return ((eta - 1) * (eta - 1) + k * k) / ((eta + 1) * (eta + 1) + k * k);
}

TEST(Spectra, MatchingFunctionsAreTheCiesTable) {
  // The CIE's 1 nm integral of y-bar over 360-830 nm is 106.856895; the table's sum is
  // 106.856917 (the CIE's tabulated values, rounded).
  EXPECT_NEAR(spectra::cieYIntegral(), 106.856895, 1e-4);
  EXPECT_EQ(spectra::cmf(555).y, 1.0);  // y-bar's peak
  expectRgbNear(spectra::cmf(600), {1.0622, 0.631, 0.0008}, 0, "600 nm");
  // The equal-energy spectrum is white at (1/3, 1/3): x-bar, y-bar and z-bar have equal
  // integrals (to the table's rounding).
  const glm::dvec2 e = chromaticity(spectra::toXyz(constant(1.0)));
  EXPECT_NEAR(e.x, 1.0 / 3.0, 1e-4);
  EXPECT_NEAR(e.y, 1.0 / 3.0, 1e-4);
}

TEST(Spectra, D65IsWhiteInPbrtV4sSrgb) {
  // The CIE's chromaticity of D65 for the 1931 observer.
  const glm::dvec2 w = chromaticity(spectra::toXyz(spectra::illuminantD65()));
  EXPECT_NEAR(w.x, 0.31272, 2e-5);
  EXPECT_NEAR(w.y, 0.32903, 2e-5);
  expectRgbNear(*spectra::emissionToRgb(spectra::illuminantD65()), glm::dvec3(1.0), 1e-9, "D65");
  // IEC 61966-2-1's matrix, which rounds its white to (0.3127, 0.3290).
  const glm::dmat3 iec = glm::transpose(glm::dmat3(3.2406, -1.5372, -0.4986,  //
                                                   -0.9689, 1.8758, 0.0415,   //
                                                   0.0557, -0.2040, 1.0570));
  for (int c = 0; c < 3; ++c) {
    for (int r = 0; r < 3; ++r) {
      EXPECT_NEAR(spectra::xyzToLinearSrgb()[c][r], iec[c][r], 4e-4) << c << "," << r;
    }
  }
}

TEST(Spectra, ConstantSpectraAreGrey) {
  for (double r : {0.0, 0.18, 0.5, 1.0}) {
    expectRgbNear(spectra::reflectanceToRgb(constant(r)), glm::dvec3(r), 1e-9, "reflectance");
  }
  expectRgbNear(spectra::unboundedToRgb(constant(1.5)), glm::dvec3(1.5), 1e-9, "index");
  expectRgbNear(spectra::unboundedToRgb(constant(0.0)), glm::dvec3(0.0), 0, "zero k");
  // An emission is normalized to luminance 1, whatever its scale: the equal-energy white
  // is then slightly pink against D65 (x = y = 1/3 lies towards red and away from blue).
  const glm::dvec3 e = *spectra::emissionToRgb(constant(7.0));
  EXPECT_NEAR(rgbLuminance(e), 1.0, 1e-9);
  EXPECT_GT(e.r, 1.0);
  EXPECT_LT(e.b, 1.0);
  EXPECT_FALSE(spectra::emissionToRgb(constant(0.0)).has_value());  // nothing to normalize
}

TEST(Spectra, PiecewiseLinearIsZeroOutsideItsWavelengths) {
  const Dense s = spectra::piecewiseLinear({400, 1, 500, 3, 510, 3});
  auto at = [&](int lambda) { return s[lambda - spectra::kLambdaMin]; };
  EXPECT_EQ(at(399), 0.0);
  EXPECT_EQ(at(400), 1.0);
  EXPECT_EQ(at(450), 2.0);
  EXPECT_EQ(at(500), 3.0);
  EXPECT_EQ(at(510), 3.0);
  EXPECT_EQ(at(511), 0.0);
  EXPECT_EQ(at(830), 0.0);
}

TEST(Spectra, BlackbodiesAndIlluminantA) {
  // Illuminant A (CIE 015: x = 0.44757, y = 0.40745) by the CIE's formula, to the published
  // figures' last digit; Planck's law at 2856 K, A's nominal temperature, is 0.00004 off
  // (the CIE's c2 = 1.435e-2 m K makes A 2855.5 K on today's scale).
  glm::dvec2 xy = chromaticity(spectra::toXyz(spectra::illuminantA()));
  EXPECT_NEAR(xy.x, 0.44757, 1.5e-5);
  EXPECT_NEAR(xy.y, 0.40745, 1.5e-5);
  xy = chromaticity(spectra::toXyz(spectra::blackbody(2856.0)));
  EXPECT_NEAR(xy.x, 0.44757, 5e-5);
  EXPECT_NEAR(xy.y, 0.40745, 5e-5);
  // pbrt-v4's BlackbodySpectrum is 1 at its peak (579.6 nm at 5000 K, 1 nm from a sample).
  const Dense b = spectra::blackbody(5000.0);
  EXPECT_NEAR(*std::max_element(b.begin(), b.end()), 1.0, 1e-5);
  // 6504 K, D65's correlated colour temperature, is near white: D65 lies 0.003 in uv above
  // the Planckian locus, so the blackbody is a little magenta (green low).
  const glm::dvec3 d = spectra::blackbodyRgb(6504.0);
  expectRgbNear(d, glm::dvec3(1.0), 0.06, "6504 K");
  EXPECT_LT(d.g, std::min(d.r, d.b));
  // Lights of luminance 1, red when cool and blue when hot.
  for (double kelvin : {1500.0, 3000.0, 6504.0, 10000.0, 40000.0}) {
    EXPECT_NEAR(rgbLuminance(spectra::blackbodyRgb(kelvin)), 1.0, 1e-9) << kelvin;
  }
  const glm::dvec3 warm = spectra::blackbodyRgb(3000.0), cool = spectra::blackbodyRgb(10000.0);
  EXPECT_GT(warm.r, warm.g);
  EXPECT_GT(warm.g, warm.b);
  EXPECT_LT(cool.r, cool.b);
}

TEST(Spectra, NarrowSpectraLieOnTheSpectralLocus) {
  // A 2 nm wide triangle about each wavelength has the chromaticity of that wavelength: the
  // CIE 1931 spectral locus (CIE 015's table, to its 4 decimals).
  struct Point {
    int lambda;
    double x, y;
  };
  for (const Point& p :
       {Point{450, 0.1566, 0.0177}, Point{500, 0.0082, 0.5384}, Point{550, 0.3016, 0.6923},
        Point{600, 0.6270, 0.3725}, Point{650, 0.7260, 0.2740}}) {
    const double l = p.lambda;
    const Dense s = spectra::piecewiseLinear({l - 1, 0, l, 1, l + 1, 0});
    const glm::dvec2 xy = chromaticity(spectra::toXyz(s));
    EXPECT_NEAR(xy.x, p.x, 6e-5) << p.lambda;
    EXPECT_NEAR(xy.y, p.y, 6e-5) << p.lambda;
  }
  // Outside sRGB: light of 600 nm alone is red with a negative blue, of 520 nm a negative red.
  const glm::dvec3 orange =
      *spectra::emissionToRgb(spectra::piecewiseLinear({599, 0, 600, 1, 601, 0}));
  EXPECT_GT(orange.r, orange.g);
  EXPECT_LT(orange.b, 0.0);
  const glm::dvec3 green =
      *spectra::emissionToRgb(spectra::piecewiseLinear({519, 0, 520, 1, 521, 0}));
  EXPECT_LT(green.r, 0.0);
}

TEST(Spectra, NamedMetalsMatchTheirSpectralReflectance) {
  // tools/metal-rgb.py fits each channel's normal-incidence reflectance to the channel's
  // value of pbrt-v4's spectral Fresnel reflectance under D65 (its report), capped at 0.999.
  struct Expected {
    const char* name;
    glm::dvec3 reflectance;
  };
  for (const Expected& e :
       {Expected{"Au", {0.999, 0.7825, 0.3434}}, Expected{"Cu", {0.9553, 0.6376, 0.5382}},
        Expected{"CuZn", {0.9096, 0.7783, 0.4228}}, Expected{"Ag", {0.9715, 0.9599, 0.9153}},
        Expected{"Al", {0.9132, 0.9215, 0.9245}}, Expected{"MgO", {0.0720, 0.0731, 0.0749}},
        Expected{"TiO2", {0.2322, 0.2446, 0.2727}}}) {
    const spectra::NamedMetal* m = spectra::namedMetal(e.name);
    ASSERT_NE(m, nullptr) << e.name;
    glm::dvec3 r;
    for (int c = 0; c < 3; ++c) r[c] = normalReflectance(m->eta[c], m->k[c]);
    expectRgbNear(r, e.reflectance, 1e-4, e.name);
  }
  // Gold and copper are red-yellow: more red than green, more green than blue.
  for (const char* name : {"Au", "Cu"}) {
    const spectra::NamedMetal& m = *spectra::namedMetal(name);
    EXPECT_GT(normalReflectance(m.eta.r, m.k.r), normalReflectance(m.eta.g, m.k.g)) << name;
    EXPECT_GT(normalReflectance(m.eta.g, m.k.g), normalReflectance(m.eta.b, m.k.b)) << name;
  }
  EXPECT_EQ(spectra::namedMetal("Xx"), nullptr);
  EXPECT_EQ(spectra::namedMetal("Au-eta"), nullptr);
}

TEST(Spectra, NamedIlluminantsAndGlasses) {
  expectRgbNear(*spectra::namedIlluminantRgb("stdillum-D65"), glm::dvec3(1.0), 1e-9, "D65");
  // Computed here from the CIE's formulas; tools/metal-rgb.py integrates pbrt-v4's tables of
  // the same illuminants to these.
  expectRgbNear(*spectra::namedIlluminantRgb("stdillum-A"), {1.845044, 0.826069, 0.233373}, 2e-3,
                "A");
  // D50 from the daylight basis has the CIE's chromaticity (0.3457, 0.3585). pbrt-v4's table
  // "CIE_Illum_D5000" does not: it integrates to (0.3368, 0.3580), RGB (1.0866, 0.9995,
  // 0.7497) against these (1.176, 0.976, 0.722) (docs/pbrt-format.md).
  const glm::dvec3 d50 = *spectra::namedIlluminantRgb("stdillum-D50");
  const glm::dvec2 xy = chromaticity(glm::inverse(spectra::xyzToLinearSrgb()) * d50);
  EXPECT_NEAR(xy.x, 0.3457, 1e-4);
  EXPECT_NEAR(xy.y, 0.3585, 1e-4);
  expectRgbNear(*spectra::namedIlluminantRgb("illum-acesD60"), {1.046912, 0.994574, 0.915528}, 2e-3,
                "ACES D60");
  for (int i = 1; i <= 12; ++i) {
    const std::string name = "stdillum-F" + std::to_string(i);
    const std::optional<glm::dvec3> f = spectra::namedIlluminantRgb(name);
    ASSERT_TRUE(f.has_value()) << name;
    EXPECT_NEAR(rgbLuminance(*f), 1.0, 1e-5) << name;
  }
  EXPECT_FALSE(spectra::namedIlluminantRgb("stdillum-F13").has_value());
  EXPECT_FALSE(spectra::namedIlluminantRgb("stdillum-D55").has_value());
  // BK7's index is 1.5168 at 587.6 nm and rises towards blue.
  const glm::vec3 bk7 = *spectra::namedGlassEta("glass-BK7");
  EXPECT_NEAR((bk7.r + bk7.g + bk7.b) / 3.0f, 1.5168f, 0.005f);
  EXPECT_LT(bk7.r, bk7.g);
  EXPECT_LT(bk7.g, bk7.b);
  EXPECT_FALSE(spectra::namedGlassEta("glass-XYZ").has_value());
}

// ---- in pbrt-v4 scene files -------------------------------------------------------------------

constexpr char kPrelude[] =
    "Scale -1 1 1\nLookAt 0 0 -10  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n";
constexpr char kSpectraTriangle[] =
    "Shape \"trianglemesh\" \"point3 P\" [ 0 0 0  1 0 0  0 1 0 ] \"integer indices\" [ 0 1 2 ]\n";

// The material of each triangle of `body` (after the prelude), and the scene's warnings.
std::vector<Material> materials(const std::string& body, std::vector<std::string>* warnings) {
  const Scene scene = loadPbrtSceneText(kPrelude + body, "scene.pbrt");
  *warnings = scene.warnings;
  std::vector<Material> out;
  for (const Triangle& t : scene.triangles) out.push_back(scene.materials.at(t.material));
  return out;
}

TEST(PbrtSpectra, BlackbodyAndSampledSpectraBecomeTheirColours) {
  std::vector<std::string> warnings;
  const std::vector<Material> m = materials(
      std::string("AttributeBegin\nAreaLightSource \"diffuse\" \"blackbody L\" [3000] "
                  "\"float scale\" 2\n") +
          kSpectraTriangle +
          "AttributeEnd\n"
          "AttributeBegin\nAreaLightSource \"diffuse\" \"spectrum L\" [500 1 510 1]\n" +
          kSpectraTriangle +
          "AttributeEnd\n"
          "AttributeBegin\nAreaLightSource \"diffuse\" \"spectrum L\" \"stdillum-A\"\n" +
          kSpectraTriangle +
          "AttributeEnd\n"
          "Material \"diffuse\" \"spectrum reflectance\" [360 0.5 830 0.5]\n" +
          kSpectraTriangle +
          "Material \"diffuse\" \"spectrum reflectance\" [360 0.05 560 0.05 620 0.8 830 0.8]\n" +
          kSpectraTriangle +
          "Material \"conductor\" \"spectrum eta\" \"metal-Cu-eta\" \"spectrum k\" "
          "\"metal-Cu-k\"\n" +
          kSpectraTriangle,
      &warnings);
  ASSERT_EQ(m.size(), 6u);
  // A 3000 K light: luminance 1 of its colour, times the scale.
  const glm::dvec3 warm = spectra::blackbodyRgb(3000.0);
  expectRgbNear(glm::dvec3(m[0].emission), 2.0 * warm, 1e-6, "blackbody");
  EXPECT_GT(m[0].emission.r, m[0].emission.g);
  EXPECT_GT(m[0].emission.g, m[0].emission.b);
  // Light from 500 to 510 nm only: cyan-green, luminance 1. Its red is negative (outside
  // sRGB) and clamped to 0, warned.
  EXPECT_EQ(m[1].emission.r, 0.0f);
  EXPECT_GT(m[1].emission.g, m[1].emission.b);
  EXPECT_GT(m[1].emission.b, 0.1f);
  expectRgbNear(glm::dvec3(m[2].emission), *spectra::namedIlluminantRgb("stdillum-A"), 1e-6,
                "stdillum-A");
  expectRgbNear(glm::dvec3(m[3].reflectance), glm::dvec3(0.5), 1e-6, "grey");
  // A reflectance rising from 0.05 below 560 nm to 0.8 above 620 nm: red.
  EXPECT_GT(m[4].reflectance.r, 0.6f);
  EXPECT_LT(m[4].reflectance.b, 0.1f);
  expectRgbNear(glm::dvec3(m[4].reflectance),
                spectra::reflectanceToRgb(
                    spectra::piecewiseLinear({360, 0.05, 560, 0.05, 620, 0.8, 830, 0.8})),
                1e-6, "red");
  EXPECT_EQ(m[5].eta, spectra::namedMetal("Cu")->eta);
  EXPECT_EQ(m[5].k, spectra::namedMetal("Cu")->k);
  // Only the gamut clamp is an approximation worth a warning.
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0],
            "scene.pbrt:10: an emission spectrum (here 'L' of AreaLightSource \"diffuse\") has a "
            "colour outside sRGB's gamut (a negative component): clamped to 0");
}

TEST(PbrtSpectra, GlassesAndDarkLights) {
  std::vector<std::string> warnings;
  const std::vector<Material> m = materials(
      std::string("Material \"dielectric\" \"spectrum eta\" \"glass-BK7\"\n") + kSpectraTriangle,
      &warnings);
  const glm::vec3 bk7 = *spectra::namedGlassEta("glass-BK7");
  EXPECT_FLOAT_EQ(m.at(0).eta.x, (bk7.r + bk7.g + bk7.b) / 3.0f);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("dispersion is not simulated"), std::string::npos) << warnings[0];
  // A light whose spectrum is zero over 360-830 nm has no luminance to normalize by.
  try {
    materials(std::string("AreaLightSource \"diffuse\" \"spectrum L\" [300 1 350 1]\n") +
                  kSpectraTriangle,
              &warnings);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("emits nothing from 360 to 830 nm"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace pt
