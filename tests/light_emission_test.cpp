// The emission sampler that starts BDPT's light subpaths and SPPM's photons
// (bdpt_vertex.h's sampleBdptLightStart): Pearson's chi-square test (tests/chi2.h) of the lights
// it chooses, the points on them and the directions it sends light in, jointly, against the
// densities BDPT weighs them with (bdptPdfLightOrigin for the light and the point, bdptPdfLight
// for the direction). A density deliberately wrong in direction fails the same test.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "bdpt_vertex.h"
#include "chi2.h"
#include "render/prepare.h"
#include "scene/load_scene.h"
#include "test_util.h"

namespace pt {
namespace {

// Two emissive triangles (one emits on its front only, one on both sides, tilted), a point
// light and a spot light over a floor: four emitters of different power.
SceneData emissionScene(const test::TempDir& dir) {
  const std::string json = R"({
    "materials": [
      {"name": "floor", "type": "diffuse", "reflectance": [0.5, 0.5, 0.5]},
      {"name": "lamp", "type": "diffuse", "reflectance": [0, 0, 0], "emission": [3, 2, 1]},
      {"name": "panel", "type": "diffuse", "reflectance": [0, 0, 0], "emission": [1, 1, 1],
       "twoSided": true}
    ],
    "shapes": [
      {"type": "triangles", "material": "floor",
       "vertices": [[-5, 0, -5], [5, 0, -5], [0, 0, 5]], "indices": [[0, 2, 1]]},
      {"type": "triangles", "material": "lamp",
       "vertices": [[0, 2, 0], [1, 2, 0], [0, 2, 2]], "indices": [[0, 1, 2]]},
      {"type": "triangles", "material": "panel",
       "vertices": [[-2, 1, 0], [-1, 2, 0.5], [-2, 1.5, 1]], "indices": [[0, 1, 2]]}
    ],
    "lights": [
      {"type": "point", "position": [1, 3, 1], "intensity": [0.5, 0.5, 0.5]},
      {"type": "spot", "position": [0, 4, 0], "target": [1, 0, 1], "intensity": [2, 2, 2],
       "coneAngle": 30, "coneDeltaAngle": 10}
    ]
  })";
  return prepareScene(loadScene(dir.write("emission.json", json)), RenderSettings{});
}

// An orthonormal frame about unit n (sampling.h's localToWorld), to express directions in.
struct Frame {
  vec3 t, b, n;
  explicit Frame(vec3 normal)
      : t(localToWorld(vec3(1, 0, 0), normal)), b(localToWorld(vec3(0, 1, 0), normal)), n(normal) {}
  vec3 toLocal(vec3 w) const { return vec3(dot(w, t), dot(w, b), dot(w, n)); }
  vec3 toWorld(vec3 l) const { return l.x * t + l.y * b + l.z * n; }
};

// The region of a triangle a point with barycentrics (b0, b1, b2) lies in: the three corner
// triangles cut off by the midpoints, then the middle one; each a quarter of the area.
int regionOf(double b0, double b1, double b2) {
  if (b0 > 0.5) return 0;
  if (b1 > 0.5) return 1;
  if (b2 > 0.5) return 2;
  return 3;
}
// The centroid of region r of triangle (v0, v1, v2).
vec3 regionCentroid(const Triangle& t, int r) {
  const vec3 c = (t.v0 + t.v1 + t.v2) / 3.0f;
  const vec3 corners[3] = {t.v0, t.v1, t.v2};
  return r == 3 ? c : 0.5f * (corners[r] + c);  // a corner triangle's centroid
}

// The octant of the unit sphere that unit n lies in (by the signs of its components), and the
// octant's centre direction: the regions of a sphere light, each an eighth of its area.
int octantOf(vec3 n) {
  return (n.x < 0.0f ? 1 : 0) + (n.y < 0.0f ? 2 : 0) + (n.z < 0.0f ? 4 : 0);
}
vec3 octantCentre(int r) {
  return normalize(
      vec3((r & 1) != 0 ? -1.0f : 1.0f, (r & 2) != 0 ? -1.0f : 1.0f, (r & 4) != 0 ? -1.0f : 1.0f));
}

struct EmitterCells {
  uint emitter = 0;
  bool onTriangle = false;
  bool onSphere = false;  // a sphere light: its directions in each point's own normal frame
  Light sphere{};
  Triangle tri{};
  Frame frame{vec3(0, 0, 1)};
  BdptVertex vertex{};  // a sample's vertex: its light's record
  size_t first = 0;     // its first cell
  int regions = 1;
};

// Draws `samples` light starts and compares the histogram of (emitter, region of its surface,
// direction cell in its frame) with the densities' integrals; with `wrongDirection` a triangle's
// or sphere's direction density is taken uniform over its emitting side instead of
// cosine-weighted.
test::Chi2Result emissionChi2(const SceneData& scene, int samples, bool wrongDirection,
                              uint32_t seed) {
  const PathScene ps = scene.pathScene();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  auto draw = [&] {
    const vec2 a(uniform(rng), uniform(rng)), b(uniform(rng), uniform(rng)),
        c(uniform(rng), uniform(rng));
    return sampleBdptLightStart(ps, a, b, c, VertexKey{uvec2(0), 0u, kDimLightSubpath});
  };
  const test::SphereGrid grid(std::array<test::LobeFocus, 2>{}, 8, 16);
  const size_t dirCells = size_t(grid.cellCount());

  // Every emitter's cells, found from pilot draws.
  std::vector<EmitterCells> emitters(scene.params.emitterCount);
  std::vector<bool> seen(emitters.size(), false);
  for (int i = 0; i < 20000; ++i) {
    const BdptLightStart s = draw();
    if (!s.found || seen[s.vertex.emitter]) continue;
    seen[s.vertex.emitter] = true;
    EmitterCells& e = emitters[s.vertex.emitter];
    e.emitter = s.vertex.emitter;
    e.vertex = s.vertex;
    e.onTriangle = s.vertex.lightType == kBdptLightTriangle;
    if (e.onTriangle) {
      e.tri = scene.bvh.triangles[ps.emitters[e.emitter].triangle];
      e.frame = Frame(s.vertex.ng);
      e.regions = 4;
    } else if (s.vertex.lightType == kLightSphere) {
      e.onSphere = true;
      e.sphere = scene.lights[ps.emitters[e.emitter].triangle & ~kEmitterLight];
      e.regions = 8;
    } else if (s.vertex.lightType == kLightSpot) {
      const Light& light = scene.lights[ps.emitters[e.emitter].triangle & ~kEmitterLight];
      e.frame = Frame(light.direction);
    }
  }
  size_t cells = 0;
  for (size_t k = 0; k < emitters.size(); ++k) {
    EXPECT_TRUE(seen[k]) << "emitter " << k << " never chosen";
    emitters[k].first = cells;
    cells += size_t(emitters[k].regions) * dirCells;
  }

  // The histogram.
  std::vector<double> observed(cells, 0.0);
  for (int i = 0; i < samples; ++i) {
    const BdptLightStart s = draw();
    EXPECT_TRUE(s.found);
    if (!s.found) continue;
    const EmitterCells& e = emitters[s.vertex.emitter];
    int region = 0;
    if (e.onTriangle) {
      // Barycentrics of the point on the triangle.
      const glm::dvec3 p(s.vertex.p), a(e.tri.v0), b(e.tri.v1), c(e.tri.v2);
      const glm::dvec3 n = glm::cross(b - a, c - a);
      const double area2 = glm::dot(n, n);
      const double b1 = glm::dot(glm::cross(p - a, c - a), n) / area2;
      const double b2 = glm::dot(glm::cross(b - a, p - a), n) / area2;
      region = regionOf(1.0 - b1 - b2, b1, b2);
    }
    Frame frame = e.frame;
    if (e.onSphere) {
      EXPECT_NEAR(length(s.vertex.p - e.sphere.position), e.sphere.radius, 1e-5f);
      region = octantOf(s.vertex.ng);
      frame = Frame(s.vertex.ng);
    }
    const size_t cell =
        e.first + size_t(region) * dirCells + size_t(grid.cellOf(frame.toLocal(s.direction)));
    observed[cell] += 1.0;
  }

  // The expected counts: the light and point's probability (bdptPdfLightOrigin, per unit area
  // on a triangle, times the region's area), times the direction's density (bdptPdfLight
  // towards a point a unit away, not on a surface) integrated over each direction cell.
  std::vector<double> expected(cells, 0.0);
  for (const EmitterCells& e : emitters) {
    for (int r = 0; r < e.regions; ++r) {
      BdptVertex v = e.vertex;
      double regionProbability;
      Frame frame = e.frame;
      if (e.onTriangle) {
        v.p = regionCentroid(e.tri, r);
        BdptVertex towards = bdptEmptyVertex(kBdptSurface, v.p + e.frame.n, vec3(1.0f), v.key);
        regionProbability = double(bdptPdfLightOrigin(ps, v, towards)) * double(v.s.area) / 4.0;
      } else if (e.onSphere) {
        // Per unit area on the sphere, times an eighth of its area.
        v = bdptSphereLightVertex(ps, e.emitter, e.sphere, octantCentre(r), vec3(1.0f), v.key);
        frame = Frame(v.ng);
        BdptVertex towards = bdptEmptyVertex(kBdptSurface, v.p + v.ng, vec3(1.0f), v.key);
        const double area = 4.0 * std::numbers::pi * double(e.sphere.radius) * e.sphere.radius;
        regionProbability = double(bdptPdfLightOrigin(ps, v, towards)) * area / 8.0;
      } else {
        BdptVertex towards = bdptEmptyVertex(kBdptSurface, v.p + vec3(0, 0, 1), vec3(1.0f), v.key);
        regionProbability = double(bdptPdfLightOrigin(ps, v, towards));
      }
      const bool twoSided = e.onTriangle && bdptTwoSided(v);
      auto pdfDir = [&](glm::vec3 local) {
        if (wrongDirection && (e.onTriangle || e.onSphere)) {
          const double side = twoSided ? 0.5 : (local.z > 0.0f ? 1.0 : 0.0);
          return side / (2.0 * std::numbers::pi);
        }
        const BdptVertex next =
            bdptEmptyVertex(kBdptSurface, v.p + frame.toWorld(local), vec3(1.0f), v.key);
        return double(bdptPdfLight(ps, v, next));
      };
      const std::vector<double> dir = test::expectedCounts(grid, pdfDir, samples);
      for (size_t c = 0; c < dirCells; ++c) {
        expected[e.first + size_t(r) * dirCells + c] = regionProbability * dir[c];
      }
    }
  }
  return test::pearsonChi2(observed, expected);
}

TEST(LightEmissionChi2, PositionAndDirectionMatchTheirDensities) {
  const test::TempDir dir;
  const SceneData scene = emissionScene(dir);
  ASSERT_EQ(scene.params.emitterCount, 4u);
  const test::Chi2Result r = emissionChi2(scene, 400000, false, 3u);
  EXPECT_GE(r.pValue, 1e-4) << "chi2 " << r.statistic << ", " << r.dof << " dof, "
                            << r.zeroDensityHits << " samples where the density is 0";
}

TEST(LightEmissionChi2, AWrongDirectionDensityFails) {
  const test::TempDir dir;
  const SceneData scene = emissionScene(dir);
  const test::Chi2Result r = emissionChi2(scene, 400000, true, 3u);
  EXPECT_LT(r.pValue, 1e-6) << "chi2 " << r.statistic << ", " << r.dof << " dof";
}

// The same for tests/data/sphere-lights.pbrt's two sphere lights: points uniform by area on the
// sphere (its octants), directions cosine-weighted about each point's outward normal.
TEST(LightEmissionChi2, SphereLightsMatchTheirDensities) {
  const SceneData scene =
      prepareScene(loadScene(test::kSphereLightsScene), RenderSettings{.width = 8, .height = 8});
  ASSERT_EQ(scene.params.emitterCount, 2u);
  const test::Chi2Result r = emissionChi2(scene, 200000, false, 5u);
  EXPECT_GE(r.pValue, 1e-4) << "chi2 " << r.statistic << ", " << r.dof << " dof, "
                            << r.zeroDensityHits << " samples where the density is 0";
  const test::Chi2Result wrong = emissionChi2(scene, 200000, true, 5u);
  EXPECT_LT(wrong.pValue, 1e-6) << "chi2 " << wrong.statistic << ", " << wrong.dof << " dof";
}

}  // namespace
}  // namespace pt
