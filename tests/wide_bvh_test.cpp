// The CPU reference's wide BVH (host/bvh/wide_bvh.h): its structure, and its queries against
// brute force and against the binary traversal, which they must reproduce bit for bit
// (distance, triangle, barycentrics) on every instruction set the traversal is compiled for.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "brute_force.h"
#include "bvh/bvh.h"
#include "bvh/traverse.h"
#include "bvh/wide_bvh.h"
#include "closed_mesh.h"
#include "render/prepare.h"
#include "test_util.h"

namespace pt {
namespace {

using test::loadBunny;

constexpr BvhBuilder kBuilders[] = {BvhBuilder::kLbvh, BvhBuilder::kBinnedSah, BvhBuilder::kPloc};

std::string builderName(BvhBuilder builder) {
  return std::string(nameOf(kBuilderNames, builder));
}

bool sameBits(float a, float b) {
  return std::bit_cast<uint32_t>(a) == std::bit_cast<uint32_t>(b);
}

// The two answers are the same bit for bit: both miss, or both hit the same triangle at the
// same distance with the same barycentrics.
bool sameHit(const std::optional<Hit>& a, const std::optional<Hit>& b) {
  if (a.has_value() != b.has_value()) return false;
  if (!a) return true;
  return sameBits(a->t, b->t) && a->triangle == b->triangle && a->primitive == b->primitive &&
         sameBits(a->barycentrics.x, b->barycentrics.x) &&
         sameBits(a->barycentrics.y, b->barycentrics.y) &&
         sameBits(a->barycentrics.z, b->barycentrics.z);
}

// Runs body() once per instruction set the wide traversal runs on here, the portable
// fallback included.
template <typename Body>
void forEachTarget(const Body& body) {
  test::forEachHighwayTarget(wideTraversalTargets(), body);
}

// The binary traversal's answers for every ray, closest hit (both tests) and any hit within
// tMax[i]: the reference that countDifferences compares the wide traversal with. The binary
// traversal is not dispatched by instruction set, so one set of answers serves every target.
struct BinaryAnswers {
  std::vector<std::optional<Hit>> closest[2];  // [0] watertight, [1] fast
  std::vector<char> any[2];
};

constexpr Intersection kBothTests[2] = {Intersection::kWatertight, Intersection::kFast};

BinaryAnswers binaryAnswers(const Bvh& bvh, const std::vector<Ray>& rays,
                            const std::vector<float>& tMax) {
  BinaryAnswers a;
  for (int k = 0; k < 2; ++k) {
    a.closest[k].reserve(rays.size());
    a.any[k].reserve(rays.size());
    for (size_t i = 0; i < rays.size(); ++i) {
      a.closest[k].push_back(closestHit(bvh, rays[i], INFINITY, kBothTests[k]));
      a.any[k].push_back(anyHit(bvh, rays[i], tMax[i], kBothTests[k]));
    }
  }
  return a;
}

// Counts the rays (and reports the first few) whose wide answers differ from the binary
// traversal's, closest hit (both tests) and any hit within tMax[i].
int countDifferences(const BinaryAnswers& binary, const WideBvh& wide, const std::vector<Ray>& rays,
                     const std::vector<float>& tMax) {
  int differences = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    for (int k = 0; k < 2; ++k) {
      const Intersection test = kBothTests[k];
      const bool same = sameHit(binary.closest[k][i], closestHit(wide, rays[i], INFINITY, test)) &&
                        bool(binary.any[k][i]) == anyHit(wide, rays[i], tMax[i], test);
      if (!same && ++differences <= 5) {
        ADD_FAILURE() << "ray " << i << (test == Intersection::kFast ? " (fast)" : "")
                      << ": the wide traversal's answer differs from the binary one";
      }
    }
  }
  return differences;
}

int countDifferences(const Bvh& bvh, const WideBvh& wide, const std::vector<Ray>& rays,
                     const std::vector<float>& tMax) {
  return countDifferences(binaryAnswers(bvh, rays, tMax), wide, rays, tMax);
}

// Walks the wide tree and checks it against the binary one it came from: every triangle in
// exactly one packet lane, at its own index, with its own vertices; every box holding what
// is below it; unused lanes inverted and never referenced.
void expectValidWideBvh(const Bvh& bvh, const WideBvh& wide) {
  const size_t n = bvh.triangles.size();
  std::vector<int> seen(n, 0);
  std::vector<int> packetSeen(wide.packets.size(), 0);
  std::vector<int> nodeSeen(wide.nodes.size(), 0);
  EXPECT_EQ(wide.rootMin, bvh.nodes[0].boundsMin);
  EXPECT_EQ(wide.rootMax, bvh.nodes[0].boundsMax);
  struct Item {
    uint32_t node;
    vec3 lo, hi;  // the box it must lie in
    int depth;
  };
  std::vector<Item> todo{{0, wide.rootMin, wide.rootMax, 0}};
  while (!todo.empty()) {
    const Item item = todo.back();
    todo.pop_back();
    ASSERT_LT(item.node, wide.nodes.size());
    ASSERT_LE(item.depth, wide.maxDepth);
    ++nodeSeen[item.node];
    const WideNode& node = wide.nodes[item.node];
    int used = 0;
    for (int i = 0; i < kWideLanes; ++i) {
      const vec3 lo(node.bounds[0][i], node.bounds[1][i], node.bounds[2][i]);
      const vec3 hi(node.bounds[3][i], node.bounds[4][i], node.bounds[5][i]);
      if (node.child[i] == kWideEmpty) {
        EXPECT_EQ(lo, vec3(INFINITY));
        EXPECT_EQ(hi, vec3(-INFINITY));
        EXPECT_EQ(node.packetCount[i], 0u);
        continue;
      }
      ++used;
      EXPECT_TRUE(all(lessThanEqual(item.lo, lo)) && all(lessThanEqual(hi, item.hi)))
          << "node " << item.node << " lane " << i << " sticks out of its parent's box";
      if (!(node.child[i] & kWideLeaf)) {
        EXPECT_EQ(node.packetCount[i], 0u);
        todo.push_back({node.child[i], lo, hi, item.depth + 1});
        continue;
      }
      const uint32_t first = node.child[i] & ~kWideLeaf;
      ASSERT_GE(node.packetCount[i], 1u);
      ASSERT_LE(size_t(first) + node.packetCount[i], wide.packets.size());
      for (uint32_t p = first; p < first + node.packetCount[i]; ++p) {
        ++packetSeen[p];
        const TrianglePacket& packet = wide.packets[p];
        ASSERT_GE(packet.count, 1u);
        ASSERT_LE(packet.count, uint32_t(kPacketLanes));
        ASSERT_LE(size_t(packet.first) + packet.count, n);
        for (uint32_t lane = 0; lane < uint32_t(kPacketLanes); ++lane) {
          // Unused lanes repeat the last triangle.
          const uint32_t index = packet.first + std::min(lane, packet.count - 1);
          if (lane < packet.count) ++seen[index];
          const Triangle& t = bvh.triangles[index];
          const vec3 v[3] = {t.v0, t.v1, t.v2};
          for (int k = 0; k < 3; ++k) {
            const vec3 stored(packet.v[k][0][lane], packet.v[k][1][lane], packet.v[k][2][lane]);
            EXPECT_EQ(stored, v[k]) << "packet " << p << " lane " << lane;
            EXPECT_TRUE(all(lessThanEqual(lo, stored)) && all(lessThanEqual(stored, hi)))
                << "packet " << p << " lane " << lane << " sticks out of its leaf's box";
          }
        }
      }
    }
    EXPECT_GE(used, 1) << "node " << item.node << " holds nothing";
    // A leaf lane's box is exactly its triangles' (a split leaf's two lanes each their own).
    for (int i = 0; i < kWideLanes; ++i) {
      if (node.child[i] == kWideEmpty || !(node.child[i] & kWideLeaf)) continue;
      vec3 lo(INFINITY), hi(-INFINITY);
      const uint32_t first = node.child[i] & ~kWideLeaf;
      for (uint32_t p = first; p < first + node.packetCount[i]; ++p) {
        for (uint32_t lane = 0; lane < wide.packets[p].count; ++lane) {
          const Triangle t = wide.packets[p].triangle(lane);
          lo = min(lo, min(t.v0, min(t.v1, t.v2)));
          hi = max(hi, max(t.v0, max(t.v1, t.v2)));
        }
      }
      EXPECT_EQ(lo, vec3(node.bounds[0][i], node.bounds[1][i], node.bounds[2][i]))
          << "node " << item.node << " lane " << i;
      EXPECT_EQ(hi, vec3(node.bounds[3][i], node.bounds[4][i], node.bounds[5][i]))
          << "node " << item.node << " lane " << i;
    }
  }
  for (size_t i = 0; i < n; ++i) ASSERT_EQ(seen[i], 1) << "triangle " << i;
  for (size_t p = 0; p < wide.packets.size(); ++p) ASSERT_EQ(packetSeen[p], 1) << "packet " << p;
  for (size_t k = 0; k < wide.nodes.size(); ++k) ASSERT_EQ(nodeSeen[k], 1) << "node " << k;
}

// The leaves that the collapse split over two lanes (wide_shape::leafSplit), checked: two
// adjacent leaf lanes whose packets, and triangles, follow on from each other, so that the
// degenerate rays' binary traversal reads them as the one leaf they were. Returns how many.
int expectValidSplitLeaves(const WideBvh& wide) {
  int splits = 0;
  for (size_t n = 0; n < wide.nodes.size(); ++n) {
    const WideNode& node = wide.nodes[n];
    const uint64_t shape = wide.shapes[n];
    // The binary ranges of the shape, as the traversal of degenerate rays walks them.
    auto walk = [&](auto& self, int first, int size, int k) -> void {
      if (size < 2) return;
      const int half = wide_shape::split(shape, k);
      if (!wide_shape::leafSplit(shape, k)) {
        self(self, first, half, k + 1);
        self(self, first + half, size - half, k + half);
        return;
      }
      ++splits;
      ASSERT_EQ(size, 2) << "node " << n;
      ASSERT_EQ(half, 1) << "node " << n;
      const uint32_t a = node.child[first], b = node.child[first + 1];
      ASSERT_TRUE((a & kWideLeaf) && a != kWideEmpty && (b & kWideLeaf) && b != kWideEmpty);
      EXPECT_EQ((a & ~kWideLeaf) + node.packetCount[first], b & ~kWideLeaf) << "node " << n;
      const TrianglePacket& last = wide.packets[(b & ~kWideLeaf) - 1];
      EXPECT_EQ(last.first + last.count, wide.packets[b & ~kWideLeaf].first) << "node " << n;
    };
    walk(walk, 0, wide_shape::lanes(shape), 0);
  }
  return splits;
}

// The binary order that the wide traversal keeps rests on every interior box being exactly
// the union of its children's (wide_bvh.h). True of every builder; checked here.
void expectParentsAreUnions(const Bvh& bvh) {
  for (size_t i = 0; i < bvh.nodes.size(); ++i) {
    const BvhNode& node = bvh.nodes[i];
    if (node.count > 0) continue;
    const BvhNode& l = bvh.nodes[i + 1];
    const BvhNode& r = bvh.nodes[node.offset];
    ASSERT_EQ(node.boundsMin, min(l.boundsMin, r.boundsMin)) << "node " << i;
    ASSERT_EQ(node.boundsMax, max(l.boundsMax, r.boundsMax)) << "node " << i;
  }
}

TEST(WideBvh, HoldsEveryTriangleOnceInsideItsBoxes) {
  const std::vector<Triangle> sphere = test::makeSphere(vec3(1, 2, 3), 5.0f, 40, 60);
  for (BvhBuilder builder : kBuilders) {
    for (int leafSize : {1, 2, 4, 7, 16}) {
      SCOPED_TRACE(builderName(builder) + ", leaf size " + std::to_string(leafSize));
      const Bvh bvh = buildBvh(sphere, BvhBuildOptions{leafSize, builder});
      expectParentsAreUnions(bvh);
      expectValidWideBvh(bvh, buildWideBvh(bvh));
    }
  }
  const std::vector<Triangle> bunny = loadBunny();
  for (BvhBuilder builder : kBuilders) {
    SCOPED_TRACE(builderName(builder) + " on the bunny");
    const Bvh bvh = buildBvh(bunny, BvhBuildOptions{4, builder});
    expectParentsAreUnions(bvh);
    expectValidWideBvh(bvh, buildWideBvh(bvh));
  }
}

TEST(WideBvh, SameTreeForAnyNumberOfThreads) {
  // Large enough for the collapse to split its work into pieces (bvh.nodes / 32768 workers).
  const std::vector<Triangle> sphere = test::makeSphere(vec3(0.0f), 1.0f, 160, 161);
  const Bvh bvh = buildBvh(sphere, BvhBuildOptions{1, BvhBuilder::kPloc});
  ASSERT_GT(bvh.nodes.size(), 3u * 32768u);
  const WideBvh one = buildWideBvh(bvh, 1);
  expectValidWideBvh(bvh, one);
  for (int threads : {2, 3, 8}) {
    SCOPED_TRACE(std::to_string(threads) + " threads");
    const WideBvh wide = buildWideBvh(bvh, threads);
    ASSERT_EQ(wide.nodes.size(), one.nodes.size());
    ASSERT_EQ(wide.packets.size(), one.packets.size());
    EXPECT_EQ(wide.shapes, one.shapes);
    EXPECT_EQ(wide.maxDepth, one.maxDepth);
    EXPECT_EQ(std::memcmp(wide.nodes.data(), one.nodes.data(), one.nodes.size() * sizeof(WideNode)),
              0);
    for (size_t p = 0; p < one.packets.size(); ++p) {  // (fields: a packet has padding)
      const TrianglePacket &a = wide.packets[p], &b = one.packets[p];
      ASSERT_TRUE(std::memcmp(a.v, b.v, sizeof(a.v)) == 0 && a.first == b.first &&
                  a.count == b.count &&
                  std::memcmp(a.primitive, b.primitive, sizeof(a.primitive)) == 0)
          << "packet " << p;
    }
  }
}

TEST(WideBvh, SingleLeafTree) {
  const std::vector<Triangle> one = {
      Triangle{vec3(0), 0, vec3(1, 0, 0), kNoEmitter, vec3(0, 1, 0), 0}};
  const Bvh bvh = buildBvh(one);
  ASSERT_EQ(bvh.nodes.size(), 1u);
  const WideBvh wide = buildWideBvh(bvh);
  expectValidWideBvh(bvh, wide);
  forEachTarget([&] {
    const auto hit = closestHit(wide, Ray{vec3(0.25f, 0.25f, -1.0f), vec3(0, 0, 1)});
    ASSERT_TRUE(hit.has_value());
    EXPECT_EQ(hit->t, 1.0f);
    EXPECT_EQ(hit->triangle, 0u);
    EXPECT_FALSE(closestHit(wide, Ray{vec3(0.75f, 0.75f, -1.0f), vec3(0, 0, 1)}).has_value());
    EXPECT_TRUE(anyHit(wide, Ray{vec3(0.25f, 0.25f, -1.0f), vec3(0, 0, 1)}, 1.5f));
    EXPECT_FALSE(anyHit(wide, Ray{vec3(0.25f, 0.25f, -1.0f), vec3(0, 0, 1)}, 1.0f));
  });
}

TEST(WideBvh, MatchesBruteForceAndTheBinaryTraversalOnBunny) {
  const std::vector<Triangle> bunny = loadBunny();
  // Rays as in BvhTraversal.MatchesBruteForceOnBunny, another seed.
  const int kRays = test::kBruteForceRays;
  const test::RandomRays set = test::raysAroundMesh(bunny, kRays, 4321);
  const std::vector<Ray>& rays = set.rays;
  const std::vector<test::BruteHit> expected = test::bruteForceClosestHits(bunny, rays);
  std::vector<float> tMax(kRays);
  int hits = 0;
  for (int i = 0; i < kRays; ++i) {
    tMax[i] = expected[i].found ? expected[i].t * set.shadowFraction[i] : 1e3f;
    hits += expected[i].found;
  }
  EXPECT_GT(hits, kRays / 2);  // the test exercises hits, not just misses
  // Leaves of up to 4 triangles (one packet), and of up to 8 (the CPU renderer's), which the
  // collapse splits where a node has lanes to spare.
  for (auto [builder, leafSize] : {std::pair{BvhBuilder::kLbvh, 4},
                                   {BvhBuilder::kBinnedSah, 4},
                                   {BvhBuilder::kPloc, 4},
                                   {BvhBuilder::kPloc, 8}}) {
    SCOPED_TRACE(builderName(builder) + ", leaf size " + std::to_string(leafSize));
    const Bvh bvh = buildBvh(bunny, BvhBuildOptions{leafSize, builder});
    const WideBvh wide = buildWideBvh(bvh);
    expectValidWideBvh(bvh, wide);
    EXPECT_EQ(expectValidSplitLeaves(wide) > 0, leafSize > 4);
    int mismatches = 0, anyHitMismatches = 0;
    for (int i = 0; i < kRays; ++i) {
      const auto hit = closestHit(wide, rays[i]);
      const test::BruteHit& e = expected[i];
      // The same distance bit for bit (at an edge two triangles may share it), and the hit
      // names its triangle's primitive.
      const bool same =
          hit.has_value() == e.found &&
          (!e.found || (hit->t == e.t && hit->primitive == bvh.triangles[hit->triangle].primitive));
      if (!same && ++mismatches <= 5) ADD_FAILURE() << "ray " << i << " closest hit differs";
      const bool blocked = anyHit(wide, rays[i], tMax[i]);
      if (blocked != (e.found && e.t < tMax[i]) && ++anyHitMismatches <= 5)
        ADD_FAILURE() << "ray " << i << " any-hit differs";
    }
    EXPECT_EQ(mismatches, 0);
    EXPECT_EQ(anyHitMismatches, 0);
    // And exactly the binary traversal's answers, with either triangle test.
    EXPECT_EQ(countDifferences(bvh, wide, rays, tMax), 0);
  }
}

TEST(WideBvh, SameAnswersOnEveryInstructionSet) {
  // Every compiled target this CPU runs, the one-lane fallback included, against the binary
  // traversal; leaf sizes that give partly filled packets and leaves of several packets.
  // Random rays, and rays from inside aimed at vertices and edges, where triangles tie and
  // the order of the tests decides.
  const std::vector<Triangle> bunny = loadBunny();
  std::mt19937 rng(77);
  std::uniform_real_distribution<float> uni(-1.0f, 1.0f);
  std::vector<Ray> rays;
  std::vector<float> tMax;
  for (int i = 0; i < 20000; ++i) {
    const vec3 o(uni(rng) * 0.3f, uni(rng) * 0.3f, uni(rng) * 0.3f);
    const Triangle& t = bunny[size_t(i) * 7919 % bunny.size()];
    const vec3 d = i % 3 ? (t.v0 + t.v1 + t.v2) / 3.0f - o : vec3(uni(rng), uni(rng), uni(rng));
    rays.push_back(Ray{o, d});
    tMax.push_back(std::abs(uni(rng)) * 1.5f);
  }
  const Bvh reference = buildBvh(bunny);
  const std::vector<RayQuery> aimed =
      test::aimedRays(reference.triangles, test::interiorPoints(reference, 8, 2));
  for (size_t i = 0; i < aimed.size(); i += 16) {
    rays.push_back(Ray{aimed[i].origin, aimed[i].direction});
    tMax.push_back(1.0f);  // the surface lies at t = 1
  }
  for (int leafSize : {1, 4, 9}) {
    SCOPED_TRACE("leaf size " + std::to_string(leafSize));
    const Bvh bvh = buildBvh(bunny, BvhBuildOptions{leafSize, BvhBuilder::kPloc});
    const WideBvh wide = buildWideBvh(bvh);
    EXPECT_EQ(expectValidSplitLeaves(wide) > 0, leafSize > 4);
    const BinaryAnswers binary = binaryAnswers(bvh, rays, tMax);
    forEachTarget([&] { EXPECT_EQ(countDifferences(binary, wide, rays, tMax), 0); });
  }
}

TEST(WideBvh, DeepTreeWithinTheStack) {
  // The chain of BvhBuild.DepthStaysWithinTraversalStack (62 levels of Morton splits, then
  // clusters of coincident triangles), the deepest tree the builders make: the wide stack
  // must hold the widest and deepest traversal of it.
  const std::vector<Triangle> tris = test::makeDeepMortonChain();
  const Bvh bvh = buildBvh(tris, BvhBuildOptions{1});
  ASSERT_GT(bvh.maxDepth, 50);
  const WideBvh wide = buildWideBvh(bvh);
  expectValidWideBvh(bvh, wide);
  EXPECT_LE(wide.maxDepth, (bvh.maxDepth + 2) / 3);
  // Rays through each cluster (which pass every coincident triangle of it) and along the
  // chain's diagonal, which enter box after box.
  std::vector<Ray> rays;
  for (size_t i = 0; i < tris.size(); i += 64) {
    const Triangle& t = tris[i];
    rays.push_back(Ray{(t.v0 + t.v1 + t.v2) / 3.0f - vec3(0, 0, 1), vec3(0, 0, 1)});
    rays.push_back(Ray{(t.v0 + t.v1 + t.v2) / 3.0f + vec3(0, 0, 1), vec3(0, 0, -1)});
  }
  rays.push_back(Ray{vec3(-0.1f), vec3(1.0f, 1.0f, 1.0f)});
  rays.push_back(Ray{vec3(1.1f), vec3(-1.0f, -1.0f, -1.0f)});
  const std::vector<float> tMax(rays.size(), 10.0f);
  forEachTarget([&] { EXPECT_EQ(countDifferences(bvh, wide, rays, tMax), 0); });
}

TEST(WideBvh, AxisParallelRaysInFacePlanes) {
  // As BvhTraversal.AxisParallelRaysInFacePlanes: direction components exactly 0, rays in the
  // planes of box faces, through a closed octahedron.
  const std::vector<Triangle> cube = test::makeSphere(vec3(0.5f), 0.5f, 2, 4);
  const Bvh bvh = buildBvh(cube);
  const WideBvh wide = buildWideBvh(bvh);
  const BvhNode& root = bvh.nodes[0];
  forEachTarget([&] {
    for (vec3 d : {vec3(1, 0, 0), vec3(-1, 0, 0), vec3(0, 1, 0), vec3(0, -1, 0), vec3(0, 0, 1),
                   vec3(0, 0, -1)}) {
      for (vec3 o : {vec3(0.5f), vec3(root.boundsMin.x, 0.5f, 0.5f) - d,
                     vec3(0.5f, root.boundsMax.y, 0.5f) - d, vec3(root.boundsMin) - d}) {
        const Ray ray{o, d};
        EXPECT_TRUE(sameHit(closestHit(wide, ray), closestHit(bvh, ray)));
        EXPECT_EQ(anyHit(wide, ray, 2.0f), anyHit(bvh, ray, 2.0f));
      }
      const auto hit = closestHit(wide, Ray{vec3(0.5f), d});
      ASSERT_TRUE(hit.has_value());
    }
    // Origin on the root box's min-x face plane, travelling along +y inside that plane; and
    // a parallel ray just outside the slab.
    const Ray inPlane{vec3(root.boundsMin.x, root.boundsMin.y - 1.0f, 0.5f), vec3(0, 1, 0)};
    EXPECT_TRUE(sameHit(closestHit(wide, inPlane), closestHit(bvh, inPlane)));
    const Ray outside{vec3(root.boundsMin.x - 1e-6f, root.boundsMin.y - 1, 0.5f), vec3(0, 1, 0)};
    EXPECT_FALSE(closestHit(wide, outside).has_value());
    EXPECT_FALSE(anyHit(wide, outside, INFINITY));
  });
}

TEST(WideBvh, DegenerateRaysAsTheBinaryTraversal) {
  // Zero, NaN and infinite components in the direction or the origin, and huge origins: the
  // answer is the binary traversal's (for NaN rays: nothing, turned away at the root box).
  const std::vector<Triangle> sphere = test::makeSphere(vec3(0.5f, -0.25f, 2.0f), 1.0f, 12, 16);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = INFINITY;
  const vec3 origins[] = {vec3(0.5f, -0.25f, 2.0f), vec3(0.5f, -0.25f, -3.0f), vec3(0.0f),
                          vec3(nan, 0, 0),          vec3(0, inf, 0),           vec3(-inf, 0, 1),
                          vec3(1e30f, 0, 0),        vec3(0.5f, -0.25f, -1e30f)};
  const vec3 directions[] = {vec3(0, 0, 1),        vec3(0, 0, -1),     vec3(0.0f),
                             vec3(nan, 0, 1),      vec3(0, nan, 0),    vec3(inf, 0, 1),
                             vec3(0, -inf, 0),     vec3(1e-38f, 0, 1), vec3(1, 1, 1e-40f),
                             vec3(-0.0f, -0.0f, 1)};
  std::vector<Ray> rays;
  for (const vec3& o : origins) {
    for (const vec3& d : directions) rays.push_back(Ray{o, d});
  }
  // And from random points inside, with one component NaN or infinite (where NaN enters only
  // the y or z slab, the scalar box test passes over it, and every triangle reached takes
  // the ray at t = NaN), or a direction too short to have one.
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> uni(-0.5f, 0.5f);
  for (int i = 0; i < 3000; ++i) {
    vec3 d(uni(rng), uni(rng), uni(rng));
    d[i % 3] = i % 2 ? nan : (i % 4 ? inf : -inf);
    if (i % 5 == 0) d = vec3(uni(rng), uni(rng), uni(rng)) * 1e-31f;
    rays.push_back(Ray{vec3(0.5f, -0.25f, 2.0f) + vec3(uni(rng), uni(rng), uni(rng)), d});
  }
  const std::vector<float> tMax(rays.size(), 5.0f);
  // Leaves of up to 2 triangles, and of up to 8, which the collapse splits over two lanes.
  for (int leafSize : {2, 8}) {
    SCOPED_TRACE("leaf size " + std::to_string(leafSize));
    const Bvh bvh = buildBvh(sphere, BvhBuildOptions{leafSize});
    const WideBvh wide = buildWideBvh(bvh);
    EXPECT_EQ(expectValidSplitLeaves(wide) > 0, leafSize > 4);
    forEachTarget([&] { EXPECT_EQ(countDifferences(bvh, wide, rays, tMax), 0); });
  }
}

// How many of the rays meet, in some triangle of the mesh, an edge function that comes out
// exactly 0 in float but not in double (the case for intersectTriangle's recomputation).
size_t raysNeedingDoublePrecision(const std::vector<Triangle>& tris, const std::vector<Ray>& rays) {
  size_t count = 0;
  for (const Ray& ray : rays) {
    const RayPrecomputed r(ray);
    for (const Triangle& tri : tris) {
      const vec3 a = tri.v0 - r.origin, b = tri.v1 - r.origin, c = tri.v2 - r.origin;
      const float ax = a[r.kx] - r.sx * a[r.kz], ay = a[r.ky] - r.sy * a[r.kz];
      const float bx = b[r.kx] - r.sx * b[r.kz], by = b[r.ky] - r.sy * b[r.kz];
      const float cx = c[r.kx] - r.sx * c[r.kz], cy = c[r.ky] - r.sy * c[r.kz];
      const float f[3] = {cx * by - cy * bx, ax * cy - ay * cx, bx * ay - by * ax};
      const double e[3] = {double(cx) * double(by) - double(cy) * double(bx),
                           double(ax) * double(cy) - double(ay) * double(cx),
                           double(bx) * double(ay) - double(by) * double(ax)};
      bool differs = false;
      for (int k = 0; k < 3; ++k) differs |= f[k] == 0.0f && float(e[k]) != 0.0f;
      if (differs) {
        ++count;
        break;
      }
    }
  }
  return count;
}

TEST(WideBvh, WatertightAtSharedEdgesAndVertices) {
  // The probe of BvhTraversal.WatertightAtSharedEdgesAndVertices: over a million rays from
  // inside a closed sphere aimed exactly at its vertices and edge midpoints. No ray may leak,
  // and every answer must be the binary traversal's: at a vertex or an edge an edge function
  // is often exactly 0 in float, and which triangle takes the ray then depends on its
  // recomputation in double precision (lane by lane here) and on the order of the tests.
  const vec3 center(0.3f, -0.2f, 0.1f);
  const std::vector<Triangle> sphere = test::makeSphere(center, 1.0f, 200, 350);
  const Bvh bvh = buildBvh(sphere);
  const WideBvh wide = buildWideBvh(bvh);
  const vec3 origins[] = {center, center + vec3(0.2f, 0.1f, -0.3f),
                          center + vec3(-0.61f, 0.33f, 0.05f)};
  std::vector<Ray> rays;
  for (const vec3& o : origins) {
    for (const Triangle& t : sphere) {
      for (vec3 target : {t.v0, 0.5f * (t.v0 + t.v1), 0.5f * (t.v1 + t.v2)}) {
        rays.push_back(Ray{o, target - o});
      }
    }
  }
  ASSERT_GE(rays.size(), 1000000u);
  // The set does exercise the recomputation (checked on a sample: brute force over the
  // whole mesh per ray; about a fifth of the sampled rays need it).
  std::vector<Ray> sample;
  for (size_t i = 0; i < rays.size(); i += 997 * test::kProbeStride) sample.push_back(rays[i]);
  const size_t needDouble = raysNeedingDoublePrecision(sphere, sample);
  EXPECT_GT(needDouble, 0u);
  int leaks = 0, differ = 0;
  for (size_t i = 0; i < rays.size(); i += test::kProbeStride) {
    const Ray& ray = rays[i];
    const auto hit = closestHit(wide, ray);
    leaks += !hit.has_value();
    differ += !sameHit(hit, closestHit(bvh, ray));
  }
  EXPECT_EQ(leaks, 0);
  EXPECT_EQ(differ, 0);
  std::printf(
      "sphere: %zu rays, %d leak, %d differ from the binary traversal; %zu of %zu sampled "
      "need double precision\n",
      rays.size(), leaks, differ, needDouble, sample.size());
}

TEST(WideBvh, WatertightOnAClosedScannedMesh) {
  // The probe of BvhTraversal.WatertightOnAClosedScannedMesh on the bunny: rays from inside
  // aimed at every vertex and edge midpoint stop at the surface, with the binary answers.
  const std::vector<Triangle> bunny = loadBunny();
  const Bvh bvh = buildBvh(bunny);
  const WideBvh wide = buildWideBvh(bvh);
  const std::vector<vec3> origins = test::interiorPoints(bvh, 8, 6);
  ASSERT_EQ(origins.size(), 6u);
  const std::vector<RayQuery> queries = test::aimedRays(bvh.triangles, origins);
  ASSERT_GE(queries.size(), 1000000u);
  const float outward = test::outwardSign(bvh.triangles);
  size_t leaks = 0, differ = 0;
  for (size_t i = 0; i < queries.size(); i += test::kProbeStride) {
    const RayQuery& q = queries[i];
    const Ray ray{q.origin, q.direction};
    const auto hit = closestHit(wide, ray);
    leaks += test::escaped(bvh.triangles, outward, q, hit.has_value(), hit ? hit->t : 0.0f,
                           hit ? hit->triangle : 0u);
    differ += !sameHit(hit, closestHit(bvh, ray));
  }
  EXPECT_EQ(leaks, 0u);
  EXPECT_EQ(differ, 0u);
}

// A closest-hit answer by the scene's triangles: which one (Triangle::primitive), where and
// with which barycentrics, bit for bit.
struct SceneHit {
  bool found = false;
  uint32_t tBits = 0, primitive = 0, bary[3] = {0, 0, 0};
  bool operator==(const SceneHit&) const = default;
};
SceneHit sceneHit(const Bvh& bvh, const std::optional<Hit>& hit) {
  SceneHit h;
  if (!hit) return h;
  h.found = true;
  h.tBits = std::bit_cast<uint32_t>(hit->t);
  h.primitive = bvh.triangles[hit->triangle].primitive;
  for (int k = 0; k < 3; ++k) h.bary[k] = std::bit_cast<uint32_t>(hit->barycentrics[k]);
  return h;
}

// The closest-hit rule (isCloserHit, sampling.h: the smallest t, then the triangle listed
// first) names one hit whatever order a traversal tests the triangles in. So every tree
// (builder, leaf size), binary or wide, on every instruction set, gives the same answer bit
// for bit, on rays through the bunny's shared vertices and edges, where two triangles often
// report the same distance; and it is the rule's answer by brute force.
TEST(ClosestHitRule, TheSameHitOnEveryTreeAndEveryTraversal) {
  const std::vector<Triangle> bunny = loadBunny();
  for (uint32_t k = 0; k < bunny.size(); ++k) ASSERT_EQ(bunny[k].primitive, k);
  const Bvh reference = buildBvh(bunny, BvhBuildOptions{4, BvhBuilder::kPloc});
  std::vector<Ray> rays;
  for (const RayQuery& q :
       test::aimedRays(reference.triangles, test::interiorPoints(reference, 4, 2))) {
    rays.push_back(Ray{q.origin, q.direction});
  }
  ASSERT_GE(rays.size(), 100000u);
  rays.resize(size_t(test::kBruteForceRays));  // 100k (20k under the sanitizers)
  std::vector<SceneHit> expected(rays.size());
  for (size_t i = 0; i < rays.size(); ++i)
    expected[i] = sceneHit(reference, closestHit(reference, rays[i]));
  // The rule by brute force on 400 of the rays, and how many of those tie.
  std::vector<Ray> sample;
  std::vector<SceneHit> sampleExpected;
  for (size_t i = 0; i < rays.size(); i += rays.size() / 400) {
    sample.push_back(rays[i]);
    sampleExpected.push_back(expected[i]);
  }
  size_t ties = 0, wrong = 0;
  const std::vector<test::BruteHit> brute = test::bruteForceClosestHits(bunny, sample);
  for (size_t i = 0; i < sample.size(); ++i) {
    SceneHit rule;
    if (brute[i].found) {
      rule.found = true;
      rule.tBits = std::bit_cast<uint32_t>(brute[i].t);
      rule.primitive = brute[i].primitive;
      for (int k = 0; k < 3; ++k) rule.bary[k] = std::bit_cast<uint32_t>(brute[i].barycentrics[k]);
    }
    wrong += !(rule == sampleExpected[i]);
    ties += brute[i].atClosest > 1;
  }
  EXPECT_EQ(wrong, 0u);
  EXPECT_GT(ties, 15u);  // the rays do tie
  std::printf("%zu of %zu rays checked by brute force tie\n", ties, sample.size());
  struct Tree {
    BvhBuilder builder;
    int leafSize;
  };
  for (const Tree tree : {Tree{BvhBuilder::kPloc, 1}, Tree{BvhBuilder::kPloc, 8},
                          Tree{BvhBuilder::kLbvh, 3}, Tree{BvhBuilder::kBinnedSah, 2}}) {
    SCOPED_TRACE(builderName(tree.builder) + ", leaf size " + std::to_string(tree.leafSize));
    const Bvh bvh = buildBvh(bunny, BvhBuildOptions{tree.leafSize, tree.builder});
    const WideBvh wide = buildWideBvh(bvh);
    size_t binaryDiffers = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
      binaryDiffers += !(sceneHit(bvh, closestHit(bvh, rays[i])) == expected[i]);
    }
    EXPECT_EQ(binaryDiffers, 0u);
    forEachTarget([&] {
      size_t wideDiffers = 0;
      for (size_t i = 0; i < rays.size(); ++i) {
        wideDiffers += !(sceneHit(bvh, closestHit(wide, rays[i])) == expected[i]);
      }
      EXPECT_EQ(wideDiffers, 0u);
    });
  }
}

// Where two triangles coincide (the same vertices, so every ray meets both at the same t),
// every traversal reports the one listed first in the scene, whichever of the pair the tree
// puts first: half the pairs list the copy first.
TEST(ClosestHitRule, CoincidentTrianglesGoToTheOneListedFirst) {
  std::vector<Triangle> grid;
  const int n = 24;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const vec3 a(i, j, 0), b(i + 1, j, 0), c(i, j + 1, 0), d(i + 1, j + 1, 0);
      for (const Triangle& t :
           {Triangle{a, 0, b, kNoEmitter, d, 0}, Triangle{a, 0, d, kNoEmitter, c, 0}}) {
        // The pair: original (material 0) and copy (material 1), in either order.
        Triangle copy = t;
        copy.material = 1;
        const bool copyFirst = (i + j) % 2 == 1;
        grid.push_back(copyFirst ? copy : t);
        grid.push_back(copyFirst ? t : copy);
      }
    }
  }
  for (uint32_t k = 0; k < grid.size(); ++k) grid[k].primitive = k;
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  std::vector<Ray> rays;
  for (int i = 0; i < 20000; ++i) {
    const vec3 target(uni(rng) * n, uni(rng) * n, 0.0f);
    const vec3 origin(uni(rng) * n, uni(rng) * n, i % 2 ? 3.0f : -3.0f);
    rays.push_back(Ray{origin, target - origin});
  }
  for (int leafSize : {1, 2, 4}) {
    for (BvhBuilder builder : kBuilders) {
      SCOPED_TRACE(builderName(builder) + ", leaf size " + std::to_string(leafSize));
      const Bvh bvh = buildBvh(grid, BvhBuildOptions{leafSize, builder});
      const WideBvh wide = buildWideBvh(bvh);
      size_t notFirst = 0, missed = 0;
      for (const Ray& ray : rays) {
        for (const auto& hit : {closestHit(bvh, ray), closestHit(wide, ray)}) {
          missed += !hit.has_value();
          // The first of its pair: an even primitive (pairs are 2k, 2k + 1).
          notFirst += hit && bvh.triangles[hit->triangle].primitive % 2 != 0;
        }
      }
      EXPECT_EQ(missed, 0u);
      EXPECT_EQ(notFirst, 0u);
    }
  }
}

TEST(WideBvh, SceneDataBuildsItOnceAndCopiesBuildTheirOwn) {
  Scene scene;
  scene.materials = {Material{vec3(0.5f), kMaterialDiffuse, vec3(0.0f), 0}};
  scene.materialNames = {"white"};
  scene.triangles = test::makeSphere(vec3(0.0f), 1.0f, 8, 12);
  scene.camera.position = vec3(0, 0, -3);
  const SceneData data = prepareScene(scene, RenderSettings{.width = 8, .height = 8});
  const WideBvh& wide = data.wideBvh();
  EXPECT_EQ(&wide, &data.wideBvh());  // built once
  expectValidWideBvh(data.bvh, wide);
  const SceneData copy = data;
  EXPECT_NE(&copy.wideBvh(), &wide);
  expectValidWideBvh(copy.bvh, copy.wideBvh());
}

}  // namespace
}  // namespace pt
