// Participating media (shaders/medium.h, volume_vertex.h; the CPU's volpath.cpp and the
// shader's volpath.glsl): closed forms on both backends (Beer-Lambert through a slab, a white
// furnace of a scattering medium, energy lost where the albedo is below one, a camera inside
// an absorbing medium without boundary), the samplers against their densities (the phase
// function, free-flight distances through homogeneous and grid media), CPU and lavapipe
// agreement, and the hard cases.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "chi2.h"
#include "media_scenes.h"
#include "render/prepare.h"
#include "render/prepare_media.h"
#include "render_compare.h"
#include "scene/media.h"
#include "scene/pbrt/spectra.h"
#include "test_util.h"
#include "volume_vertex.h"

namespace pt {
namespace {

using namespace media_scenes;

// ---- Closed forms ---------------------------------------------------------------------------

// A slab of absorbing medium, 1 thick along z, between the camera and an emitter of radiance 1
// that fills the view: each camera ray arrives with exp(-sigma_a / |cos|). As a homogeneous
// medium the flight takes that transmittance in closed form, so every pixel is the closed form
// up to the pixel's own sampling (the cosine varies little across it). As a grid of 2^3 voxels
// of density 1 it is delta tracked: each sample is 0 or T / T[hero] (the hero channel passes or
// not), so every pixel is within its own noise of the closed form and the image's mean within
// a fraction of a percent. The grid's density falls to 1/2 at its faces (pbrt-v4's SampledGrid
// takes voxels outside as zero), linearly over the outer half voxel: over z that leaves 7/8 of
// the slab's optical depth; the camera sees only the middle of x and y, where it is 1.
void expectBeerLambertThroughASlab(bool asGrid) {
  const vec3 sigma(0.2f, 0.5f, 1.0f);
  Scene scene;
  scene.camera = camera(vec3(0, 0, -5), vec3(0, 0, 0), 20.0f, 16);
  scene.materials = {Material{vec3(0.0f), kMaterialInterface, vec3(0.0f), 0},
                     Material{vec3(0.0f), kMaterialDiffuse, vec3(1.0f), 0}};
  const vec3 lo(-3, -3, -0.5f), hi(3, 3, 0.5f);
  scene.media = {
      asGrid ? uniformGrid(scene, lo, hi, uvec3(2), std::vector<float>(8, 1.0f), sigma, vec3(0.0f))
             : homogeneous(sigma, vec3(0.0f))};
  addShape(scene, box(lo, hi), 0, MediumInterface{0, kVacuum});
  addShape(scene, quad(vec3(0, 0, 2), vec3(0, 3, 0), vec3(3, 0, 0)), 1,
           MediumInterface{kVacuum, kVacuum});
  const SceneData data = prepare(scene, 5);
  ASSERT_TRUE(data.effects.media);
  constexpr int kSpp = 256;
  const Comparison cmp = renderBoth(data, kSpp);
  expectAgreement(cmp);
  const float depth = asGrid ? 0.875f : 1.0f;
  const Image expected = pixelAverages(data.params.camera, [&](const Ray& r) {
    const vec3 d = normalize(r.direction);
    return glm::dvec3(exp(-sigma * depth / std::fabs(d.z)));
  });
  if (!asGrid) {
    expectNearClosedForm(cmp, expected, 0.0, 1e-3);
    return;
  }
  for (const Image* image : {&cmp.cpuImage, &cmp.gpuImage}) {
    glm::dvec3 mean(0.0), expectedMean(0.0);
    for (size_t i = 0; i < expected.pixels.size(); ++i) {
      const vec3 e = expected.pixels[i];
      const double meanT = (e.x + e.y + e.z) / 3.0;
      for (int c = 0; c < 3; ++c) {
        const double sd = e[c] * std::sqrt(1.0 / meanT - 1.0) / std::sqrt(double(kSpp));
        EXPECT_NEAR(image->pixels[i][c], e[c], 5.0 * sd + 1e-4)
            << "pixel " << i << " channel " << c;
      }
      mean += glm::dvec3(image->pixels[i]);
      expectedMean += glm::dvec3(e);
    }
    const double n = double(expected.pixels.size());
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(mean[c] / n, expectedMean[c] / n, 0.012);
  }
}

TEST(MediaBothBackends, BeerLambertThroughAnAbsorbingSlab) {
  expectBeerLambertThroughASlab(false);
}

TEST(MediaBothBackends, BeerLambertThroughAnAbsorbingGridByDeltaTracking) {
  expectBeerLambertThroughASlab(true);
}

// The camera inside an absorbing medium that has no boundary, looking at an emitter 3 away:
// exp(-sigma_a d) with d the distance along each ray.
TEST(MediaBothBackends, CameraInsideAMediumWithoutBoundary) {
  const vec3 sigma(0.1f, 0.2f, 0.4f);
  Scene scene;
  scene.camera = camera(vec3(0, 0, -3), vec3(0, 0, 0), 20.0f, 8);
  scene.materials = {Material{vec3(0.0f), kMaterialDiffuse, vec3(2.0f), 0}};
  scene.media = {homogeneous(sigma, vec3(0.0f))};
  scene.cameraMedium = 0;
  addShape(scene, quad(vec3(0, 0, 0), vec3(0, 3, 0), vec3(3, 0, 0)), 0,
           MediumInterface{kVacuum, kVacuum});
  const SceneData data = prepare(scene, 5);
  const Comparison cmp = renderBoth(data, 256);
  expectAgreement(cmp);
  const Image expected = pixelAverages(data.params.camera, [&](const Ray& r) {
    const vec3 d = normalize(r.direction);
    return glm::dvec3(2.0f * exp(-sigma * (3.0f / d.z)));
  });
  expectNearClosedForm(cmp, expected, 0.0, 0.25);
  for (const Image* image : {&cmp.cpuImage, &cmp.gpuImage}) {
    glm::dvec3 mean(0.0), expectedMean(0.0);
    for (size_t i = 0; i < expected.pixels.size(); ++i) {
      mean += glm::dvec3(image->pixels[i]);
      expectedMean += glm::dvec3(expected.pixels[i]);
    }
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(mean[c] / expectedMean[c], 1.0, 0.01);
  }
}

// A diffuse wall lit by a point light, the camera and the light inside an absorbing medium
// without boundary: only light samples reach the light, and their shadow rays carry
// exp(-sigma_a r) over their length r, the camera ray exp(-sigma_a d) over its own. Every
// pixel is the closed form up to its sampling of the pixel's area.
TEST(MediaBothBackends, LightSamplesThroughAMediumWithoutBoundary) {
  const vec3 sigma(0.1f, 0.3f, 0.6f);
  const vec3 light(0.1f, 0.2f, -1.0f);
  const float intensity = 2.0f, albedo = 0.5f;
  Scene scene;
  scene.camera = camera(vec3(0, 0, -3), vec3(0, 0, 0), 20.0f, 8);
  scene.materials = {Material{vec3(albedo), kMaterialDiffuse, vec3(0.0f), 0}};
  scene.media = {homogeneous(sigma, vec3(0.0f))};
  scene.cameraMedium = 0;
  Light point{};
  point.type = kLightPoint;
  point.position = light;
  point.radiance = vec3(intensity);
  scene.lights = {point};
  addShape(scene, quad(vec3(0, 0, 0), vec3(0, 3, 0), vec3(3, 0, 0)), 0,
           MediumInterface{kVacuum, kVacuum});
  const SceneData data = prepare(scene, 5);
  ASSERT_FALSE(data.effects.interfaces);
  const Comparison cmp = renderBoth(data, 64);
  expectAgreement(cmp);
  const Image expected = pixelAverages(data.params.camera, [&](const Ray& r) {
    const glm::dvec3 o(r.origin), d = glm::normalize(glm::dvec3(r.direction));
    const double t = -o.z / d.z;  // the wall at z = 0, t along the unit ray
    const glm::dvec3 x = o + t * d, toLight = glm::dvec3(light) - x;
    const double r2 = glm::dot(toLight, toLight), dist = std::sqrt(r2);
    const double cosine = -toLight.z / dist;  // the wall faces -z
    glm::dvec3 L;
    for (int c = 0; c < 3; ++c) {
      L[c] = albedo / kPi * intensity * cosine / r2 * std::exp(-double(sigma[c]) * (dist + t));
    }
    return L;
  });
  expectNearClosedForm(cmp, expected, 0.0, 0.01);
}

TEST(MediaBothBackends, WhiteFurnaceOfAScatteringMediumRendersTheEnvironment) {
  expectTheEnvironment(furnace(vec3(0.0f), vec3(0.5f, 1.0f, 2.0f), 0.6f, 160));
}

TEST(MediaBothBackends, AMediumOfAlbedoBelowOneLosesEnergy) {
  const FurnaceResult r = furnace(vec3(0.5f), vec3(0.5f), 0.0f, 32);
  expectAgreement(r.cmp);
  for (const Image* image : {&r.cmp.cpuImage, &r.cmp.gpuImage}) {
    double sum = 0.0;
    for (size_t i : r.sphere) {
      for (int c = 0; c < 3; ++c) {
        EXPECT_LT(image->pixels[i][c], 1.0f) << "pixel " << i;
        sum += image->pixels[i][c];
      }
    }
    EXPECT_LT(sum / (3.0 * double(r.sphere.size())), 0.6);
  }
}

// An emissive, absorbing slab seen against black: pbrt-v4's emission is sigma_a Le per unit
// length, so a ray of length d through it gathers Le (1 - exp(-sigma_a d)).
TEST(MediaBothBackends, EmissiveSlabGathersItsEmission) {
  const vec3 sigma(0.3f, 1.0f, 3.0f);
  const vec3 Le(2.0f, 1.0f, 0.5f);
  Scene scene;
  scene.camera = camera(vec3(0, 0, -5), vec3(0, 0, 0), 20.0f, 8);
  scene.materials = {Material{vec3(0.0f), kMaterialInterface, vec3(0.0f), 0}};
  Medium m = homogeneous(sigma, vec3(0.0f));
  m.Le = Le;
  m.emissive = kEmitsLe;
  scene.media = {m};
  addShape(scene, box(vec3(-3, -3, -0.5f), vec3(3, 3, 0.5f)), 0, MediumInterface{0, kVacuum});
  const SceneData data = prepare(scene, 5);
  const Comparison cmp = renderBoth(data, 128);
  expectAgreement(cmp);
  const Image expected = pixelAverages(data.params.camera, [&](const Ray& r) {
    const vec3 d = normalize(r.direction);
    return glm::dvec3(Le * (1.0f - exp(-sigma / d.z)));
  });
  expectNearClosedForm(cmp, expected, 0.0, 0.2);
  for (const Image* image : {&cmp.cpuImage, &cmp.gpuImage}) {
    glm::dvec3 mean(0.0), expectedMean(0.0);
    for (size_t i = 0; i < expected.pixels.size(); ++i) {
      mean += glm::dvec3(image->pixels[i]);
      expectedMean += glm::dvec3(expected.pixels[i]);
    }
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(mean[c] / expectedMean[c], 1.0, 0.02) << c;
  }
}

// ---- Emission by temperature ---------------------------------------------------------------

// pbrt-v4's normalized blackbody at `kelvin` as its film records it (as the NanoVDB tests).
glm::dvec3 blackbodyRgb(double kelvin) {
  return spectra::xyzToLinearSrgb() * spectra::toXyz(spectra::blackbody(kelvin)) *
         spectra::cieYIntegral();
}

// A uniformgrid of two voxels along x over [-1, 1] x [-1, 1] x [-0.5, 0.5], density 1, hot by
// its temperature grid (and scaled by a Lescale grid where one is given).
MediumParams hotGrid(std::vector<float> temperature, std::vector<float> LeScale = {}) {
  MediumParams p;
  p.type = kMediumUniformGrid;
  p.sigmaA = vec3(0.5f, 1.0f, 2.0f);
  p.sigmaS = vec3(0.0f);
  p.nx = 2;
  p.p0 = glm::dvec3(-1, -1, -0.5);
  p.p1 = glm::dvec3(1, 1, 0.5);
  p.density = {1.0f, 1.0f};
  p.temperature = std::move(temperature);
  p.LeScaleGrid = std::move(LeScale);
  return p;
}

// pbrt-v4's GridMedium: Le = Lescale(p) B((T(p) - temperatureoffset) * temperaturescale), both
// grids interpolated as the density (voxel centres at x = -0.5 and 0.5), Lescale without a grid
// of its own pbrt-v4's one voxel of 1 (falling to a half at the faces). With one voxel along y
// and z, every grid falls off along them too: at y = 0.5 (a quarter of the way in from the
// face) the temperature is 3/4 of the voxels' along x. (A blackbody's linear sRGB is negative
// in blue below about 1900 K, as pbrt-v4's film records it.)
TEST(Media, UniformGridTemperatureEmitsTheBlackbody) {
  Scene scene;
  MediumParams p = hotGrid({1000.0f, 3000.0f});
  p.temperatureOffset = 100.0;
  p.temperatureScale = 1.5;
  const Medium plain = scene.media[addMedium(scene, "plain", p)];
  const Medium scaled =
      scene.media[addMedium(scene, "scaled", hotGrid({1000.0f, 3000.0f}, {1.0f, 0.5f}))];
  ASSERT_EQ(plain.emissive, kEmitsBlackbody);
  ASSERT_EQ(scaled.emissive, kEmitsBlackbody);
  PathScene s{};
  s.mediumGrids = scene.mediumGrids.data();
  struct Case {
    const Medium& m;
    vec3 p;
    double scale, kelvin;
  };
  for (const Case& c : {Case{plain, vec3(0, 0, 0), 1.0, (2000.0 - 100.0) * 1.5},
                        Case{plain, vec3(-0.5f, 0, 0), 0.75, (1000.0 - 100.0) * 1.5},
                        Case{plain, vec3(0.25f, 0.5f, 0), 0.875 * 0.75, (1875.0 - 100.0) * 1.5},
                        Case{scaled, vec3(0, 0, 0), 0.75, 2000.0},
                        Case{scaled, vec3(0.5f, 0, 0.25f), 0.375, 2250.0}}) {
    const vec3 Le = mediumPropertiesAt(s, c.m, c.p).Le;
    const glm::dvec3 want = c.scale * blackbodyRgb(c.kelvin);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(Le[k], want[k], 2e-4 * std::fabs(want[k])) << c.kelvin << " K, channel " << k;
    }
  }
  // (T - offset) * scale at 100 K or below emits nothing.
  p.temperatureOffset = 950.0;
  p.temperatureScale = 1.0;
  const Medium cool = scene.media[addMedium(scene, "cool", p)];
  s.mediumGrids = scene.mediumGrids.data();
  EXPECT_EQ(mediumPropertiesAt(s, cool, vec3(-0.5f, 0, 0)).Le, vec3(0.0f));  // 50 K
  EXPECT_GT(mediumPropertiesAt(s, cool, vec3(0.5f, 0, 0)).Le.x, 0.0f);       // 2050 K
}

// A hot grid (4^3 voxels, 1500 K to 4500 K along x) seen against black through its depth:
// both backends gather the emission integral of sigma_a d(p) Le(p) times the transmittance
// along each ray, here integrated by quadrature from the medium's own coefficients (the test
// above checks those). Four voxels on each axis keep the grids' fall-off at the faces to the
// outer eighth, so that the emission varies little along a ray.
TEST(MediaBothBackends, HotUniformGridGathersItsBlackbodyEmission) {
  Scene scene;
  scene.camera = camera(vec3(0, 0, -5), vec3(0, 0, 0), 20.0f, 8);
  scene.materials = {Material{vec3(0.0f), kMaterialInterface, vec3(0.0f), 0}};
  MediumParams p = hotGrid({});
  p.nx = p.ny = p.nz = 4;
  p.density.assign(64, 1.0f);
  for (int i = 0; i < 64; ++i) p.temperature.push_back(1500.0f + 1000.0f * float(i % 4));
  addMedium(scene, "hot", p);
  const vec3 lo(-1, -1, -0.5f), hi(1, 1, 0.5f);
  addShape(scene, box(lo, hi), 0, MediumInterface{0, kVacuum});
  const SceneData data = prepare(scene, 5);
  const Comparison cmp = renderBoth(data, 2048);
  expectAgreement(cmp);
  PathScene s{};
  s.mediumGrids = scene.mediumGrids.data();
  const Medium& m = scene.media[0];
  const Image expected = pixelAverages(data.params.camera, [&](const Ray& r) {
    const vec3 d = normalize(r.direction);
    const float t0 = (lo.z - r.origin.z) / d.z, t1 = (hi.z - r.origin.z) / d.z;
    constexpr int kSteps = 200;
    const double dt = double(t1 - t0) / kSteps;
    glm::dvec3 L(0.0), depth(0.0);
    for (int i = 0; i < kSteps; ++i) {
      const MediumProperties mp =
          mediumPropertiesAt(s, m, r.origin + (t0 + float((i + 0.5) * dt)) * d);
      const glm::dvec3 sigma(mp.sigmaA);
      // The step's emission times the transmittance to it, exact within the step.
      L += exp(-depth) * (1.0 - exp(-sigma * dt)) * glm::dvec3(mp.Le);
      depth += sigma * dt;
    }
    return L;
  });
  // Each pixel within 15 % of its brightest channel (blue is negative below about 1900 K): at
  // 2048 samples the worst is 7 %; delta tracking gathers a sample's emission where it
  // collides, and with the hero channel's majorant 0.5 over a depth of 1 most samples pass
  // without, so fewer samples leave the error above 10 %.
  for (const Image* image : {&cmp.cpuImage, &cmp.gpuImage}) {
    glm::dvec3 mean(0.0), expectedMean(0.0);
    for (size_t i = 0; i < expected.pixels.size(); ++i) {
      const vec3 e = expected.pixels[i];
      const float bound = 0.15f * maxComponent(abs(e));
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(image->pixels[i][c], e[c], bound) << i << " " << c;
      mean += glm::dvec3(image->pixels[i]);
      expectedMean += glm::dvec3(e);
    }
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(mean[c] / expectedMean[c], 1.0, 0.02) << c;
  }
}

// ---- Hard cases -------------------------------------------------------------------------------

// No NaN, nothing invalid or cut short, and the backends agree, on scenes at the edges: a
// medium of coefficient 0 (vacuum exactly), of 1e6 (opaque: nothing behind it, exactly), a
// scattering medium of 1e6 (paths end at maxDepth), a ray grazing an interface.
TEST(MediaBothBackends, ZeroAndHugeCoefficientsStayFinite) {
  Scene base;
  base.camera = camera(vec3(0, 0, -5), vec3(0, 0, 0), 20.0f, 8);
  base.materials = {Material{vec3(0.0f), kMaterialInterface, vec3(0.0f), 0},
                    Material{vec3(0.0f), kMaterialDiffuse, vec3(1.0f, 2.0f, 3.0f), 0}};
  addShape(base, quad(vec3(0, 0, 2), vec3(0, 3, 0), vec3(3, 0, 0)), 1,
           MediumInterface{kVacuum, kVacuum});
  {
    SCOPED_TRACE("sigma 0 around the camera");
    Scene scene = base;
    scene.media = {homogeneous(vec3(0.0f), vec3(0.0f))};
    scene.cameraMedium = 0;
    const Comparison cmp = renderBoth(prepare(scene, 5), 4);
    for (const Image* image : {&cmp.cpuImage, &cmp.gpuImage}) {
      for (const vec3& p : image->pixels) EXPECT_EQ(p, vec3(1.0f, 2.0f, 3.0f));
    }
  }
  {
    SCOPED_TRACE("sigma_a 1e6 in front of the emitter");
    Scene scene = base;
    scene.media = {homogeneous(vec3(1e6f), vec3(0.0f))};
    addShape(scene, box(vec3(-3, -3, -0.5f), vec3(3, 3, 0.5f)), 0, MediumInterface{0, kVacuum});
    const Comparison cmp = renderBoth(prepare(scene, 5), 4);
    EXPECT_EQ(cmp.gpu.invalidSamples, 0u);
    EXPECT_EQ(cmp.gpu.truncatedSamples, 0u);
    for (const Image* image : {&cmp.cpuImage, &cmp.gpuImage}) {
      for (const vec3& p : image->pixels) EXPECT_EQ(p, vec3(0.0f));
    }
  }
  {
    SCOPED_TRACE("sigma_s 1e6 under an environment, and a ray along the slab's face");
    Scene scene = base;
    scene.lights = {environment(1.0f)};
    scene.media = {homogeneous(vec3(0.0f), vec3(1e6f), 0.5f)};
    addShape(scene, box(vec3(-0.3f, -3, -0.5f), vec3(3, 3, 0.5f)), 0, MediumInterface{0, kVacuum});
    scene.camera = camera(vec3(-0.3f, 0, -5), vec3(-0.3f, 0, 0), 10.0f, 8);
    const Comparison cmp = renderBoth(prepare(scene, 64), 4);
    EXPECT_EQ(cmp.gpu.invalidSamples, 0u);
    EXPECT_EQ(cmp.gpu.truncatedSamples, 0u);
    EXPECT_EQ(cmp.diff.nonFinitePixels, 0u);
    for (const Image* image : {&cmp.cpuImage, &cmp.gpuImage}) {
      for (const vec3& p : image->pixels) {
        EXPECT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
        EXPECT_GE(std::min(p.x, std::min(p.y, p.z)), 0.0f);
      }
    }
  }
}

// A glass of tea inside fog: the camera in the fog, a dielectric sphere whose inside is an
// absorbing medium, an interface sphere of a chromatic scattering medium, a grid medium with
// empty cells, an area light and a floor.
Scene nestedMediaScene(int size) {
  Scene scene;
  scene.camera = camera(vec3(0, 1, -6), vec3(0, 0.5f, 0), 35.0f, size);
  Material glass{};
  glass.type = kMaterialDielectric;
  glass.eta = vec3(1.33f);
  scene.materials = {Material{vec3(0.0f), kMaterialInterface, vec3(0.0f), 0},
                     Material{vec3(0.6f), kMaterialDiffuse, vec3(0.0f), 0},
                     Material{vec3(0.0f), kMaterialDiffuse, vec3(12.0f, 10.0f, 8.0f), 0}, glass};
  scene.media = {homogeneous(vec3(0.01f), vec3(0.08f), 0.3f),               // 0: fog
                 homogeneous(vec3(0.1f, 0.6f, 2.0f), vec3(0.0f)),           // 1: tea
                 homogeneous(vec3(0.05f), vec3(1.5f, 0.8f, 0.3f), -0.4f)};  // 2: smoke
  std::vector<float> density(4 * 4 * 4, 0.0f);
  for (int i = 0; i < 64; i += 3) density[size_t(i)] = 2.0f;  // empty cells between
  scene.media.push_back(uniformGrid(scene, vec3(1.2f, 0.05f, -1), vec3(2.8f, 1.6f, 0.6f),
                                    uvec3(4, 4, 4), density, vec3(0.1f), vec3(0.9f)));
  scene.cameraMedium = 0;
  const uint fog = 0, tea = 1, smoke = 2, grid = 3;
  addShape(scene, box(vec3(-6, -0.5f, -8), vec3(6, 6, 6)), 0, MediumInterface{fog, kVacuum});
  addShape(scene, quad(vec3(0, 0, 0), vec3(0, 0, 5), vec3(5, 0, 0)), 1,
           MediumInterface{kVacuum, kVacuum});
  addShape(scene, quad(vec3(0, 4, 0), vec3(1, 0, 0), vec3(0, 0, 1)), 2,
           MediumInterface{kVacuum, kVacuum});
  addShape(scene, sphere(vec3(-1.2f, 0.8f, 0), 0.8f), 3, MediumInterface{tea, fog});
  addShape(scene, sphere(vec3(0.3f, 0.6f, -1.5f), 0.6f), 0, MediumInterface{smoke, fog});
  addShape(scene, box(vec3(1.2f, 0.05f, -1), vec3(2.8f, 1.6f, 0.6f)), 0,
           MediumInterface{grid, fog});
  return scene;
}

// The backends agree on it.
TEST(MediaBothBackends, NestedMediaAgree) {
  const Comparison cmp = renderBoth(prepare(nestedMediaScene(24), 16), 8);
  expectAgreement(cmp);
}

// The CPU's volume integrator alone (the sanitizer build runs this one): finite, nothing
// invalid, and the same image from one thread and from two.
TEST(Media, VolumeIntegratorOnTheCpu) {
  const SceneData data = prepare(nestedMediaScene(12), 16);
  Film one(12, 12), two(12, 12);
  EXPECT_EQ(renderCpu(data, test::cpuOptions(1, 2), one).invalidSamples, 0u);
  EXPECT_EQ(renderCpu(data, test::cpuOptions(2, 2), two).invalidSamples, 0u);
  const Image a = one.resolve(), b = two.resolve();
  EXPECT_EQ(a.pixels, b.pixels);
  double sum = 0.0;
  for (const vec3& p : a.pixels) sum += double(p.x + p.y + p.z);
  EXPECT_GT(sum, 0.0);
}

// A triangle's inside and outside follow its vertex normals where it has them (pbrt-v4 turns
// the geometric normal towards them): the one whose normals face against its winding has its
// two media swapped, the other keeps them.
TEST(Media, InterfacesFollowTheVertexNormals) {
  Scene scene;
  scene.camera = camera(vec3(0, 0, -5), vec3(0, 0, 0), 20.0f, 4);
  scene.materials = {Material{vec3(0.0f), kMaterialInterface, vec3(0.0f), 0}};
  scene.media = {homogeneous(vec3(1.0f), vec3(0.0f))};
  addShape(scene, quad(vec3(0, 0, 0), vec3(1, 0, 0), vec3(0, 1, 0)), 0,
           MediumInterface{0, kVacuum});
  const vec3 z(0, 0, 1);
  scene.normals = {TriangleNormals{-z, 0, -z, 0, -z, 0}, TriangleNormals{z, 0, z, 0, z, 0}};
  const SceneData data = prepare(scene);
  ASSERT_EQ(data.mediumInterfaces.size(), 2u);
  EXPECT_EQ(data.mediumInterfaces[0].inside, kVacuum);
  EXPECT_EQ(data.mediumInterfaces[0].outside, 0u);
  EXPECT_EQ(data.mediumInterfaces[1].inside, 0u);
  EXPECT_EQ(data.mediumInterfaces[1].outside, kVacuum);
}

// ---- Samplers against their densities -------------------------------------------------------

// The phase function's directions against its density, for wo along a fixed direction.
test::Chi2Result phaseChi2(float g, float pdfG) {
  constexpr int kSamples = 200000;
  const vec3 wo = normalize(vec3(0.3f, -0.2f, 0.9f));
  RandomStream rng{uvec4(1u, 2u, uint(std::fabs(g) * 1000.0f), 7u)};
  auto draw = [&] {
    float pdf;
    return sampleHenyeyGreenstein(wo, g, nextRandom2(rng), pdf);
  };
  std::vector<glm::vec3> pilot;
  for (int i = 0; i < 4000; ++i) pilot.push_back(draw());
  const test::SphereGrid grid = test::focusedGrid(pilot, 20, 40);
  std::vector<double> observed(size_t(grid.cellCount()), 0.0);
  for (int i = 0; i < kSamples; ++i) {
    float pdf;
    const vec3 wi = sampleHenyeyGreenstein(wo, g, nextRandom2(rng), pdf);
    EXPECT_NEAR(pdf, henyeyGreenstein(dot(wo, wi), g), 1e-3f * pdf);
    observed[size_t(grid.cellOf(wi))] += 1.0;
  }
  const auto density = [&](vec3 w) { return double(henyeyGreenstein(dot(wo, w), pdfG)); };
  return test::pearsonChi2(observed, test::expectedCounts(grid, density, kSamples));
}

TEST(Media, PhaseFunctionSamplerPassesChiSquare) {
  for (float g : {-0.9f, -0.5f, 0.0f, 0.3f, 0.9f}) {
    SCOPED_TRACE(g);
    const test::Chi2Result good = phaseChi2(g, g);
    EXPECT_GE(good.pValue, test::sidakSignificance(1e-3, 5))
        << "chi2 " << good.statistic << ", " << good.dof << " dof";
  }
  // A density of another asymmetry is told apart.
  const test::Chi2Result bad = phaseChi2(0.3f, 0.4f);
  EXPECT_LT(bad.pValue, 1e-6);
}

// Where delta tracking scatters a path: through a purely scattering medium of coefficient
// sigma(t) along the ray, the first scattering point has the density sigma(t) exp(-integral
// of sigma), whatever the majorants. Histogrammed over [0, tMax) with the escapes in a last
// cell, against that density integrated per cell; `wrongScale` multiplies the expected
// coefficient (1: the right one).
struct FlightSetup {
  std::vector<Medium> media;
  std::vector<float> grids;
  RenderParams params{};
};

test::Chi2Result flightChi2(const FlightSetup& setup, float tMax, double (*opticalDepth)(double),
                            double wrongScale) {
  PathScene ps{};
  ps.params = &setup.params;
  ps.media = setup.media.data();
  ps.mediumGrids = setup.grids.data();
  constexpr int kCells = 40, kSamples = 100000;
  std::vector<double> observed(kCells + 1, 0.0), expected(kCells + 1, 0.0);
  for (int i = 0; i < kSamples; ++i) {
    VolumePath v{};
    v.path = startPathState();
    v.rU = v.rL = vec3(1.0f);
    v.hero = uint(i % 3);
    v.medium = 0;
    v.rng = RandomStream{uvec4(uint(i), 11u, 13u, 0u)};
    vec3 p;
    float g;
    const uint flight = trackFlight(ps, v, vec3(0.0f), vec3(1, 0, 0), tMax, p, g);
    EXPECT_NE(flight, kFlightEnded);  // nothing absorbs
    const int cell =
        flight == kFlightScattered ? std::min(kCells - 1, int(p.x / tMax * kCells)) : kCells;
    observed[size_t(cell)] += 1.0;
  }
  for (int c = 0; c < kCells; ++c) {
    const double t0 = tMax * c / kCells, t1 = tMax * (c + 1) / kCells;
    expected[size_t(c)] = kSamples * (std::exp(-wrongScale * opticalDepth(t0)) -
                                      std::exp(-wrongScale * opticalDepth(t1)));
  }
  expected[kCells] = kSamples * std::exp(-wrongScale * opticalDepth(tMax));
  return test::pearsonChi2(observed, expected);
}

TEST(Media, FreeFlightDistancesFollowTheTransmittance) {
  {
    SCOPED_TRACE("homogeneous");
    FlightSetup s;
    s.media = {homogeneous(vec3(0.0f), vec3(0.7f))};
    s.params.maxDepth = 64;
    const auto depth = [](double t) { return 0.7 * t; };
    EXPECT_GE(flightChi2(s, 3.0f, depth, 1.0).pValue, 1e-4);
    EXPECT_LT(flightChi2(s, 3.0f, depth, 1.1).pValue, 1e-6);
  }
  {
    // A grid over x in [0, 4] of 16 voxels whose density rises by 0.25 a voxel from 0: the
    // majorant grid's cells hold their largest values, so most tentative collisions are null.
    SCOPED_TRACE("grid");
    FlightSetup s;
    Scene scene;
    std::vector<float> density;
    for (int x = 0; x < 16; ++x) density.push_back(0.25f * float(x));
    Medium m = uniformGrid(scene, vec3(0, -1, -1), vec3(4, 1, 1), uvec3(16, 1, 1), density,
                           vec3(0.0f), vec3(0.5f));
    s.grids = scene.mediumGrids;
    const std::vector<float> majorants = majorantGrid(m, s.grids);
    m.majorants = uint(s.grids.size());
    s.grids.insert(s.grids.end(), majorants.begin(), majorants.end());
    s.media = {m};
    s.params.maxDepth = 64;
    // Voxel k's centre is at x = 0.125 + 0.25 k, its value 0.25 k: between the outer centres
    // the density is x - 0.125, below the first 0 (interpolated with the zero outside the
    // grid); sigma_s = 0.5 of it, so the optical depth to t is 0.25 (t - 0.125)^2.
    const auto depth = [](double t) { return t <= 0.125 ? 0.0 : 0.25 * (t - 0.125) * (t - 0.125); };
    EXPECT_GE(flightChi2(s, 3.5f, depth, 1.0).pValue, 1e-4);
    EXPECT_LT(flightChi2(s, 3.5f, depth, 1.1).pValue, 1e-6);
  }
}

}  // namespace
}  // namespace pt
