// The parallel BVH builders: the same tree for any thread count, the LBVH the same as the
// serial builder it replaced, the PLOC tree valid and of SAH quality, degenerate inputs.
// (Traversal of the PLOC tree against brute force is in bvh_test.cpp, with the LBVH's.)
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "bvh/bvh.h"
#include "bvh/bvh_build.h"
#include "bvh/traverse.h"
#include "closed_mesh.h"
#include "test_util.h"

namespace pt {
namespace test {
void expectValidBvh(const Bvh& bvh, size_t triangleCount, int maxLeafSize);  // bvh_test.cpp
}  // namespace test

namespace {

using test::expectValidBvh;

Bvh build(const std::vector<Triangle>& triangles, BvhBuilder builder, int leafSize, int threads) {
  BvhBuildOptions options;
  options.maxLeafSize = leafSize;
  options.builder = builder;
  options.threads = threads;
  return buildBvh(triangles, options);
}

void expectSameTree(const Bvh& a, const Bvh& b) {
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  EXPECT_EQ(std::memcmp(a.nodes.data(), b.nodes.data(), a.nodes.size() * sizeof(BvhNode)), 0);
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  for (size_t i = 0; i < a.triangles.size(); ++i) {
    ASSERT_EQ(a.triangles[i].primitive, b.triangles[i].primitive) << "slot " << i;
  }
  EXPECT_EQ(a.maxDepth, b.maxDepth);
  EXPECT_EQ(a.sahCost, b.sahCost);
}

// Small triangles scattered over a flat box, from an integer generator: coordinates are
// multiples of 1/1024, exact in float, so the tree is the same on every machine.
std::vector<Triangle> scatteredTriangles(int count) {
  uint32_t state = 20240611u;
  auto next = [&state](uint32_t range) {
    state = state * 1664525u + 1013904223u;
    return float((state >> 8) % range) / 1024.0f;
  };
  std::vector<Triangle> triangles;
  for (int i = 0; i < count; ++i) {
    const vec3 c(next(4096), next(4096), next(256));
    triangles.push_back(Triangle{c, 0, c + vec3(next(64), next(64), next(16)), kNoEmitter,
                                 c + vec3(next(16), next(64), next(64)), uint(i)});
  }
  return triangles;
}

// FNV-1a over the nodes' bytes and the triangles' load-order indices.
uint64_t treeHash(const Bvh& bvh) {
  uint64_t hash = 1469598103934665603ull;
  auto add = [&hash](const void* data, size_t size) {
    const unsigned char* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < size; ++i) hash = (hash ^ p[i]) * 1099511628211ull;
  };
  add(bvh.nodes.data(), bvh.nodes.size() * sizeof(BvhNode));
  for (const Triangle& t : bvh.triangles) add(&t.primitive, sizeof t.primitive);
  return hash;
}

Triangle triangle(vec3 a, vec3 b, vec3 c, uint primitive) {
  return Triangle{a, 0, b, kNoEmitter, c, primitive};
}

// `count` coincident copies of one triangle.
std::vector<Triangle> copies(uint count, vec3 a, vec3 b, vec3 c) {
  std::vector<Triangle> triangles;
  for (uint i = 0; i < count; ++i) triangles.push_back(triangle(a, b, c, i));
  return triangles;
}

TEST(BvhParallel, SameTreeForAnyThreadCount) {
  // About 100k triangles: enough work for seven workers (the builders use at most one per
  // 16k triangles), and the bunny, a real scan.
  const std::vector<Triangle> sphere = test::makeSphere(vec3(1, 2, 3), 5.0f, 224, 224);
  ASSERT_GT(sphere.size(), 6u * 16384u);
  const std::vector<Triangle> bunny = test::loadBunny();
  for (BvhBuilder builder : {BvhBuilder::kLbvh, BvhBuilder::kPloc}) {
    for (const auto* mesh : {&sphere, &bunny}) {
      SCOPED_TRACE(std::string(nameOf(kBuilderNames, builder)) + ", " +
                   std::to_string(mesh->size()) + " triangles");
      const Bvh one = build(*mesh, builder, 4, 1);
      for (int threads : {2, 7}) {
        SCOPED_TRACE(std::to_string(threads) + " threads");
        expectSameTree(one, build(*mesh, builder, 4, threads));
      }
    }
  }
}

TEST(BvhParallel, LbvhIsTheSerialBuildersTree) {
  // The hashes are of the trees that the serial LBVH builder (before it ran in parallel)
  // built from this mesh: the parallel one must not change a single node, or the images.
  const std::vector<Triangle> triangles = scatteredTriangles(60000);
  EXPECT_EQ(treeHash(build(triangles, BvhBuilder::kLbvh, 1, 0)), 0xc63929bc26e5f552ull);
  EXPECT_EQ(treeHash(build(triangles, BvhBuilder::kLbvh, 4, 0)), 0x55795a13dca5fef3ull);
}

TEST(BvhPloc, InvariantsHoldForSeveralLeafSizes) {
  const std::vector<Triangle> sphere = test::makeSphere(vec3(1, 2, 3), 5.0f, 40, 60);
  const std::vector<Triangle> bunny = test::loadBunny();
  for (const auto* mesh : {&sphere, &bunny}) {
    for (int leafSize : {1, 2, 4, 8}) {
      SCOPED_TRACE(std::to_string(mesh->size()) + " triangles, leaf size " +
                   std::to_string(leafSize));
      expectValidBvh(build(*mesh, BvhBuilder::kPloc, leafSize, 0), mesh->size(), leafSize);
    }
  }
}

TEST(BvhPloc, SahCostWithinTenPercentOfBinnedSahOnBunny) {
  const std::vector<Triangle> bunny = test::loadBunny();
  const double ploc = build(bunny, BvhBuilder::kPloc, 4, 0).sahCost;
  const double sah = build(bunny, BvhBuilder::kBinnedSah, 4, 0).sahCost;
  const double lbvh = build(bunny, BvhBuilder::kLbvh, 4, 0).sahCost;
  std::printf("bunny SAH cost: ploc %.2f, binned SAH %.2f, lbvh %.2f\n", ploc, sah, lbvh);
  EXPECT_LE(ploc, 1.1 * sah);
  EXPECT_LT(ploc, lbvh);
}

TEST(BvhBuild, SahCostOfAHandBuiltTree) {
  // Two unit right triangles far apart, leaves of one: a root over two leaves. The root box
  // is [0, 11] x [0, 1] x [0, 0]; each leaf's is [0, 1]^2 x [0, 0] (area 2 of the root's 22).
  const std::vector<Triangle> two = {triangle(vec3(0), vec3(1, 0, 0), vec3(0, 1, 0), 0),
                                     triangle(vec3(10, 0, 0), vec3(11, 0, 0), vec3(10, 1, 0), 1)};
  for (BvhBuilder builder : {BvhBuilder::kLbvh, BvhBuilder::kBinnedSah, BvhBuilder::kPloc}) {
    SCOPED_TRACE(std::string(nameOf(kBuilderNames, builder)));
    const Bvh bvh = build(two, builder, 1, 0);
    ASSERT_EQ(bvh.nodes.size(), 3u);
    EXPECT_DOUBLE_EQ(bvh.sahCost, kSahTraversalCost + 2 * (2.0 / 22.0) * kSahTriangleCost);
  }
  // A single leaf costs its triangle count.
  EXPECT_DOUBLE_EQ(build(two, BvhBuilder::kPloc, 4, 0).sahCost, 2 * kSahTriangleCost);
}

TEST(BvhBuild, DegenerateInputsBuildWithEveryBuilder) {
  const std::vector<Triangle> same = copies(300, vec3(0), vec3(1, 0, 0), vec3(0, 1, 0));
  const std::vector<Triangle> one = {triangle(vec3(1), vec3(2, 1, 1), vec3(1, 2, 1), 0)};
  const std::vector<Triangle> two = {triangle(vec3(1), vec3(2, 1, 1), vec3(1, 2, 1), 0),
                                     triangle(vec3(1), vec3(1, 1, 2), vec3(2, 1, 1), 1)};
  // Points and lines: boxes without area, so the SAH cost counts every node in full.
  const std::vector<Triangle> points = copies(50, vec3(3), vec3(3), vec3(3));
  for (BvhBuilder builder : {BvhBuilder::kLbvh, BvhBuilder::kBinnedSah, BvhBuilder::kPloc}) {
    for (int leafSize : {1, 4}) {
      SCOPED_TRACE(std::string(nameOf(kBuilderNames, builder)) + ", leaf size " +
                   std::to_string(leafSize));
      for (const auto* mesh : {&same, &one, &two, &points}) {
        const Bvh bvh = build(*mesh, builder, leafSize, 0);
        expectValidBvh(bvh, mesh->size(), leafSize);
        EXPECT_TRUE(std::isfinite(bvh.sahCost));
      }
      // Coincident triangles still split down to the leaf size, balanced.
      EXPECT_LE(build(same, builder, leafSize, 0).maxDepth, leafSize == 1 ? 9 : 7);
    }
  }
}

TEST(BvhPloc, FallsBackToBalancedSplitsBelowTheDepthLimit) {
  // Trees deeper than the traversal stack are rare (no mesh here makes one), so the fallback
  // is tested with a smaller limit: the sphere's PLOC tree is deeper than 14 levels.
  const std::vector<Triangle> sphere = test::makeSphere(vec3(1, 2, 3), 5.0f, 40, 60);
  const Bvh free = build(sphere, BvhBuilder::kPloc, 1, 0);
  ASSERT_GT(free.maxDepth, 14);
  Workers workers(2);
  const Bvh limited = buildPlocBvh(sphere, 1, workers, 14);
  expectValidBvh(limited, sphere.size(), 1);
  EXPECT_LE(limited.maxDepth, 14);
  // Rays from the centre through every triangle find the same hits in both trees.
  for (const Triangle& t : sphere) {
    const Ray ray{vec3(1, 2, 3), (t.v0 + t.v1 + t.v2) / 3.0f - vec3(1, 2, 3)};
    const auto a = closestHit(free, ray), b = closestHit(limited, ray);
    ASSERT_TRUE(a.has_value() && b.has_value());
    EXPECT_EQ(a->t, b->t);
  }
}

}  // namespace
}  // namespace pt
