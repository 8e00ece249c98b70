// Participating media as both readers give them (host/scene/media.h, pbrt/pbrt_media.cpp,
// json_media.cpp): pbrt-v4's types, parameters and defaults, presets, grids (counts, offsets,
// order), transforms, interfaces parallel to the triangles, the camera's medium, interface
// shapes kept or dropped, every error as one line, and media-free scenes left as they were.
#include <gtest/gtest.h>

#include <cstddef>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "common/check.h"
#include "fuzz/fuzz_entry.h"
#include "scene/load_scene.h"
#include "scene/media.h"
#include "scene/pbrt/pbrt_scene.h"
#include "scene/scene.h"
#include "test_util.h"

namespace pt {
namespace {

namespace fs = std::filesystem;

// A camera that needs no mirroring (Scale -1 1 1, as Bitterli's files start), so that world
// coordinates come through unchanged.
constexpr char kMediaUnmirrored[] =
    "Scale -1 1 1\nLookAt 0 0 -10  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n";

// A triangle at the origin, its normal +z: (0,0,0), (1,0,0), (0,1,0).
constexpr char kMediaTriangle[] =
    "Shape \"trianglemesh\" \"point3 P\" [ 0 0 0  1 0 0  0 1 0 ] \"integer indices\" [ 0 1 2 ]\n";

Scene pbrtScene(const std::string& text, bool strict = false) {
  return loadPbrtSceneText(text, "scene.pbrt", SceneLoadOptions{.strict = strict});
}

std::string pbrtError(const std::string& text, bool strict = false) {
  try {
    pbrtScene(text, strict);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

// The world point p in medium m's space.
glm::dvec3 toMedium(const Medium& m, glm::dvec3 p) {
  const glm::dvec4 h(p, 1.0);
  return {glm::dot(glm::dvec4(m.toMedium0), h), glm::dot(glm::dvec4(m.toMedium1), h),
          glm::dot(glm::dvec4(m.toMedium2), h)};
}

void expectNearMedia(glm::dvec3 a, glm::dvec3 b, const std::string& what) {
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], 1e-5) << what << " [" << c << "]";
}

std::vector<float> grid(const Scene& s, uint offset, std::size_t count) {
  EXPECT_LE(offset + count, s.mediumGrids.size());
  if (offset + count > s.mediumGrids.size()) return {};
  return {s.mediumGrids.begin() + offset, s.mediumGrids.begin() + offset + count};
}

void expectNoMedia(const Scene& s) {
  EXPECT_TRUE(s.media.empty());
  EXPECT_TRUE(s.mediumNames.empty());
  EXPECT_TRUE(s.mediumGrids.empty());
  EXPECT_TRUE(s.mediumInterfaces.empty());
  EXPECT_EQ(s.cameraMedium, kNoMedium);
}

// ---- pbrt-v4: homogeneous -----------------------------------------------------------------

TEST(MediaPbrt, HomogeneousTakesPbrtV4sDefaults) {
  const Scene s = pbrtScene(std::string(kMediaUnmirrored) +
                            "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\"\n"
                            "MediumInterface \"fog\" \"\"\n" +
                            kMediaTriangle);
  ASSERT_EQ(s.media.size(), 1u);
  EXPECT_EQ(s.mediumNames, std::vector<std::string>{"fog"});
  const Medium& m = s.media[0];
  EXPECT_EQ(m.type, kMediumHomogeneous);
  EXPECT_EQ(m.sigmaA, vec3(1.0f));
  EXPECT_EQ(m.sigmaS, vec3(1.0f));
  EXPECT_EQ(m.g, 0.0f);
  EXPECT_EQ(m.Le, vec3(0.0f));
  EXPECT_EQ(m.emissive, kEmitsNothing);
  EXPECT_EQ(m.density, kNoGrid);
  EXPECT_EQ(m.majorants, kNoGrid);
  EXPECT_EQ(m.emission, kNoGrid);
  EXPECT_TRUE(s.mediumGrids.empty());
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
}

TEST(MediaPbrt, HomogeneousScalesCoefficientsAndEmission) {
  const Scene s = pbrtScene(std::string(kMediaUnmirrored) +
                            "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\"\n"
                            "  \"rgb sigma_a\" [1 2 3] \"rgb sigma_s\" [4 5 6] \"float scale\" 2\n"
                            "  \"float g\" 0.5 \"rgb Le\" [1 2 3] \"float Lescale\" 3\n"
                            "MediumInterface \"fog\"\n" +
                            kMediaTriangle);
  ASSERT_EQ(s.media.size(), 1u);
  const Medium& m = s.media[0];
  EXPECT_EQ(m.sigmaA, vec3(2.0f, 4.0f, 6.0f));
  EXPECT_EQ(m.sigmaS, vec3(8.0f, 10.0f, 12.0f));
  EXPECT_EQ(m.g, 0.5f);
  EXPECT_EQ(m.Le, vec3(3.0f, 6.0f, 9.0f));
  EXPECT_EQ(m.emissive, kEmitsLe);
  // One name: the medium on both sides.
  ASSERT_EQ(s.mediumInterfaces.size(), 1u);
  EXPECT_EQ(s.mediumInterfaces[0].inside, 0u);
  EXPECT_EQ(s.mediumInterfaces[0].outside, 0u);
}

TEST(MediaPbrt, PresetsArePbrtV4sMeasuredMediaWithSigmaPrimeSAsSigmaS) {
  const Scene s = pbrtScene(std::string(kMediaUnmirrored) +
                            "MakeNamedMedium \"k\" \"string type\" \"homogeneous\"\n"
                            "  \"string preset\" \"Ketchup\" \"float scale\" 10\n"
                            "MediumInterface \"k\" \"\"\n" +
                            kMediaTriangle);
  ASSERT_EQ(s.media.size(), 1u);
  // Jensen et al. 2001: Ketchup's sigma'_s (0.18, 0.07, 0.03), sigma_a (0.061, 0.97, 1.45).
  expectNearMedia(s.media[0].sigmaS, glm::dvec3(1.8, 0.7, 0.3), "sigma_s");
  expectNearMedia(s.media[0].sigmaA, glm::dvec3(0.61, 9.7, 14.5), "sigma_a");
  ASSERT_NE(findMediumPreset("Regular Milk"), nullptr);
  EXPECT_EQ(findMediumPreset("Regular Milk")->sigmaPrimeS, vec3(4.5513f, 5.8294f, 7.136f));
  EXPECT_EQ(mediumPresetNames().size(), 47u);

  // With a preset pbrt-v4 reads neither sigma_a nor sigma_s: they are reported unused.
  const Scene both = pbrtScene(std::string(kMediaUnmirrored) +
                               "MakeNamedMedium \"k\" \"string type\" \"homogeneous\"\n"
                               "  \"string preset\" \"Apple\" \"rgb sigma_a\" [9 9 9]\n"
                               "MediumInterface \"k\" \"\"\n" +
                               kMediaTriangle);
  EXPECT_EQ(both.media[0].sigmaA, vec3(0.0030f, 0.0034f, 0.046f));
  ASSERT_EQ(both.warnings.size(), 1u);
  EXPECT_NE(both.warnings[0].find("sigma_a"), std::string::npos) << both.warnings[0];

  // An unknown preset: warned as pbrt-v4 does, sigma_a and sigma_s used.
  const Scene unknown = pbrtScene(std::string(kMediaUnmirrored) +
                                  "MakeNamedMedium \"k\" \"string type\" \"homogeneous\"\n"
                                  "  \"string preset\" \"Ketchp\" \"rgb sigma_a\" [2 2 2]\n"
                                  "MediumInterface \"k\" \"\"\n" +
                                  kMediaTriangle);
  EXPECT_EQ(unknown.media[0].sigmaA, vec3(2.0f));
  ASSERT_EQ(unknown.warnings.size(), 1u);
  EXPECT_EQ(unknown.warnings[0],
            "scene.pbrt:6: MakeNamedMedium 'k': unknown preset 'Ketchp' (did you mean "
            "'Ketchup'?) (pbrt-v4 warns too): sigma_a and sigma_s are used");
}

// ---- pbrt-v4: grids -----------------------------------------------------------------------

TEST(MediaPbrt, UniformGridStoresDensityXFastestAndItsEmissionGrid) {
  const Scene s =
      pbrtScene(std::string(kMediaUnmirrored) +
                "MakeNamedMedium \"smoke\" \"string type\" \"uniformgrid\"\n"
                "  \"integer nx\" 3 \"integer ny\" 2 \"integer nz\" 1\n"
                "  \"float density\" [0 1 2 3 4 5] \"point3 p0\" [-1 -2 -3] \"point3 p1\" [1 2 3]\n"
                "  \"rgb sigma_a\" [0.5 1 2] \"float scale\" 4 \"rgb Le\" [1 0.5 0.25]\n"
                "  \"float Lescale\" [6 7 8 9 10 11]\n"
                "MediumInterface \"smoke\" \"\"\n" +
                kMediaTriangle);
  ASSERT_EQ(s.media.size(), 1u);
  const Medium& m = s.media[0];
  EXPECT_EQ(m.type, kMediumUniformGrid);
  EXPECT_EQ(m.size, uvec3(3, 2, 1));
  EXPECT_EQ(m.boundsMin, vec3(-1, -2, -3));
  EXPECT_EQ(m.boundsMax, vec3(1, 2, 3));
  EXPECT_EQ(m.sigmaA, vec3(2.0f, 4.0f, 8.0f));  // times scale
  EXPECT_EQ(m.sigmaS, vec3(4.0f));              // pbrt-v4's default 1, times scale
  EXPECT_EQ(m.Le, vec3(1.0f, 0.5f, 0.25f));
  EXPECT_EQ(m.emissive, kEmitsLe);
  EXPECT_EQ(m.majorants, kNoGrid);
  // The file's order is pbrt-v4's SampledGrid order, (z * ny + y) * nx + x: kept as it is.
  EXPECT_EQ(grid(s, m.density, 6), (std::vector<float>{0, 1, 2, 3, 4, 5}));
  ASSERT_NE(m.emission, kNoGrid);
  EXPECT_EQ(grid(s, m.emission, 6), (std::vector<float>{6, 7, 8, 9, 10, 11}));
  EXPECT_EQ(s.mediumGrids.size(), 12u);
  EXPECT_EQ(densityFloats(m, s.mediumGrids), 6u);
  EXPECT_EQ(emissionFloats(m, s.mediumGrids), 6u);

  // Without Le it does not emit, and its Lescale grid is not kept; defaults p0 (0 0 0),
  // p1 (1 1 1), nx = ny = nz = 1.
  const Scene dark = pbrtScene(std::string(kMediaUnmirrored) +
                               "MakeNamedMedium \"smoke\" \"string type\" \"uniformgrid\"\n"
                               "  \"float density\" [2] \"float Lescale\" [3]\n"
                               "MediumInterface \"smoke\" \"\"\n" +
                               kMediaTriangle);
  const Medium& d = dark.media[0];
  EXPECT_EQ(d.emissive, kEmitsNothing);
  EXPECT_EQ(d.emission, kNoGrid);
  EXPECT_EQ(d.size, uvec3(1));
  EXPECT_EQ(d.boundsMin, vec3(0.0f));
  EXPECT_EQ(d.boundsMax, vec3(1.0f));
  EXPECT_EQ(dark.mediumGrids, std::vector<float>{2.0f});
}

TEST(MediaPbrt, RgbGridHasItsScalesInItsGrids) {
  const Scene s =
      pbrtScene(std::string(kMediaUnmirrored) +
                "MakeNamedMedium \"c\" \"string type\" \"rgbgrid\"\n"
                "  \"integer nx\" 2 \"rgb sigma_a\" [1 2 3  4 5 6]\n"
                "  \"rgb sigma_s\" [0.5 0.5 0.5  1 1 1] \"float scale\" 2\n"
                "  \"rgb Le\" [2 4 6  8 10 12] \"float Lescale\" 0.5 \"float g\" -0.25\n"
                "MediumInterface \"\" \"c\"\n" +
                kMediaTriangle);
  ASSERT_EQ(s.media.size(), 1u);
  const Medium& m = s.media[0];
  EXPECT_EQ(m.type, kMediumRgbGrid);
  EXPECT_EQ(m.size, uvec3(2, 1, 1));
  EXPECT_EQ(m.g, -0.25f);
  EXPECT_EQ(m.sigmaA, vec3(1.0f));
  EXPECT_EQ(m.sigmaS, vec3(1.0f));
  EXPECT_EQ(m.Le, vec3(1.0f));
  EXPECT_EQ(m.emissive, kEmitsLe);
  // sigma_a's RGB per voxel, then sigma_s's, times scale; then Le times Lescale.
  EXPECT_EQ(grid(s, m.density, 12), (std::vector<float>{2, 4, 6, 8, 10, 12, 1, 1, 1, 2, 2, 2}));
  EXPECT_EQ(grid(s, m.emission, 6), (std::vector<float>{1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(s.mediumInterfaces[0].inside, kNoMedium);
  EXPECT_EQ(s.mediumInterfaces[0].outside, 0u);

  // A missing sigma_s is pbrt-v4's constant 1 (times scale), stored as a grid, warned.
  const Scene one = pbrtScene(std::string(kMediaUnmirrored) +
                              "MakeNamedMedium \"c\" \"string type\" \"rgbgrid\"\n"
                              "  \"rgb sigma_a\" [1 2 3] \"float scale\" 3\n"
                              "MediumInterface \"\" \"c\"\n" +
                              kMediaTriangle);
  EXPECT_EQ(one.mediumGrids, (std::vector<float>{3, 6, 9, 3, 3, 3}));
  EXPECT_EQ(one.media[0].emission, kNoGrid);
  EXPECT_EQ(one.media[0].emissive, kEmitsNothing);
  ASSERT_EQ(one.warnings.size(), 1u);
  EXPECT_NE(one.warnings[0].find("grid of ones"), std::string::npos) << one.warnings[0];
}

TEST(MediaPbrt, TheCtmAtMakeNamedMediumPlacesAGrid) {
  const std::string grid =
      "MakeNamedMedium \"g\" \"string type\" \"uniformgrid\" \"float density\" [1]\n";
  const std::string use = "MediumInterface \"g\" \"\"\n" + std::string(kMediaTriangle);
  // Medium to world: translate (1, 2, 3) after a scale by 2.
  const Scene s = pbrtScene(std::string(kMediaUnmirrored) + "AttributeBegin\nTranslate 1 2 3\n" +
                            "Scale 2 2 2\n" + grid + "AttributeEnd\n" + use);
  const Medium& m = s.media[0];
  expectNearMedia(toMedium(m, {1, 2, 3}), {0, 0, 0}, "origin");
  expectNearMedia(toMedium(m, {3, 2, 3}), {1, 0, 0}, "x");
  expectNearMedia(toMedium(m, {1, 2, 5}), {0, 0, 1}, "z");
  EXPECT_EQ(m.toMedium0, vec4(0.5f, 0.0f, 0.0f, -0.5f));

  // A camera that pbrt's left-handed space makes this renderer mirror in x: the medium is
  // mirrored with the triangles.
  const Scene mirrored = pbrtScene(
      "LookAt 0 0 -10  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\nTranslate 1 2 3\n" + grid +
      use);
  expectNearMedia(toMedium(mirrored.media[0], {-1, 2, 3}), {0, 0, 0}, "mirrored origin");
  expectNearMedia(toMedium(mirrored.media[0], {-2, 2, 3}), {1, 0, 0}, "mirrored x");

  // Before the Camera directive pbrt-v4 takes the CTM in its render space, the world moved
  // to the camera's position (0, 0, -10).
  const Scene before = pbrtScene(grid + "Scale -1 1 1\nLookAt 0 0 -10  0 0 0  0 1 0\n" +
                                 "Camera \"perspective\"\nWorldBegin\n" + use);
  expectNearMedia(toMedium(before.media[0], {0, 0, -10}), {0, 0, 0}, "before the camera");

  // Homogeneous media ignore it.
  const Scene homogeneous =
      pbrtScene(std::string(kMediaUnmirrored) + "Scale 0 0 0\n" +
                "MakeNamedMedium \"h\" \"string type\" \"homogeneous\"\nIdentity\n" +
                "MediumInterface \"h\" \"\"\n" + kMediaTriangle);
  EXPECT_EQ(homogeneous.media[0].toMedium0, vec4(1, 0, 0, 0));
}

// ---- pbrt-v4: interfaces, the camera, interface shapes -----------------------------------

TEST(MediaPbrt, EveryTriangleGetsTheInterfaceOfItsShapeThroughDropsAndInstances) {
  const Scene s = pbrtScene(
      std::string(kMediaUnmirrored) +
      "MakeNamedMedium \"a\" \"string type\" \"homogeneous\"\n"
      "MakeNamedMedium \"b\" \"string type\" \"homogeneous\" \"float g\" 0.5\n"
      "ObjectBegin \"o\"\n"
      "  MediumInterface \"b\" \"a\"\n" +
      kMediaTriangle + "ObjectEnd\n" +
      // 0: vacuum; 1, 2: a inside, vacuum outside (one zero-area triangle between them dropped)
      kMediaTriangle +
      "AttributeBegin\n  MediumInterface \"a\" \"\"\n"
      "  Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0 2 0 0 0 0 1]\n"
      "    \"integer indices\" [0 1 2  0 1 3  0 1 4]\n"
      // interface material without a transition: dropped
      "  AttributeBegin\n    Material \"interface\"\n    MediumInterface \"a\"\n" +
      kMediaTriangle +
      "  AttributeEnd\nAttributeEnd\n"
      // 3: vacuum again after AttributeEnd; 4, 5: the instance, its definition's interface,
      // whatever is current at its use
      + kMediaTriangle + "MediumInterface \"a\" \"b\"\nObjectInstance \"o\"\nTranslate 0 0 1\n" +
      "ObjectInstance \"o\"\n");
  ASSERT_EQ(s.triangles.size(), 6u);
  ASSERT_EQ(s.mediumInterfaces.size(), s.triangles.size());
  ASSERT_EQ(s.mediumNames, (std::vector<std::string>{"a", "b"}));
  const uint a = 0, b = 1, none = kNoMedium;
  const std::vector<std::pair<uint, uint>> expected = {{none, none}, {a, none}, {a, none},
                                                       {none, none}, {b, a},    {b, a}};
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(s.mediumInterfaces[i].inside, expected[i].first) << i;
    EXPECT_EQ(s.mediumInterfaces[i].outside, expected[i].second) << i;
    EXPECT_EQ(s.triangles[i].primitive, i);
  }
  EXPECT_EQ(s.triangles[4].v0.z, 0.0f);
  EXPECT_EQ(s.triangles[5].v0.z, 1.0f);
}

TEST(MediaPbrt, TheCameraIsInTheOutsideMediumCurrentAtCamera) {
  const Scene s = pbrtScene(
      "MediumInterface \"fog\" \"water\"\nScale -1 1 1\nLookAt 0 0 -10  0 0 0  0 1 0\n"
      "Camera \"perspective\"\nMediumInterface \"\"\n"
      "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\"\n"
      "MakeNamedMedium \"water\" \"string type\" \"homogeneous\" \"float scale\" 2\n"
      "WorldBegin\n" +
      std::string(kMediaTriangle));
  // Only water is used: fog, named inside, is not kept.
  ASSERT_EQ(s.media.size(), 1u);
  EXPECT_EQ(s.mediumNames[0], "water");
  EXPECT_EQ(s.cameraMedium, 0u);
  EXPECT_EQ(s.media[0].sigmaA, vec3(2.0f));
  // The triangle after MediumInterface "": vacuum on both sides, kept parallel.
  ASSERT_EQ(s.mediumInterfaces.size(), 1u);
  EXPECT_EQ(s.mediumInterfaces[0].inside, kNoMedium);
  EXPECT_EQ(s.mediumInterfaces[0].outside, kNoMedium);
}

TEST(MediaPbrt, InterfaceShapesAreKeptWhereTheyBoundAMedium) {
  const std::string fog = "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\"\n";
  const Scene s =
      pbrtScene(std::string(kMediaUnmirrored) + fog + kMediaTriangle +
                "AttributeBegin\nMaterial \"interface\"\nMediumInterface \"fog\" \"\"\n" +
                kMediaTriangle + "AttributeEnd\n" +
                // defined after its use, with an area light: the light is ignored
                "AttributeBegin\nNamedMaterial \"later\"\nMediumInterface \"\" \"fog\"\n" +
                "AreaLightSource \"diffuse\"\n" + kMediaTriangle + "AttributeEnd\n" +
                "MakeNamedMaterial \"later\" \"string type\" \"interface\"\n");
  ASSERT_EQ(s.triangles.size(), 3u);
  ASSERT_EQ(s.materials.size(), 3u);
  EXPECT_EQ(s.materials[s.triangles[0].material].type, kMaterialDiffuse);
  for (int i : {1, 2}) {
    const Material& m = s.materials[s.triangles[i].material];
    EXPECT_EQ(m.type, kMaterialInterface) << i;
    EXPECT_EQ(m.emission, vec3(0.0f)) << i;
  }
  EXPECT_EQ(s.mediumInterfaces[1].inside, 0u);
  EXPECT_EQ(s.mediumInterfaces[2].outside, 0u);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("area light on shapes with the \"interface\" material is ignored"),
            std::string::npos)
      << s.warnings[0];

  // Without a medium they change nothing and go silently; the scene has no media fields.
  const Scene none =
      pbrtScene(std::string(kMediaUnmirrored) + fog + kMediaTriangle + "Material \"interface\"\n" +
                kMediaTriangle + "MediumInterface \"fog\"\n" + kMediaTriangle);
  EXPECT_EQ(none.triangles.size(), 1u);
  EXPECT_TRUE(none.warnings.empty());
  expectNoMedia(none);
}

TEST(MediaPbrt, ScenesWithoutMediaHaveEmptyMediaFields) {
  expectNoMedia(loadScene(test::kConfigs / "cornell-box.pbrt"));
  // Media defined but used by no shape and not the camera: left out.
  expectNoMedia(pbrtScene(std::string(kMediaUnmirrored) +
                          "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\"\n" +
                          "MakeNamedMedium \"g\" \"string type\" \"uniformgrid\" "
                          "\"float density\" [1]\n" +
                          kMediaTriangle));
}

TEST(MediaPbrt, UnusedMediaAndTheirGridsAreLeftOut) {
  const Scene s = pbrtScene(std::string(kMediaUnmirrored) +
                            "MakeNamedMedium \"big\" \"string type\" \"uniformgrid\" "
                            "\"integer nx\" 4 \"float density\" [1 2 3 4]\n"
                            "MakeNamedMedium \"small\" \"string type\" \"uniformgrid\" "
                            "\"integer nx\" 2 \"float density\" [5 6] \"rgb Le\" [1 1 1] "
                            "\"float Lescale\" [7 8]\n"
                            "MediumInterface \"small\" \"\"\n" +
                            kMediaTriangle);
  ASSERT_EQ(s.media.size(), 1u);
  EXPECT_EQ(s.mediumNames[0], "small");
  EXPECT_EQ(s.mediumGrids, (std::vector<float>{5, 6, 7, 8}));
  EXPECT_EQ(s.media[0].density, 0u);
  EXPECT_EQ(s.media[0].emission, 2u);
}

TEST(MediaPbrt, CloudsAreRead) {
  // A cloud: pbrt-v4's parameters and defaults (wispiness 1, frequency 5, p0 0 0 0, p1 1 1 1).
  const Scene cloud =
      pbrtScene(std::string(kMediaUnmirrored) +
                "MakeNamedMedium \"c\" \"string type\" \"cloud\" \"float density\" 2\n"
                "MediumInterface \"c\" \"\"\n" +
                kMediaTriangle);
  ASSERT_EQ(cloud.media.size(), 1u);
  EXPECT_EQ(cloud.media[0].type, kMediumCloud);
  EXPECT_EQ(cloud.media[0].Le, vec3(2.0f, 1.0f, 5.0f));
  EXPECT_EQ(cloud.media[0].boundsMin, vec3(0.0f));
  EXPECT_EQ(cloud.media[0].boundsMax, vec3(1.0f));
  EXPECT_TRUE(cloud.warnings.empty());
  // A nanovdb medium names its file: a missing one is an error at the parameter.
  EXPECT_EQ(pbrtError(std::string(kMediaUnmirrored) +
                      "MakeNamedMedium \"vdb\" \"string type\" \"nanovdb\"\n"
                      "MediumInterface \"vdb\" \"\"\n" +
                      kMediaTriangle),
            "scene.pbrt:5:1: MakeNamedMedium 'vdb': a \"nanovdb\" medium needs a \"string "
            "filename\"");
}

// A uniformgrid's temperature grid: pbrt-v4's blackbody emission, stored after a blackbody
// table up to the hottest voxel, then the Lescale grid where there is one; "temperaturecutoff"
// is read where "temperatureoffset" is missing.
TEST(MediaPbrt, UniformGridTemperaturesEmitBlackbody) {
  const auto medium = [](const std::string& params) {
    const Scene s = pbrtScene(std::string(kMediaUnmirrored) +
                              "MakeNamedMedium \"g\" \"string type\" \"uniformgrid\" "
                              "\"integer nx\" 2 \"float density\" [1 1] " +
                              params + "\nMediumInterface \"g\" \"\"\n" + kMediaTriangle);
    EXPECT_TRUE(s.warnings.empty());
    return s;
  };
  const Scene hot = medium(
      "\"float temperature\" [1500 800] \"float temperaturecutoff\" 300 "
      "\"float temperaturescale\" 2");
  ASSERT_EQ(hot.media.size(), 1u);
  const Medium& m = hot.media[0];
  EXPECT_EQ(m.emissive, kEmitsBlackbody);
  EXPECT_EQ(m.Le, vec3(0.0f, 300.0f, 2.0f));  // no Lescale grid: pbrt-v4's one voxel of 1
  EXPECT_EQ(hot.mediumGrids[m.emission], (1500.0f - 300.0f) * 2.0f);  // the table's top
  EXPECT_EQ(emissionFloats(m, hot.mediumGrids), kBlackbodyTableFloats + 2u);
  EXPECT_EQ(hot.mediumGrids[m.emission + kBlackbodyTableFloats + 1u], 800.0f);

  const Scene scaled = medium("\"float temperature\" [1500 800] \"float Lescale\" [0.5 0.25]");
  const Medium& s = scaled.media[0];
  EXPECT_EQ(s.emissive, kEmitsBlackbody);
  EXPECT_EQ(s.Le, vec3(1.0f, 0.0f, 1.0f));
  EXPECT_EQ(emissionFloats(s, scaled.mediumGrids), kBlackbodyTableFloats + 4u);
  EXPECT_EQ(scaled.mediumGrids[s.emission + kBlackbodyTableFloats + 3u], 0.25f);

  // Nothing above 100 K once offset, or a Lescale of zeros: it does not emit.
  EXPECT_EQ(
      medium("\"float temperature\" [150 90] \"float temperatureoffset\" 60").media[0].emissive,
      kEmitsNothing);
  EXPECT_EQ(medium("\"float temperature\" [1500 800] \"float Lescale\" [0 0]").media[0].emissive,
            kEmitsNothing);

  EXPECT_EQ(pbrtError(std::string(kMediaUnmirrored) +
                      "MakeNamedMedium \"g\" \"string type\" \"uniformgrid\" "
                      "\"float density\" [1] \"float temperature\" [1 2]\n"
                      "MediumInterface \"g\" \"\"\n" +
                      kMediaTriangle),
            "scene.pbrt:5:69: 'temperature' of MakeNamedMedium 'g': has 2 values; expected nx * "
            "ny * nz = 1");
  EXPECT_EQ(pbrtError(std::string(kMediaUnmirrored) +
                      "MakeNamedMedium \"g\" \"string type\" \"uniformgrid\" "
                      "\"float density\" [1] \"float temperature\" [1000] \"rgb Le\" [1 1 1]\n"
                      "MediumInterface \"g\" \"\"\n" +
                      kMediaTriangle),
            "scene.pbrt:5:69: 'temperature' of MakeNamedMedium 'g': a medium emits by \"Le\" or "
            "by \"temperature\", not both (pbrt-v4's rule)");
}

TEST(MediaPbrt, EveryErrorIsOneLineAtItsPlace) {
  const std::string w = kMediaUnmirrored;
  const std::string use = "MediumInterface \"m\" \"\"\n" + std::string(kMediaTriangle);
  const auto grid = [&](const std::string& params) {
    return w + "MakeNamedMedium \"m\" \"string type\" \"uniformgrid\" " + params + "\n" + use;
  };
  const auto rgb = [&](const std::string& params) {
    return w + "MakeNamedMedium \"m\" \"string type\" \"rgbgrid\" " + params + "\n" + use;
  };
  const std::pair<std::string, std::string> cases[] = {
      {w +
           "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\"\n"
           "MediumInterface \"fgo\" \"\"\n" +
           kMediaTriangle,
       "scene.pbrt:6:17: MediumInterface: no medium named 'fgo' (did you mean 'fog'?)"},
      {w + "MediumInterface \"\" \"nowhere\"\n" + kMediaTriangle,
       "scene.pbrt:5:20: MediumInterface: no medium named 'nowhere'"},
      {w +
           "MakeNamedMedium \"m\" \"string type\" \"homogeneous\"\n"
           "MakeNamedMedium \"m\" \"string type\" \"homogeneous\"\n" +
           use,
       "scene.pbrt:6:1: named medium 'm' redefined (first at scene.pbrt:5)"},
      {w + "MakeNamedMedium \"m\" \"float g\" 0\n" + use,
       "scene.pbrt:5:1: MakeNamedMedium 'm' needs a \"string type\" parameter"},
      {w + "MakeNamedMedium \"m\" \"string type\" \"homogenous\"\n" + use,
       "scene.pbrt:5:21: MakeNamedMedium 'm': unknown medium type 'homogenous' (did you mean "
       "'homogeneous'?)"},
      {w + "MakeNamedMedium \"m\" \"string type\" \"heterogeneous\"\n" + use,
       "scene.pbrt:5:21: MakeNamedMedium 'm': unknown medium type 'heterogeneous' (pbrt-v3's "
       "name of pbrt-v4's \"uniformgrid\")"},
      {w + "MakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"float g\" 1.5\n" + use,
       "scene.pbrt:5:49: 'g' of MakeNamedMedium 'm': expected a number in [-1, 1], got 1.5"},
      {w + "MakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"float scale\" -1\n" + use,
       "scene.pbrt:5:49: 'scale' of MakeNamedMedium 'm': expected a non-negative number that "
       "fits a 32-bit float, got -1"},
      {w + "MakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [1 -1 1]\n" + use,
       "scene.pbrt:5:49: rgb 'sigma_a' of MakeNamedMedium 'm' has a negative component"},
      {w +
           "MakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"rgb sigma_s\" [1e38 1 1] "
           "\"float scale\" 10\n" +
           use,
       "scene.pbrt:5:74: 'scale' of MakeNamedMedium 'm': 'sigma_s' times 'scale' does not fit a "
       "32-bit float"},
      {grid(""),
       "scene.pbrt:5:1: 'density' of MakeNamedMedium 'm': is required: one value per "
       "voxel"},
      {grid("\"integer nx\" 2 \"integer ny\" 2 \"float density\" [1 2 3]"),
       "scene.pbrt:5:79: 'density' of MakeNamedMedium 'm': has 3 values; expected nx * ny * nz "
       "= 4"},
      {grid("\"integer nx\" 2 \"float density\" [1 -2]"),
       "scene.pbrt:5:64: 'density' of MakeNamedMedium 'm', its value [1]: expected a "
       "non-negative number that fits a 32-bit float, got -2"},
      {grid("\"integer nz\" 0 \"float density\" [1]"),
       "scene.pbrt:5:49: 'nz' of MakeNamedMedium 'm': expected a number of voxels of at least 1, "
       "got 0"},
      {grid("\"float density\" [1] \"point3 p1\" [1 0 1]"),
       "scene.pbrt:5:69: 'p1' of MakeNamedMedium 'm': expected p0 < p1 on every axis, got p0 "
       "(0, 0, 0) and p1 (1, 0, 1)"},
      {grid("\"float density\" [1 2] \"integer nx\" 2 \"float Lescale\" [1]"),
       "scene.pbrt:5:86: 'Lescale' of MakeNamedMedium 'm': has 1 value; expected nx * ny * nz "
       "= 2"},
      {grid("\"float density\" [1] \"rgb Le\" [1 1 1] \"float temperature\" [1000]"),
       "scene.pbrt:5:86: 'temperature' of MakeNamedMedium 'm': a medium emits by \"Le\" or by "
       "\"temperature\", not both (pbrt-v4's rule)"},
      {grid("\"integer nx\" 2 \"float density\" [1 1] \"float temperature\" [-20 1e39]"),
       "scene.pbrt:5:86: 'temperature' of MakeNamedMedium 'm', its value [1]: expected a number "
       "that fits a 32-bit float, got inf"},
      {grid("\"float density\" [1] \"float temperature\" [1000 2000]"),
       "scene.pbrt:5:69: 'temperature' of MakeNamedMedium 'm': has 2 values; expected nx * ny * "
       "nz = 1"},
      {rgb("\"float scale\" 2"),
       "scene.pbrt:5:1: 'sigma_a' of MakeNamedMedium 'm': an rgbgrid needs \"sigma_a\" or "
       "\"sigma_s\" (or both)"},
      {rgb("\"rgb sigma_s\" [1 1 1] \"rgb Le\" [1 1 1]"),
       "scene.pbrt:5:67: 'Le' of MakeNamedMedium 'm': an rgbgrid with \"Le\" needs \"sigma_a\" "
       "too (pbrt-v4's rule)"},
      {rgb("\"integer nx\" 2 \"rgb sigma_a\" [1 1 1]"),
       "scene.pbrt:5:60: 'sigma_a' of MakeNamedMedium 'm': has 1 RGB value; expected nx * ny * "
       "nz = 2"},
      {w +
           "Scale 1 0 1\nMakeNamedMedium \"m\" \"string type\" \"uniformgrid\" \"float density\" "
           "[1]\nIdentity\n" +
           use,
       "scene.pbrt:6:1: MakeNamedMedium 'm': the CTM is singular or too large (a grid medium "
       "needs an invertible transform)"},
  };
  for (const auto& [text, message] : cases) EXPECT_EQ(pbrtError(text), message) << text;
}

// ---- JSON --------------------------------------------------------------------------------

// A scene of one diffuse triangle (normal +z) with `media` as its "media", `shape` as more keys
// of the shape, `camera` as keys of the camera and `more` as more top-level keys.
std::string jsonText(const std::string& media, const std::string& shape = "",
                     const std::string& camera = "", const std::string& more = "") {
  return R"({"camera": {"position": [0, 0, 5], "target": [0, 0, 0])" + camera +
         R"(}, "materials": [{"name": "white"}, {"name": "glass", "type": "interface"}],)" +
         (media.empty() ? "" : R"("media": )" + media + ",") + more +
         R"("shapes": [{"type": "triangles", "material": "white", "vertices": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "indices": [[0, 1, 2]])" +
         shape + "}]}";
}

Scene jsonScene(const std::string& text) {
  test::TempDir dir;
  return loadScene(dir.write("s.json", text));
}

// The error without its "<file>: " prefix.
std::string jsonError(const std::string& text) {
  test::TempDir dir;
  const fs::path path = dir.write("s.json", text);
  try {
    loadScene(path);
  } catch (const InputError& e) {
    const std::string m = e.what();
    const std::string prefix = path.string() + ": ";
    return m.rfind(prefix, 0) == 0 ? m.substr(prefix.size()) : m;
  }
  return "no error";
}

TEST(MediaJson, HomogeneousWithDefaultsAndPbrtV4sNames) {
  const Scene s = jsonScene(jsonText(R"([{"name": "fog", "type": "homogeneous"},
      {"name": "tea", "type": "homogeneous", "sigma_a": [1, 2, 3], "sigma_s": [4, 5, 6],
       "scale": 2, "g": -0.5, "Le": [1, 0, 0], "Lescale": 4}])",
                                     R"(, "interior": "tea", "exterior": "fog")"));
  ASSERT_EQ(s.media.size(), 2u);
  EXPECT_EQ(s.mediumNames, (std::vector<std::string>{"fog", "tea"}));
  EXPECT_EQ(s.media[0].sigmaA, vec3(1.0f));
  EXPECT_EQ(s.media[0].sigmaS, vec3(1.0f));
  EXPECT_EQ(s.media[0].g, 0.0f);
  EXPECT_EQ(s.media[0].emissive, kEmitsNothing);
  const Medium& tea = s.media[1];
  EXPECT_EQ(tea.sigmaA, vec3(2, 4, 6));
  EXPECT_EQ(tea.sigmaS, vec3(8, 10, 12));
  EXPECT_EQ(tea.g, -0.5f);
  EXPECT_EQ(tea.Le, vec3(4, 0, 0));
  EXPECT_EQ(tea.emissive, kEmitsLe);
  ASSERT_EQ(s.mediumInterfaces.size(), 1u);
  EXPECT_EQ(s.mediumInterfaces[0].inside, 1u);
  EXPECT_EQ(s.mediumInterfaces[0].outside, 0u);
  EXPECT_EQ(s.cameraMedium, kNoMedium);
}

TEST(MediaJson, PresetsAreThePbrtTable) {
  const Scene s = jsonScene(
      jsonText(R"([{"name": "milk", "type": "homogeneous", "preset": "Wholemilk", "scale": 100}])",
               "", R"(, "medium": "milk")"));
  ASSERT_EQ(s.media.size(), 1u);
  expectNearMedia(s.media[0].sigmaS, glm::dvec3(255, 321, 377), "sigma_s");
  expectNearMedia(s.media[0].sigmaA, glm::dvec3(0.11, 0.24, 1.4), "sigma_a");
  EXPECT_EQ(s.cameraMedium, 0u);
  // Only the camera uses it: every triangle has vacuum on both sides, kept parallel.
  ASSERT_EQ(s.mediumInterfaces.size(), 1u);
  EXPECT_EQ(s.mediumInterfaces[0].inside, kNoMedium);
}

TEST(MediaJson, GridsTheirOrderOffsetsAndTransform) {
  const Scene s = jsonScene(jsonText(
      R"([{"name": "unused", "type": "uniformgrid", "nx": 2, "density": [9, 9]},
          {"name": "smoke", "type": "uniformgrid", "nx": 2, "ny": 1, "nz": 2,
           "density": [0, 1, 2, 3], "p0": [-1, -1, -1], "p1": [1, 1, 1], "sigma_s": [2, 2, 2],
           "Le": [1, 1, 1], "Lescale": [4, 5, 6, 7],
           "transform": {"scale": 2, "translate": [10, 0, 0]}},
          {"name": "cloud", "type": "rgbgrid", "nx": 2, "sigma_a": [[1, 2, 3], [4, 5, 6]],
           "scale": 0.5, "Le": [[2, 2, 2], [0, 0, 0]], "Lescale": 3}])",
      R"(, "interior": "smoke", "exterior": "cloud")"));
  // "unused" is left out with its grid; the others' grids follow in their order.
  ASSERT_EQ(s.mediumNames, (std::vector<std::string>{"smoke", "cloud"}));
  const Medium& smoke = s.media[0];
  EXPECT_EQ(smoke.type, kMediumUniformGrid);
  EXPECT_EQ(smoke.size, uvec3(2, 1, 2));
  EXPECT_EQ(smoke.sigmaA, vec3(1.0f));
  EXPECT_EQ(smoke.sigmaS, vec3(2.0f));
  EXPECT_EQ(smoke.density, 0u);
  EXPECT_EQ(smoke.emission, 4u);
  const Medium& cloud = s.media[1];
  EXPECT_EQ(cloud.type, kMediumRgbGrid);
  EXPECT_EQ(cloud.density, 8u);
  EXPECT_EQ(cloud.emission, 20u);
  EXPECT_EQ(s.mediumGrids, (std::vector<float>{0,    1,    2,    3,    4,    5, 6,    7,  // smoke
                                               0.5f, 1,    1.5f, 2,    2.5f, 3, 0.5f, 0.5f,
                                               0.5f, 0.5f, 0.5f, 0.5f,  // cloud
                                               6,    6,    6,    0,    0,    0}));
  // World (10, 0, 0) is the medium's origin, world (12, 0, 0) its (1, 0, 0).
  expectNearMedia(toMedium(smoke, {10, 0, 0}), {0, 0, 0}, "origin");
  expectNearMedia(toMedium(smoke, {12, 0, 0}), {1, 0, 0}, "x");
  EXPECT_EQ(cloud.toMedium0, vec4(1, 0, 0, 0));
}

// A uniformgrid's temperatures, offset and scale, as the pbrt-v4 reader takes them.
TEST(MediaJson, UniformGridTemperatures) {
  const Scene s = jsonScene(jsonText(
      R"([{"name": "fire", "type": "uniformgrid", "nx": 2, "density": [1, 1],
           "temperature": [1200, 2000], "temperatureoffset": 200, "temperaturescale": 3}])",
      R"(, "interior": "fire")"));
  ASSERT_EQ(s.media.size(), 1u);
  const Medium& m = s.media[0];
  EXPECT_EQ(m.emissive, kEmitsBlackbody);
  EXPECT_EQ(m.Le, vec3(0.0f, 200.0f, 3.0f));
  EXPECT_EQ(s.mediumGrids[m.emission], (2000.0f - 200.0f) * 3.0f);
  EXPECT_EQ(s.mediumGrids[m.emission + kBlackbodyTableFloats], 1200.0f);
}

TEST(MediaJson, InterfaceShapesAreKeptOnlyWhereTheyBoundAMedium) {
  const std::string media = R"([{"name": "fog", "type": "homogeneous"}])";
  const std::string glass =
      R"(}, {"type": "quad", "material": "glass", "vertices": [[0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]])";
  const Scene kept = jsonScene(jsonText(media, glass + R"(, "exterior": "fog")"));
  ASSERT_EQ(kept.triangles.size(), 3u);
  EXPECT_EQ(kept.materials[kept.triangles[1].material].type, kMaterialInterface);
  EXPECT_EQ(kept.mediumInterfaces[1].outside, 0u);
  EXPECT_EQ(kept.mediumInterfaces[0].outside, kNoMedium);
  const Scene dropped =
      jsonScene(jsonText(media, glass + R"(, "exterior": "fog", "interior": "fog")"));
  EXPECT_EQ(dropped.triangles.size(), 1u);
  expectNoMedia(dropped);
}

TEST(MediaJson, ScenesWithoutMediaHaveEmptyMediaFields) {
  expectNoMedia(loadScene(test::kConfigs / "cornell-box.json"));
  expectNoMedia(jsonScene(jsonText(R"([{"name": "fog", "type": "homogeneous"}])")));
}

TEST(MediaJson, EveryErrorNamesItsField) {
  const std::string fog = R"({"name": "fog", "type": "homogeneous")";
  std::string interfaceOnly = jsonText("");
  interfaceOnly.replace(interfaceOnly.find(R"("material": "white")"), 19, R"("material": "glass")");
  const std::pair<std::string, std::string> cases[] = {
      {jsonText(R"([)" + fog + "}]", R"(, "interior": "fgo")"),
       "shapes[0].interior: unknown medium 'fgo' (did you mean 'fog'?)"},
      {jsonText(R"([)" + fog + "}]", R"(, "exterior": "")"),
       "shapes[0].exterior: expected a medium's name (leave the key out for vacuum)"},
      {jsonText("[]", "", R"(, "medium": "air")"), "camera.medium: unknown medium 'air'"},
      {jsonText(R"([)" + fog + "}, " + fog + "}]"),
       "media[1].name: duplicate medium name 'fog' (also used by media[0])"},
      {jsonText(R"([{"name": "m", "type": "nanovdb"}])"),
       "media[0].filename: required key is missing"},
      {jsonText(R"([{"name": "m", "type": "vdb"}])"),
       "media[0].type: unknown medium type 'vdb' (expected \"homogeneous\", \"uniformgrid\", "
       "\"rgbgrid\", \"nanovdb\" or \"cloud\")"},
      {jsonText(R"([{"name": "m", "type": "cloud", "density": -1}])"),
       "media[0].density: expected a non-negative number that fits a 32-bit float, got -1"},
      {jsonText(R"([{"name": "m", "type": "homogeneous", "density": [1]}])"),
       "media[0].density: unknown key (expected 'name', 'type', 'sigma_a', 'sigma_s', 'scale', "
       "'g', 'Le', 'Lescale' or 'preset')"},
      {jsonText(R"([)" + fog + R"(, "g": 1.5}])"),
       "media[0].g: expected a number in [-1, 1], got 1.5"},
      {jsonText(R"([)" + fog + R"(, "sigma_s": [1, -2, 1]}])"),
       "media[0].sigma_s[1]: expected a non-negative number that fits a 32-bit float, got -2"},
      {jsonText(R"([)" + fog + R"(, "preset": "Ketchp"}])"),
       "media[0].preset: unknown preset 'Ketchp' (did you mean 'Ketchup'?)"},
      {jsonText(R"([)" + fog + R"(, "preset": "Apple", "sigma_a": [1, 1, 1]}])"),
       "media[0].preset: give a preset or sigma_a and sigma_s, not both"},
      {jsonText(R"([{"name": "m", "type": "uniformgrid", "nx": 2, "density": [1]}])"),
       "media[0].density: has 1 value; expected nx * ny * nz = 2"},
      {jsonText(R"([{"name": "m", "type": "uniformgrid"}])"),
       "media[0]: 'density': is required: one value per voxel"},
      {jsonText(R"([{"name": "m", "type": "uniformgrid", "nx": 2, "density": [1, 1],
                     "temperature": [900]}])"),
       "media[0].temperature: has 1 value; expected nx * ny * nz = 2"},
      {jsonText(R"([{"name": "m", "type": "uniformgrid", "density": [1], "temperature": [900],
                     "Le": [1, 1, 1]}])"),
       "media[0].temperature: a medium emits by \"Le\" or by \"temperature\", not both "
       "(pbrt-v4's rule)"},
      {jsonText(R"([{"name": "m", "type": "uniformgrid", "density": [1, -1], "nx": 2}])"),
       "media[0].density[1]: expected a non-negative number that fits a 32-bit float, got -1"},
      {jsonText(R"([{"name": "m", "type": "uniformgrid", "density": [1], "p0": [0, 2, 0]}])"),
       "media[0]: 'p1': expected p0 < p1 on every axis, got p0 (0, 2, 0) and p1 (1, 1, 1)"},
      {jsonText(
           R"([{"name": "m", "type": "rgbgrid", "nx": 2, "sigma_s": [[1, 1, 1], [1, -1, 1]]}])"),
       "media[0].sigma_s[1][1]: expected a non-negative number that fits a 32-bit float, got -1"},
      {jsonText(R"([{"name": "m", "type": "rgbgrid", "sigma_a": [[1, 1]]}])"),
       "media[0].sigma_a[0]: expected an array of 3 numbers, got an array of 2 elements"},
      {jsonText(R"([{"name": "m", "type": "rgbgrid", "nx": 0, "sigma_a": [[1, 1, 1]]}])"),
       "media[0].nx: expected an integer in [1, 2147483647], got the number 0"},
      {jsonText(
           R"([{"name": "m", "type": "uniformgrid", "density": [1], "transform": {"scale": 1e-39}}])"),
       "media[0].transform: its inverse does not fit 32-bit floats (a scale too close to 0)"},
      {interfaceOnly,
       "shapes: no triangles left: all 1 have zero area or belong to \"interface\" shapes that "
       "bound no medium"},
  };
  for (const auto& [text, message] : cases) EXPECT_EQ(jsonError(text), message) << text;
}

// ---- fuzzing -------------------------------------------------------------------------------

// The media seeds of the fuzz corpora are accepted, so that the fuzzers start inside the media
// code rather than at an early error (the replay test only asks for no crash).
TEST(MediaFuzzSeeds, AreAcceptedByTheFuzzEntryPoints) {
  const fs::path corpus = fs::path(PT_SOURCE_DIR) / "fuzz" / "corpus";
  const auto bytes = [&](const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  };
  const std::string pbrt = bytes(corpus / "pbrt" / "media.pbrt");
  const std::string json = bytes(corpus / "scene" / "media.json");
  ASSERT_FALSE(pbrt.empty());
  ASSERT_FALSE(json.empty());
  EXPECT_EQ(fuzz::fuzzPbrt(reinterpret_cast<const std::uint8_t*>(pbrt.data()), pbrt.size()),
            fuzz::Outcome::kAccepted);
  EXPECT_EQ(fuzz::fuzzScene(reinterpret_cast<const std::uint8_t*>(json.data()), json.size()),
            fuzz::Outcome::kAccepted);
  const std::string nvdb = bytes(corpus / "nvdb" / "fire-zip.nvdb");
  ASSERT_FALSE(nvdb.empty());
  EXPECT_EQ(fuzz::fuzzNanoVdb(reinterpret_cast<const std::uint8_t*>(nvdb.data()), nvdb.size()),
            fuzz::Outcome::kAccepted);
  // And they do have media.
  const Scene s = loadPbrtSceneText(pbrt, "media.pbrt");
  EXPECT_EQ(s.mediumNames, (std::vector<std::string>{"air", "fog", "smoke", "cloud", "puff"}));
  EXPECT_EQ(s.cameraMedium, 0u);
}

}  // namespace
}  // namespace pt
