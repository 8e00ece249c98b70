// The emitter alias table (buildEmitters, host/render/prepare.cpp) that next-event estimation
// picks lights from: with emitters of unequal area and emission, each must be picked with
// probability proportional to its power (area x luminance), and its pmf must say so.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "common/shared.h"
#include "render/prepare.h"

namespace pt {
namespace {

// The emitter (index into the table) that the integrators pick with random numbers u,
// through the functions of shaders/sampling.h both of them call: a slot from u.x, kept when
// u.y is below its threshold, else that slot's alias.
uint pickEmitter(const std::vector<Emitter>& table, vec2 u) {
  const uint slot = aliasTableSlot(u.x, uint(table.size()));
  return aliasTablePick(slot, table[slot], u.y);
}

// Luminance of an emission, the weight of its channels in the table.
double luminance(vec3 e) {
  return 0.2126 * e.x + 0.7152 * e.y + 0.0722 * e.z;
}

// Right triangles in the plane z = 0 with legs `a` along x and `b` along y (area a * b / 2).
Triangle rightTriangle(float a, float b, uint material) {
  return Triangle{vec3(0.0f), material, vec3(a, 0, 0), kNoEmitter, vec3(0, b, 0), 0};
}

struct Lights {
  std::vector<Material> materials;
  std::vector<Triangle> triangles;
  std::vector<uint32_t> emissive;   // the triangles that must be in the table, in order
  std::vector<double> probability;  // of each, proportional to area x luminance
};

// Six emitters whose powers span a factor of 60, in four colours (luminance 0.72 to 2), with
// areas from 0.05 to 3, among triangles that must stay out of the table: one that does not
// emit and one of zero area. Weighing by area alone, by luminance alone, by the sum of the
// channels or uniformly moves every probability by far more than the tolerance below.
Lights unequalLights() {
  Lights l;
  const vec3 none(0.0f), red(4, 0, 0), green(0, 1, 0), blue(0, 0, 10), white(2.0f);
  for (vec3 e : {none, red, green, blue, white}) {
    l.materials.push_back(Material{vec3(0.5f), kMaterialDiffuse, e, 0});
  }
  l.triangles = {rightTriangle(1, 1, 1),        // red, area 0.5
                 rightTriangle(2, 1, 0),        // does not emit
                 rightTriangle(2, 3, 2),        // green, area 3
                 rightTriangle(0.5f, 0.5f, 3),  // blue, area 0.125
                 rightTriangle(1, 2, 4),        // white, area 1
                 Triangle{vec3(0.0f), 1, vec3(1, 1, 0), kNoEmitter, vec3(2, 2, 0), 0},  // no area
                 rightTriangle(0.2f, 0.5f, 2),  // green, area 0.05
                 rightTriangle(1.5f, 1, 4)};    // white, area 0.75
  l.emissive = {0, 2, 3, 4, 6, 7};
  double total = 0.0;
  for (uint32_t t : l.emissive) {
    const Triangle& tri = l.triangles[t];
    const double area = 0.5 * double(tri.v1.x) * double(tri.v2.y);
    l.probability.push_back(area * luminance(l.materials[tri.material].emission));
    total += l.probability.back();
  }
  for (double& p : l.probability) p /= total;
  return l;
}

TEST(EmitterTable, PmfIsProportionalToAreaTimesLuminance) {
  Lights l = unequalLights();
  const std::vector<Emitter> table = buildEmitters(l.triangles, l.materials);
  ASSERT_EQ(table.size(), l.emissive.size());
  for (uint32_t t = 0; t < l.triangles.size(); ++t) {
    const auto k = std::find(l.emissive.begin(), l.emissive.end(), t) - l.emissive.begin();
    EXPECT_EQ(l.triangles[t].emitter, k < long(table.size()) ? uint32_t(k) : kNoEmitter)
        << "triangle " << t;
  }
  // The probability that pickEmitter gives each emitter, from the table's entries: each slot
  // is drawn with probability 1/n, and gives its own emitter below the threshold, else its
  // alias.
  const double n = double(table.size());
  std::vector<double> picked(table.size(), 0.0);
  for (const Emitter& e : table) {
    ASSERT_GE(e.aliasThreshold, 0.0f);
    ASSERT_LE(e.aliasThreshold, 1.0f);
    ASSERT_LT(e.alias, table.size());
  }
  for (size_t slot = 0; slot < table.size(); ++slot) {
    picked[slot] += double(table[slot].aliasThreshold) / n;
    picked[table[slot].alias] += (1.0 - double(table[slot].aliasThreshold)) / n;
  }
  for (size_t k = 0; k < table.size(); ++k) {
    SCOPED_TRACE("emitter " + std::to_string(k));
    EXPECT_EQ(table[k].triangle, l.emissive[k]);
    EXPECT_NEAR(table[k].pmf, l.probability[k], 1e-6 * l.probability[k]);
    EXPECT_NEAR(picked[k], l.probability[k], 1e-6);
  }
}

// Like pbrt-v4's AliasTable tests: how often each emitter is picked in many draws of the
// integrators' own random numbers for the light choice, against its probability, within
// 5 standard deviations of the binomial count (at one million draws, at most 0.0025 of
// probability; each alternative named at unequalLights() is off by more than 0.1 for some
// emitter).
TEST(EmitterTable, PickedAsOftenAsItsProbability) {
  Lights l = unequalLights();
  const std::vector<Emitter> table = buildEmitters(l.triangles, l.materials);
  ASSERT_EQ(table.size(), l.probability.size());
  constexpr uint kDraws = 1u << 20;
  for (bool sobol : {false, true}) {
    SCOPED_TRACE(sobol ? "Sobol" : "independent");
    std::vector<double> count(table.size(), 0.0);
    for (uint i = 0; i < kDraws; ++i) {
      const vec2 u = random2(sobol, uvec2(3, 5), i, kDimFirstBounce + kDimLightChoose, 1u);
      ++count[pickEmitter(table, u)];
    }
    for (size_t k = 0; k < table.size(); ++k) {
      const double p = l.probability[k];
      const double sigma = std::sqrt(double(kDraws) * p * (1.0 - p));
      EXPECT_NEAR(count[k], double(kDraws) * p, 5.0 * sigma)
          << "emitter " << k << ": picked " << count[k] / kDraws << " of the time, pmf "
          << table[k].pmf << ", expected " << p;
    }
  }
}

TEST(EmitterTable, NoEmittersGiveAnEmptyTable) {
  Lights l = unequalLights();
  for (Material& m : l.materials) m.emission = vec3(0.0f);
  EXPECT_TRUE(buildEmitters(l.triangles, l.materials).empty());
  for (const Triangle& t : l.triangles) EXPECT_EQ(t.emitter, kNoEmitter);
}

}  // namespace
}  // namespace pt
