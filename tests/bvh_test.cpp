// BVH construction invariants and traversal against brute force.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "brute_force.h"
#include "bvh/bvh.h"
#include "bvh/traverse.h"
#include "closed_mesh.h"
#include "scene/scene.h"
#include "test_util.h"

namespace pt {
namespace test {

// Checks every structural invariant of a built BVH (bvh_build_test.cpp uses it too).
void expectValidBvh(const Bvh& bvh, size_t triangleCount, int maxLeafSize) {
  ASSERT_EQ(bvh.triangles.size(), triangleCount);
  ASSERT_LE(bvh.maxDepth, int(kBvhStackSize));
  std::vector<int> leafOf(triangleCount, 0);  // how many leaves hold each triangle slot
  std::vector<int> seenPrimitive(triangleCount, 0);
  size_t leaves = 0;
  // Walk the tree from the root, checking children against parents.
  struct Item {
    uint32_t node;
    int depth;
  };
  std::vector<Item> todo{{0, 0}};
  std::vector<int> visited(bvh.nodes.size(), 0);
  while (!todo.empty()) {
    const Item item = todo.back();
    todo.pop_back();
    ASSERT_LT(item.node, bvh.nodes.size());
    visited[item.node]++;
    const BvhNode& node = bvh.nodes[item.node];
    ASSERT_TRUE(all(lessThanEqual(node.boundsMin, node.boundsMax)));
    if (node.count > 0) {
      ++leaves;
      EXPECT_LE(node.count, uint32_t(maxLeafSize));
      ASSERT_LE(size_t(node.offset) + node.count, triangleCount);
      for (uint32_t i = node.offset; i < node.offset + node.count; ++i) {
        leafOf[i]++;
        const Triangle& t = bvh.triangles[i];
        for (vec3 v : {t.v0, t.v1, t.v2}) {
          EXPECT_TRUE(all(lessThanEqual(node.boundsMin, v)) &&
                      all(lessThanEqual(v, node.boundsMax)));
        }
      }
      continue;
    }
    const uint32_t left = item.node + 1, right = node.offset;
    ASSERT_GT(right, left) << "right child must come after the left subtree";
    for (uint32_t child : {left, right}) {
      const BvhNode& c = bvh.nodes[child];
      EXPECT_TRUE(all(lessThanEqual(node.boundsMin, c.boundsMin)));
      EXPECT_TRUE(all(lessThanEqual(c.boundsMax, node.boundsMax)));
      todo.push_back({child, item.depth + 1});
    }
  }
  EXPECT_EQ(bvh.nodes.size(), 2 * leaves - 1);
  for (size_t i = 0; i < bvh.nodes.size(); ++i) EXPECT_EQ(visited[i], 1) << "node " << i;
  for (size_t i = 0; i < triangleCount; ++i) {
    EXPECT_EQ(leafOf[i], 1) << "triangle slot " << i;
    ASSERT_LT(bvh.triangles[i].primitive, triangleCount);
    seenPrimitive[bvh.triangles[i].primitive]++;
  }
  for (size_t i = 0; i < triangleCount; ++i) EXPECT_EQ(seenPrimitive[i], 1) << "primitive " << i;
}

}  // namespace test
namespace {

using test::expectValidBvh;
using test::loadBunny;

// Morton codes of the reordered triangles, normalised as the builder does, are sorted.
void expectMortonOrder(const Bvh& bvh) {
  vec3 lo(INFINITY), hi(-INFINITY);
  std::vector<vec3> c;
  for (const Triangle& t : bvh.triangles) {
    c.push_back((t.v0 + t.v1 + t.v2) * (1.0f / 3.0f));
    lo = min(lo, c.back());
    hi = max(hi, c.back());
  }
  const vec3 e = hi - lo;
  const vec3 s(e.x > 0 ? 1 / e.x : 0, e.y > 0 ? 1 / e.y : 0, e.z > 0 ? 1 / e.z : 0);
  for (size_t i = 1; i < c.size(); ++i) {
    ASSERT_LE(mortonCode63((c[i - 1] - lo) * s), mortonCode63((c[i] - lo) * s)) << i;
  }
}

using test::BruteHit;

// Closest hit by testing every triangle.

BruteHit bruteForce(const std::vector<Triangle>& tris, const Ray& ray) {
  const RayPrecomputed r(ray);
  BruteHit best;
  for (const Triangle& tri : tris) {
    Hit h;
    if (intersectTriangle(r, tri, best.t, h)) best = {true, h.t, tri.primitive};
  }
  return best;
}

TEST(BvhMorton, InterleavesBitsXLowest) {
  const float cell = 1.0f / float(1 << 21);
  EXPECT_EQ(mortonCode63(vec3(0.0f)), 0u);
  EXPECT_EQ(mortonCode63(vec3(cell * 1.5f, 0, 0)), 0b001u);
  EXPECT_EQ(mortonCode63(vec3(0, cell * 1.5f, 0)), 0b010u);
  EXPECT_EQ(mortonCode63(vec3(0, 0, cell * 1.5f)), 0b100u);
  EXPECT_EQ(mortonCode63(vec3(cell * 2.5f, 0, 0)), 0b001000u);
  // The top corner uses all 63 bits, and 1.0 maps to the last cell, not past it.
  EXPECT_EQ(mortonCode63(vec3(1.0f)), (uint64_t(1) << 63) - 1);
}

TEST(BvhBuild, InvariantsHoldForSeveralLeafSizes) {
  const std::vector<Triangle> sphere = test::makeSphere(vec3(1, 2, 3), 5.0f, 40, 60);
  for (int leafSize : {1, 2, 4, 8}) {
    SCOPED_TRACE("leaf size " + std::to_string(leafSize));
    const Bvh bvh = buildBvh(sphere, BvhBuildOptions{leafSize});
    expectValidBvh(bvh, sphere.size(), leafSize);
    expectMortonOrder(bvh);
  }
}

TEST(BvhBuild, BinnedSahInvariantsHoldForSeveralLeafSizes) {
  const std::vector<Triangle> sphere = test::makeSphere(vec3(1, 2, 3), 5.0f, 40, 60);
  for (int leafSize : {1, 4, 8}) {
    SCOPED_TRACE("leaf size " + std::to_string(leafSize));
    expectValidBvh(buildBvh(sphere, BvhBuildOptions{leafSize, BvhBuilder::kBinnedSah}),
                   sphere.size(), leafSize);
  }
  // Coincident triangles and a deep chain still respect the stack.
  std::vector<Triangle> same(100,
                             Triangle{vec3(0), 0, vec3(1, 0, 0), kNoEmitter, vec3(0, 1, 0), 0});
  for (uint i = 0; i < same.size(); ++i) same[i].primitive = i;
  expectValidBvh(buildBvh(same, BvhBuildOptions{1, BvhBuilder::kBinnedSah}), same.size(), 1);
}

TEST(BvhBuild, SingleTriangleIsOneLeaf) {
  const Bvh bvh = buildBvh({Triangle{vec3(0), 0, vec3(1, 0, 0), kNoEmitter, vec3(0, 1, 0), 0}});
  ASSERT_EQ(bvh.nodes.size(), 1u);
  EXPECT_EQ(bvh.nodes[0].count, 1u);
  EXPECT_EQ(bvh.nodes[0].boundsMax, vec3(1, 1, 0));
}

TEST(BvhBuild, EqualMortonCodesStillSplit) {
  // 100 copies of one triangle: every code is equal, yet leaves must stay small.
  std::vector<Triangle> tris(100,
                             Triangle{vec3(0), 0, vec3(1, 0, 0), kNoEmitter, vec3(0, 1, 0), 0});
  for (uint i = 0; i < tris.size(); ++i) tris[i].primitive = i;
  const Bvh bvh = buildBvh(tris, BvhBuildOptions{2});
  expectValidBvh(bvh, tris.size(), 2);
  EXPECT_LE(bvh.maxDepth, 7);  // balanced: ceil(log2(50)) levels
}

TEST(BvhBuild, DepthStaysWithinTraversalStack) {
  // 63 clusters whose Morton codes each have a single bit set, one cluster per bit: every
  // highest-differing-bit split peels off one cluster, a chain 62 levels deep, and each
  // cluster of 64 coincident triangles needs 6 more levels with leaves of 1. Without the
  // balanced fallback the tree would be 68 deep; the traversal stack holds kBvhStackSize.
  const std::vector<Triangle> tris = test::makeDeepMortonChain();
  const Bvh bvh = buildBvh(tris, BvhBuildOptions{1});
  expectValidBvh(bvh, tris.size(), 1);
  EXPECT_GT(bvh.maxDepth, 50);  // the Morton chain really is deep here
  // Traversal with the fixed stack still finds what brute force finds, for every cluster.
  for (size_t i = 0; i < tris.size(); i += 64) {
    const Triangle& t = tris[i];
    const Ray ray{(t.v0 + t.v1 + t.v2) / 3.0f - vec3(0, 0, 1), vec3(0, 0, 1)};
    const auto hit = closestHit(bvh, ray);
    ASSERT_TRUE(hit.has_value()) << "cluster " << i / 64;
    EXPECT_EQ(hit->t, bruteForce(tris, ray).t);
  }
}

TEST(BvhBuild, BunnyInvariants) {
  const std::vector<Triangle> bunny = loadBunny();
  ASSERT_EQ(bunny.size(), 69666u);
  const Bvh bvh = buildBvh(bunny, BvhBuildOptions{4});
  expectValidBvh(bvh, bunny.size(), 4);
  expectMortonOrder(bvh);
}

TEST(BvhTraversal, MatchesBruteForceOnBunny) {
  const std::vector<Triangle> bunny = loadBunny();
  const int kRays = test::kBruteForceRays;
  const test::RandomRays set = test::raysAroundMesh(bunny, kRays, 1234);
  const std::vector<Ray>& rays = set.rays;
  const std::vector<BruteHit> expected = test::bruteForceClosestHits(bunny, rays);
  // The LBVH and the PLOC tree (the SAH tree is compared with the LBVH below).
  for (BvhBuilder builder : {BvhBuilder::kLbvh, BvhBuilder::kPloc}) {
    SCOPED_TRACE(std::string(nameOf(kBuilderNames, builder)));
    const Bvh bvh = buildBvh(bunny, BvhBuildOptions{4, builder});
    int hits = 0, mismatches = 0, anyHitMismatches = 0;
    for (int i = 0; i < kRays; ++i) {
      const auto hit = closestHit(bvh, rays[i]);
      const BruteHit& e = expected[i];
      hits += e.found;
      // Same distance bit for bit (the triangle may differ only where two share that
      // distance, at an edge, so the distance is what is compared).
      const bool same = hit.has_value() == e.found && (!e.found || hit->t == e.t);
      if (!same && ++mismatches <= 5) ADD_FAILURE() << "ray " << i << " closest hit differs";
      // Any-hit within a range that may or may not contain the closest hit.
      const float tMax = e.found ? e.t * set.shadowFraction[i] : 1e3f;
      const bool blocked = anyHit(bvh, rays[i], tMax);
      const bool expectBlocked = e.found && e.t < tMax;
      if (blocked != expectBlocked && ++anyHitMismatches <= 5)
        ADD_FAILURE() << "ray " << i << " any-hit differs";
    }
    EXPECT_EQ(mismatches, 0);
    EXPECT_EQ(anyHitMismatches, 0);
    EXPECT_GT(hits, kRays / 2);  // the test exercises hits, not just misses
  }
}

TEST(BvhTraversal, BinnedSahTracesLikeTheLbvhOnBunny) {
  // The LBVH is checked against brute force above; the SAH tree must give the same hits.
  const std::vector<Triangle> bunny = loadBunny();
  const Bvh lbvh = buildBvh(bunny, BvhBuildOptions{4, BvhBuilder::kLbvh});
  const Bvh sah = buildBvh(bunny, BvhBuildOptions{4, BvhBuilder::kBinnedSah});
  expectValidBvh(sah, bunny.size(), 4);
  std::mt19937 rng(99);
  std::uniform_real_distribution<float> uni(-2.0f, 2.0f);
  int hits = 0, differ = 0;
  for (int i = 0; i < 100000; ++i) {
    const vec3 o(uni(rng), uni(rng), uni(rng));
    const Triangle& t = bunny[size_t(i) * 7919 % bunny.size()];
    const vec3 d = i % 2 ? (t.v0 + t.v1 + t.v2) / 3.0f - o : vec3(uni(rng), uni(rng), uni(rng));
    const auto a = closestHit(lbvh, Ray{o, d});
    const auto b = closestHit(sah, Ray{o, d});
    hits += a.has_value();
    differ += a.has_value() != b.has_value() || (a && a->t != b->t);
    const float tMax = std::abs(uni(rng));
    differ += anyHit(lbvh, Ray{o, d}, tMax) != anyHit(sah, Ray{o, d}, tMax);
  }
  EXPECT_EQ(differ, 0);
  EXPECT_GT(hits, 30000);
}

TEST(BvhTraversal, AxisParallelRaysInFacePlanes) {
  // A closed octahedron in the unit cube; rays along the axes that run exactly in the planes of the
  // box faces (direction components exactly 0) must still find the far faces.
  const std::vector<Triangle> cube = test::makeSphere(vec3(0.5f), 0.5f, 2, 4);  // an octahedron
  const Bvh bvh = buildBvh(cube);
  const BvhNode& root = bvh.nodes[0];
  // Origin on the root box's min-x face plane, travelling along +y inside that plane.
  const Ray inPlane{vec3(root.boundsMin.x, root.boundsMin.y - 1.0f, 0.5f), vec3(0, 1, 0)};
  float tNear = 0;
  EXPECT_TRUE(
      intersectBox(RayPrecomputed(inPlane), root.boundsMin, root.boundsMax, INFINITY, tNear));
  EXPECT_FLOAT_EQ(tNear, 1.0f);
  // A parallel ray outside the slab misses the box. (Within about 1e-30 of the plane the
  // test may report a hit: box tests may err towards hits, never towards misses.)
  const Ray outside{vec3(root.boundsMin.x - 1e-6f, root.boundsMin.y - 1, 0.5f), vec3(0, 1, 0)};
  EXPECT_FALSE(
      intersectBox(RayPrecomputed(outside), root.boundsMin, root.boundsMax, INFINITY, tNear));
  // Axis-parallel rays through the centre hit the closed mesh, and agree with brute force.
  for (vec3 d : {vec3(1, 0, 0), vec3(-1, 0, 0), vec3(0, 1, 0), vec3(0, -1, 0), vec3(0, 0, 1),
                 vec3(0, 0, -1)}) {
    const Ray ray{vec3(0.5f), d};
    const auto hit = closestHit(bvh, ray);
    ASSERT_TRUE(hit.has_value());
    EXPECT_EQ(hit->t, bruteForce(cube, ray).t);
  }
}

TEST(BvhTraversal, WatertightAtSharedEdgesAndVertices) {
  // Over a million rays from inside a closed, finely tessellated sphere, aimed exactly at
  // its vertices and edge midpoints, where a non-watertight test lets rays slip between
  // neighbouring triangles. The sphere is off the origin so coordinates are not symmetric.
  const vec3 center(0.3f, -0.2f, 0.1f);
  const std::vector<Triangle> sphere = test::makeSphere(center, 1.0f, 200, 350);
  const Bvh bvh = buildBvh(sphere);
  const vec3 origins[] = {center, center + vec3(0.2f, 0.1f, -0.3f),
                          center + vec3(-0.61f, 0.33f, 0.05f)};
  int rays = 0, probed = 0, leaks = 0, fastLeaks = 0;
  for (const vec3& o : origins) {
    for (const Triangle& t : sphere) {
      for (vec3 target : {t.v0, 0.5f * (t.v0 + t.v1), 0.5f * (t.v1 + t.v2)}) {
        if (size_t(rays++) % test::kProbeStride != 0) continue;
        ++probed;
        if (!closestHit(bvh, Ray{o, target - o}).has_value()) ++leaks;
        if (!closestHit(bvh, Ray{o, target - o}, INFINITY, Intersection::kFast)) {
          ++fastLeaks;
        }
      }
    }
  }
  EXPECT_GE(rays, 1000000);
  EXPECT_EQ(probed, (rays + int(test::kProbeStride) - 1) / int(test::kProbeStride));
  EXPECT_EQ(leaks, 0);
  // The same rays find the cracks of a non-watertight test (Moller-Trumbore): the rays are
  // hard enough to tell the two apart.
  EXPECT_GT(fastLeaks, 1000 / int(test::kProbeStride));
}

TEST(BvhTraversal, WatertightOnAClosedScannedMesh) {
  // The same probe on a real scan: rays from points inside the bunny aimed at each of its
  // vertices and edge midpoints must stop at the surface there, not slip through and
  // then hit the bunny from outside or nothing at all.
  const std::vector<Triangle> bunny = loadBunny();
  ASSERT_EQ(test::openOrMisorientedEdges(bunny), 0u) << "the bunny is expected to be closed";
  const Bvh bvh = buildBvh(bunny);
  const std::vector<vec3> origins = test::interiorPoints(bvh, 8, 6);
  ASSERT_EQ(origins.size(), 6u);
  const std::vector<RayQuery> queries = test::aimedRays(bvh.triangles, origins);
  ASSERT_GE(queries.size(), 1000000u);
  const float outward = test::outwardSign(bvh.triangles);
  size_t leaks = 0, fastLeaks = 0;
  for (size_t i = 0; i < queries.size(); i += test::kProbeStride) {
    const RayQuery& q = queries[i];
    const Ray ray{q.origin, q.direction};
    const auto hit = closestHit(bvh, ray);
    leaks += test::escaped(bvh.triangles, outward, q, hit.has_value(), hit ? hit->t : 0.0f,
                           hit ? hit->triangle : 0u);
    const auto fast = closestHit(bvh, ray, INFINITY, Intersection::kFast);
    fastLeaks += test::escaped(bvh.triangles, outward, q, fast.has_value(), fast ? fast->t : 0.0f,
                               fast ? fast->triangle : 0u);
  }
  EXPECT_EQ(leaks, 0u);
  // The rays are hard enough to tell a watertight test from one that is not.
  EXPECT_GT(fastLeaks, 1000u / test::kProbeStride);
  std::printf("bunny: %zu rays, %zu escape with the watertight test, %zu with Moller-Trumbore\n",
              queries.size(), leaks, fastLeaks);
}

}  // namespace
}  // namespace pt
