// The light BVH (host/render/light_bvh.cpp, shaders/light_bvh.h, path_vertex.h's
// chooseEmitter and emitterChoicePmf): pbrt-v4's BVHLightSampler. Its probabilities sum to
// one over the emitters at any shading point, its choices follow them (chi-square, with a
// wrong distribution shown to fail), the probability a sample reports is the one the walk up
// the tree computes for MIS, the importance matches hand-computed values, and images rendered
// with each light sampler converge to the same mean.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "chi2.h"
#include "common/shared.h"
#include "cpu/integrator.h"
#include "path_vertex.h"
#include "render/light_bvh.h"
#include "render/prepare.h"
#include "render_compare.h"
#include "scene/pbrt/pbrt_scene.h"
#include "test_util.h"

namespace pt {
namespace {

// Forty emissive triangles of random size, orientation, emission and sidedness in a 10^3 box,
// three axis-aligned quads whose halves emit unequally (one of them on both sides: pairs of
// triangles with the same bounds but their power), two point lights, a spot light and two
// unbounded lights (distant, infinite).
struct ManyLights {
  std::vector<Material> materials;
  std::vector<Triangle> triangles;
  std::vector<Light> lights;
  std::vector<Emitter> emitters;
  LightBvh bvh;
  RenderParams params{};

  ManyLights() {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    const auto point = [&] { return vec3(u(rng), u(rng), u(rng)) * 10.0f; };
    for (int i = 0; i < 40; ++i) {
      Material m{vec3(0.5f), kMaterialDiffuse, vec3(0.1f + 5.0f * u(rng)), i % 5 == 0 ? 1u : 0u};
      materials.push_back(m);
      const vec3 c = point();
      const float size = 0.05f + 2.0f * u(rng);
      triangles.push_back(Triangle{c, uint(i), c + size * (vec3(u(rng), u(rng), u(rng)) - 0.5f),
                                   kNoEmitter, c + size * (vec3(u(rng), u(rng), u(rng)) - 0.5f),
                                   uint(i)});
    }
    // Quads in the planes z = 3, x = 6 and y = 8: corner a, edges e and f (their cross product
    // the front side); the second half emits three times the first.
    const vec3 quads[3][3] = {
        {vec3(2.0f, 2.0f, 3.0f), vec3(1.5f, 0.0f, 0.0f), vec3(0.0f, 1.0f, 0.0f)},
        {vec3(6.0f, 1.0f, 1.0f), vec3(0.0f, 2.0f, 0.0f), vec3(0.0f, 0.0f, 0.5f)},
        {vec3(4.0f, 8.0f, 5.0f), vec3(0.0f, 0.0f, 1.0f), vec3(1.0f, 0.0f, 0.0f)}};
    for (int q = 0; q < 3; ++q) {
      const vec3 a = quads[q][0], b = a + quads[q][1], c = b + quads[q][2], d = a + quads[q][2];
      for (int half = 0; half < 2; ++half) {
        const uint m = uint(materials.size());
        materials.push_back(Material{vec3(0.5f), kMaterialDiffuse, vec3(half == 0 ? 1.0f : 3.0f),
                                     q == 2 ? 1u : 0u});
        triangles.push_back(half == 0 ? Triangle{a, m, b, kNoEmitter, c, m}
                                      : Triangle{a, m, c, kNoEmitter, d, m});
      }
    }
    Light p{};
    p.type = kLightPoint;
    p.position = point();
    p.radiance = vec3(20.0f);
    lights.push_back(p);
    p.position = point();
    p.radiance = vec3(3.0f, 1.0f, 0.5f);
    lights.push_back(p);
    Light spot = p;
    spot.type = kLightSpot;
    spot.position = point();
    spot.direction = glm::normalize(vec3(0.3f, -1.0f, 0.2f));
    spot.cosFalloffStart = std::cos(0.3f);
    spot.cosFalloffEnd = std::cos(0.5f);
    lights.push_back(spot);
    Light distant{};
    distant.type = kLightDistant;
    distant.direction = glm::normalize(vec3(1.0f, 2.0f, 3.0f));
    distant.radiance = vec3(1.0f);
    lights.push_back(distant);
    Light infinite{};
    infinite.type = kLightInfinite;
    infinite.radiance = vec3(0.2f);
    lights.push_back(infinite);
    emitters = buildEmitters(triangles, materials, lights, 10.0f);
    bvh = buildLightBvh(emitters, triangles, materials, lights);
    params.emitterCount = uint(emitters.size());
    params.lightBvhNodes = uint(bvh.nodes.size());
    params.unboundedEmitters = bvh.unbounded;
  }

  PathScene scene() const {
    PathScene s{};
    s.params = &params;
    s.triangles = triangles.data();
    s.materials = materials.data();
    s.emitters = emitters.data();
    s.lights = lights.data();
    s.lightBvh = bvh.nodes.data();
    s.lightBvhWords = bvh.words.data();
    return s;
  }
};

// Shading points inside and around the lights' box, with random normals (and none: a medium).
std::vector<std::pair<vec3, vec3>> shadingPoints() {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-3.0f, 13.0f);
  std::normal_distribution<float> g;
  std::vector<std::pair<vec3, vec3>> points;
  for (int i = 0; i < 24; ++i) {
    const vec3 n = i % 6 == 5 ? vec3(0.0f) : glm::normalize(vec3(g(rng), g(rng), g(rng)));
    points.emplace_back(vec3(u(rng), u(rng), u(rng)), n);
  }
  return points;
}

TEST(LightBvh, TreeHoldsEveryBoundedEmitterOnceWithItsPower) {
  const ManyLights l;
  ASSERT_EQ(l.emitters.size(), 51u);
  EXPECT_EQ(l.bvh.unbounded, 2u);
  ASSERT_EQ(l.bvh.nodes.size(), 2u * 49u - 1u);
  ASSERT_EQ(l.bvh.words.size(), l.emitters.size() + 2u);
  std::vector<int> seen(l.emitters.size(), 0);
  for (uint32_t i = 0; i < l.bvh.nodes.size(); ++i) {
    const LightBvhNode& n = l.bvh.nodes[i];
    if ((n.flags & kLightBvhLeaf) != 0u) {
      ++seen[n.child];
      EXPECT_EQ(l.bvh.words[n.child], i);
      continue;
    }
    // Children: next and `child`, each pointing back; the box and power hold theirs.
    for (uint32_t c : {i + 1, n.child}) {
      const LightBvhNode& k = l.bvh.nodes[c];
      EXPECT_EQ(k.parent, i);
      EXPECT_TRUE(glm::all(glm::lessThanEqual(l.bvh.boxes[i].lo, l.bvh.boxes[c].lo)));
      EXPECT_TRUE(glm::all(glm::greaterThanEqual(l.bvh.boxes[i].hi, l.bvh.boxes[c].hi)));
      EXPECT_LE(n.cosThetaO, k.cosThetaO + 1e-6f);
    }
    EXPECT_NEAR(n.phi, l.bvh.nodes[i + 1].phi + l.bvh.nodes[n.child].phi, 1e-5f * n.phi);
  }
  for (uint32_t e = 0; e < l.emitters.size(); ++e) {
    const bool unbounded = (l.emitters[e].triangle & kEmitterLight) != 0u &&
                           l.lights[l.emitters[e].triangle & ~kEmitterLight].type >= kLightDistant;
    EXPECT_EQ(seen[e], unbounded ? 0 : 1) << "emitter " << e;
    EXPECT_EQ(l.bvh.words[e] == kNoEmitter, unbounded);
  }
}

// The two halves of each quad are siblings marked kLightBvhSameBounds, and no other node is;
// wherever their importance is not zero, it is in the ratio of their power (what the walk
// assumes when it weighs such children by power).
TEST(LightBvh, SameBoundsChildrenWeighAsTheirPower) {
  const ManyLights l;
  int marked = 0;
  for (uint32_t i = 0; i < l.bvh.nodes.size(); ++i) {
    const LightBvhNode& n = l.bvh.nodes[i];
    if ((n.flags & kLightBvhLeaf) != 0u) continue;
    const LightBvhNode& a = l.bvh.nodes[i + 1];
    const LightBvhNode& b = l.bvh.nodes[n.child];
    const bool same = a.centre == b.centre && a.radius == b.radius && a.w == b.w &&
                      a.cosThetaO == b.cosThetaO && a.cosThetaE == b.cosThetaE;
    EXPECT_EQ((n.flags & kLightBvhSameBounds) != 0u, same) << "node " << i;
    if (!same) continue;
    ++marked;
    EXPECT_NEAR(std::max(a.phi, b.phi) / std::min(a.phi, b.phi), 3.0f, 1e-5f);  // the halves
    int lit = 0;
    for (const auto& [p, normal] : shadingPoints()) {
      const float ia = lightBoundsImportance(a, p, normal);
      const float ib = lightBoundsImportance(b, p, normal);
      EXPECT_EQ(ia == 0.0f, ib == 0.0f);
      if (ia == 0.0f) continue;
      ++lit;
      EXPECT_NEAR(ib / ia, b.phi / a.phi, 1e-5f * b.phi / a.phi);
    }
    EXPECT_GT(lit, 0);
  }
  EXPECT_EQ(marked, 3);
}

// pbrt-v4's importance, worked by hand: a point light (phi = 4 pi I) at distance 2 along the
// normal of the point: phi / d^2; at 60 degrees to the normal, times cos 60. A one-sided
// triangle seen from behind: none; two-sided: the same as from the front.
TEST(LightBvh, ImportanceMatchesHandComputedValues) {
  LightBvhNode point{};
  point.centre = vec3(0.0f, 0.0f, 2.0f);
  point.phi = 4.0f * kPi * 3.0f;
  point.w = vec3(0.0f, 0.0f, 1.0f);
  point.cosThetaO = -1.0f;
  point.sinThetaO = 0.0f;
  point.cosThetaE = std::cos(kPi / 2.0f);
  EXPECT_FLOAT_EQ(lightBoundsImportance(point, vec3(0.0f), vec3(0.0f, 0.0f, 1.0f)),
                  point.phi / 4.0f);
  const vec3 tilted(std::sin(kPi / 3.0f), 0.0f, std::cos(kPi / 3.0f));
  EXPECT_NEAR(lightBoundsImportance(point, vec3(0.0f), tilted), point.phi / 4.0f * 0.5f,
              1e-5f * point.phi);
  // In a medium (no normal): no cosine at the point.
  EXPECT_FLOAT_EQ(lightBoundsImportance(point, vec3(0.0f), vec3(0.0f)), point.phi / 4.0f);

  // A small triangle's bounds at height 2 facing down (w = -z): lit from below, dark above.
  LightBvhNode tri{};
  tri.centre = vec3(0.0f, 0.0f, 2.0f);
  tri.radius = 0.01f * std::sqrt(2.0f);
  tri.phi = 1.0f;
  tri.w = vec3(0.0f, 0.0f, -1.0f);
  tri.cosThetaO = 1.0f;
  tri.sinThetaO = 0.0f;
  tri.cosThetaE = std::cos(kPi / 2.0f);
  const float below = lightBoundsImportance(tri, vec3(0.0f), vec3(0.0f, 0.0f, 1.0f));
  EXPECT_NEAR(below, 1.0f / 4.0f, 1e-3f);
  EXPECT_EQ(lightBoundsImportance(tri, vec3(0.0f, 0.0f, 4.0f), vec3(0.0f, 0.0f, 1.0f)), 0.0f);
  tri.flags = kLightBvhTwoSided;
  EXPECT_NEAR(lightBoundsImportance(tri, vec3(0.0f, 0.0f, 4.0f), vec3(0.0f, 0.0f, 1.0f)), below,
              1e-6f);
}

// The tree's probabilities enumerated from the root (the test's own walk): each node's share
// of its parent's by the children's importance (by their power where their bounds differ in
// nothing else), the mass of a node whose children both have
// none lost (light sampling draws no light there, as in pbrt-v4). Each emitter's probability
// from emitterChoicePmf's walk up is its leaf's share, and the shares, the lost mass and the
// unbounded emitters' sum to one.
void enumerate(const ManyLights& l, uint32_t at, double mass, vec3 p, vec3 n,
               std::vector<double>& leafMass, double& lost) {
  const LightBvhNode& node = l.bvh.nodes[at];
  if ((node.flags & kLightBvhLeaf) != 0u) {
    if (at == 0u && !(lightBoundsImportance(node, p, n) > 0.0f)) {
      lost += mass;
    } else {
      leafMass[node.child] = mass;
    }
    return;
  }
  double c0 = lightBoundsImportance(l.bvh.nodes[at + 1], p, n);
  double c1 = lightBoundsImportance(l.bvh.nodes[node.child], p, n);
  if ((node.flags & kLightBvhSameBounds) != 0u) {  // by power: never both zero
    c0 = l.bvh.nodes[at + 1].phi;
    c1 = l.bvh.nodes[node.child].phi;
  }
  if (c0 == 0.0 && c1 == 0.0) {
    lost += mass;
    return;
  }
  enumerate(l, at + 1, mass * c0 / (c0 + c1), p, n, leafMass, lost);
  enumerate(l, node.child, mass * c1 / (c0 + c1), p, n, leafMass, lost);
}

TEST(LightBvh, ProbabilitiesSumToOneAtEveryPoint) {
  const ManyLights l;
  const PathScene scene = l.scene();
  int somethingLost = 0;
  for (const auto& [p, n] : shadingPoints()) {
    std::vector<double> leafMass(l.emitters.size(), 0.0);
    double lost = 0.0;
    enumerate(l, 0u, 1.0 - 2.0 / 3.0, p, n, leafMass, lost);
    double sum = lost;
    for (uint e = 0; e < l.emitters.size(); ++e) {
      const double pmf = emitterChoicePmf(scene, e, l.emitters[e], p, n);
      if (l.bvh.words[e] == kNoEmitter) {
        EXPECT_FLOAT_EQ(float(pmf), 1.0f / 3.0f);  // two unbounded emitters: 1 / (U + 1) each
      } else {
        EXPECT_NEAR(pmf, leafMass[e], 1e-5 * leafMass[e] + 1e-12) << "emitter " << e;
      }
      sum += pmf;
    }
    EXPECT_NEAR(sum, 1.0, 1e-5) << "at " << p.x << " " << p.y << " " << p.z;
    if (lost > 0.0) ++somethingLost;
  }
  // Some points see no light of some subtree: the lost mass is exercised, not only zero.
  EXPECT_GT(somethingLost, 0);
}

// Pearson's chi-square of counts against n * pmf, cells of expected count below 5 merged into
// one; the p-value.
double chiSquarePValue(const std::vector<double>& counts, const std::vector<double>& pmf,
                       double n) {
  double chi2 = 0.0, poolCount = 0.0, poolExpected = 0.0;
  int cells = 0;
  for (size_t i = 0; i < counts.size(); ++i) {
    const double expected = n * pmf[i];
    if (expected < 5.0) {
      poolCount += counts[i];
      poolExpected += expected;
      continue;
    }
    chi2 += (counts[i] - expected) * (counts[i] - expected) / expected;
    ++cells;
  }
  if (poolExpected > 0.0) {
    chi2 += (poolCount - poolExpected) * (poolCount - poolExpected) / poolExpected;
    ++cells;
  }
  return test::gammaQ(0.5 * (cells - 1), 0.5 * chi2);
}

// Choices at each point counted against emitterChoicePmf: they agree (p > 1e-4 at each of 24
// points, so that a sound sampler fails by chance once in 400 runs); the same counts against
// the power sampler's table (what the choice would follow without the tree), or against the
// tree's probabilities with the point's normal ignored, are rejected at most of the points.
TEST(LightBvh, ChoicesFollowTheirProbabilitiesChiSquare) {
  const ManyLights l;
  const PathScene scene = l.scene();
  constexpr int kSamples = 200000;
  int powerRejected = 0, normalRejected = 0, withNormal = 0;
  for (const auto& [p, n] : shadingPoints()) {
    std::vector<double> counts(l.emitters.size(), 0.0), pmf(l.emitters.size()),
        power(l.emitters.size()), noNormal(l.emitters.size());
    double total = 0.0;
    for (uint e = 0; e < l.emitters.size(); ++e) {
      pmf[e] = emitterChoicePmf(scene, e, l.emitters[e], p, n);
      power[e] = l.emitters[e].pmf;
      noNormal[e] = emitterChoicePmf(scene, e, l.emitters[e], p, vec3(0.0f));
    }
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int i = 0; i < kSamples; ++i) {
      const EmitterChoice c = chooseEmitter(scene, p, n, vec2(u(rng), u(rng)));
      if (c.emitter.triangle == kNoEmitter) continue;
      // The emitter's index in the table: the one whose entry this is.
      uint e = 0;
      while (l.emitters[e].triangle != c.emitter.triangle) ++e;
      // The probability the choice reports is the one the walk up computes.
      ASSERT_NEAR(c.pmf, pmf[e], 1e-5 * pmf[e]);
      counts[e] += 1.0;
      total += 1.0;
    }
    ASSERT_GT(total, 0.0);
    const double sum = std::accumulate(pmf.begin(), pmf.end(), 0.0);
    EXPECT_GT(chiSquarePValue(counts, pmf, total / sum), 1e-4) << "at " << p.x << " " << p.y;
    if (chiSquarePValue(counts, power, total) < 1e-6) ++powerRejected;
    if (n != vec3(0.0f)) {
      ++withNormal;
      if (chiSquarePValue(counts, noNormal, total) < 1e-6) ++normalRejected;
    }
  }
  EXPECT_EQ(powerRejected, 24);
  EXPECT_GE(normalRejected, withNormal * 3 / 4);
}

// A room of many small lights of unequal power (a 6 x 6 grid of ceiling tiles, one bright
// point light, a spot light) over a diffuse floor and walls: the light BVH, the power and the
// uniform samplers render it to the same image mean, on the CPU; the BVH with less noise than
// either (it chooses the tiles near each point).
std::string manyLightsScene(const std::string& lightSampler) {
  std::string s =
      "LookAt 0 -9 4  0 0 2  0 0 1\nCamera \"perspective\" \"float fov\" [60]\n"
      "Film \"rgb\" \"integer xresolution\" [32] \"integer yresolution\" [32]\n"
      "PixelFilter \"box\"\nIntegrator \"path\" \"integer maxdepth\" [3] "
      "\"string lightsampler\" \"" +
      lightSampler +
      "\"\nWorldBegin\n"
      "Material \"diffuse\" \"rgb reflectance\" [0.5 0.5 0.5]\n"
      "Shape \"trianglemesh\" \"point3 P\" [-10 -10 0  10 -10 0  10 10 0  -10 10 0]\n"
      "  \"integer indices\" [0 1 2 0 2 3]\n"
      "Shape \"trianglemesh\" \"point3 P\" [-10 10 0  10 10 0  10 10 8  -10 10 8]\n"
      "  \"integer indices\" [0 1 2 0 2 3]\n"
      "LightSource \"point\" \"point3 from\" [4 2 3] \"rgb I\" [6 6 6]\n"
      "LightSource \"spot\" \"point3 from\" [-4 -2 6] \"point3 to\" [-4 0 0] \"rgb I\" [30 30 "
      "30]\n";
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) {
      const float x = -7.5f + 3.0f * float(i), y = -7.5f + 3.0f * float(j);
      const float L = 1.0f + float((i * 7 + j * 3) % 5) * 4.0f;
      s += "AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [" + std::to_string(L) + " " +
           std::to_string(L) + " " + std::to_string(L) +
           "]\nShape \"trianglemesh\" \"point3 P\" [" + std::to_string(x) + " " +
           std::to_string(y) + " 8  " + std::to_string(x + 0.4f) + " " + std::to_string(y) +
           " 8  " + std::to_string(x + 0.4f) + " " + std::to_string(y + 0.4f) + " 8  " +
           std::to_string(x) + " " + std::to_string(y + 0.4f) +
           " 8]\n  \"integer indices\" [0 2 1 0 3 2]\nAttributeEnd\n";
    }
  }
  return s;
}

Image renderMean(const std::string& lightSampler, int spp, uint seed, vec3& mean) {
  RenderSettings settings;
  settings.seed = seed;
  const SceneData data =
      prepareScene(loadPbrtSceneText(manyLightsScene(lightSampler), "lights.pbrt"), settings);
  EXPECT_EQ(data.effects.lightBvh, lightSampler == "bvh");
  Film film(32, 32);
  const RenderStats stats = renderCpu(data, test::cpuOptions(2, spp), film);
  EXPECT_EQ(stats.invalidSamples, 0u);
  Image image = film.resolve();
  mean = vec3(0.0f);
  for (const vec3& v : image.pixels) mean += v / float(image.pixels.size());
  return image;
}

double relativeError(const Image& a, const Image& reference) {
  double sum = 0.0;
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    const double d = double(a.pixels[i].y) - double(reference.pixels[i].y);
    sum += d * d / (double(reference.pixels[i].y) * double(reference.pixels[i].y) + 1e-3);
  }
  return sum / double(a.pixels.size());
}

TEST(LightBvh, EverySamplerConvergesToTheSameImage) {
  vec3 reference{};
  const Image ref = renderMean("bvh", 512, 99, reference);
  double bvhError = 0.0;
  for (const char* sampler : {"bvh", "power", "uniform"}) {
    vec3 mean{};
    const Image image = renderMean(sampler, 128, 1, mean);
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(mean[c], reference[c], 0.01f * reference[c]) << sampler << " channel " << c;
    }
    const double error = relativeError(image, ref);
    if (std::string(sampler) == "bvh") {
      bvhError = error;
    } else {
      EXPECT_LT(bvhError, 0.8 * error) << sampler;
    }
  }
}

// The pbrt reader takes pbrt-v4's names; another is an error naming the parameter's line.
TEST(LightBvh, PbrtLightSamplerParameter) {
  RenderSettings settings;
  const SceneData power =
      prepareScene(loadPbrtSceneText(manyLightsScene("power"), "lights.pbrt"), settings);
  EXPECT_TRUE(power.lightBvh.empty());
  EXPECT_THROW(
      {
        try {
          loadPbrtSceneText(manyLightsScene("exhaustive"), "lights.pbrt");
        } catch (const InputError& e) {
          EXPECT_NE(std::string(e.what()).find("lights.pbrt:5"), std::string::npos) << e.what();
          EXPECT_NE(std::string(e.what()).find("unknown light sampler 'exhaustive'"),
                    std::string::npos)
              << e.what();
          throw;
        }
      },
      InputError);
}

// Both backends choose the same lights with the tree: the many-lights room agrees.
TEST(LightBvh, ManyLightsAgreeOnBothBackends) {
  RenderSettings settings;
  settings.width = 24;
  settings.height = 24;
  const SceneData data =
      prepareScene(loadPbrtSceneText(manyLightsScene("bvh"), "lights.pbrt"), settings);
  ASSERT_TRUE(data.effects.lightBvh);
  expectAgreement(renderBoth(data, 8));
}

}  // namespace
}  // namespace pt
