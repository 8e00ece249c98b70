// The GPU's layout of the BVH (vulkan/gpu_bvh.h) against the binary tree it comes from, and
// the shader's traversal of it (through shaders/raycast.comp) against the CPU traversal:
// watertightness at shared edges and vertices, closest and any hit on the bunny, the
// triangle chosen where hits tie, leaves split for the layout, and axis-parallel rays, all
// with the validation layers on.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "bvh/traverse.h"
#include "bvh/wide_bvh.h"
#include "closed_mesh.h"
#include "common/check.h"
#include "render_compare.h"
#include "scene/scene.h"
#include "test_util.h"
#include "vulkan/gpu_bvh.h"
#include "vulkan/raycast.h"

namespace pt {
namespace {

const ContextOptions kValidated{.validation = validationWanted()};

// The rays traced on the device with validation (where wanted), which must report no
// validation error and no query cut short by the loop cap, and the dispatch's device time
// (what the ray benchmark divides by) as a positive, finite number of seconds.
std::vector<RayResult> traceChecked(const Bvh& bvh, const std::vector<RayQuery>& queries) {
  RaycastStats stats;
  std::vector<RayResult> results = traceRaysVulkan(bvh, queries, kValidated, &stats);
  EXPECT_EQ(stats.validationErrors, 0u);
  EXPECT_EQ(stats.truncated, 0u);
  EXPECT_GT(stats.deviceSeconds, 0.0);
  EXPECT_LT(stats.deviceSeconds, 3600.0);
  return results;
}

bool boxContains(vec3 lo, vec3 hi, vec3 p) {
  return all(lessThanEqual(lo, p)) && all(lessThanEqual(p, hi));
}

// Walks the GPU layout alongside the binary tree it was built from and counts what differs:
// the shape and the boxes must be the binary tree's (a leaf of more than kGpuBvhMaxLeafCount
// triangles split under nodes with infinite boxes), every node but node 0 referred to once,
// every box must contain the boxes or triangles below it, every triangle must lie in one leaf
// reference, the leaves in the binary tree's depth-first order, and GpuBvh::maxDepth must be
// the depth the traversal stack needs.
class LayoutCheck {
 public:
  LayoutCheck(const Bvh& bvh, const GpuBvh& gpu)
      : bvh_(bvh), gpu_(gpu), references_(gpu.nodes.size(), 0) {
    const GpuBvhNode& top = gpu.nodes.at(0);
    boxesDiffer += top.leftMin != bvh.nodes[0].boundsMin || top.leftMax != bvh.nodes[0].boundsMax;
    child(top.left, top.leftMin, top.leftMax, 0, 0);
    for (size_t i = 1; i < references_.size(); ++i) badReferences += references_[i] != 1;
    missedTriangles = bvh.triangles.size() - nextTriangle_;
  }

  size_t boxesDiffer = 0;      // a child's box is not its binary node's
  size_t notContained = 0;     // a box or triangle sticks out of the box above it
  size_t badReferences = 0;    // out of range, of the wrong kind, or not referred to once
  size_t outOfOrder = 0;       // a leaf reference that does not start where the last ended
  size_t missedTriangles = 0;  // triangles in no leaf reference
  int maxDepth = 0;            // interior nodes on the longest path
  size_t splitNodes = 0;       // nodes over the halves of a leaf too large for a reference

 private:
  // The reference `ref` to binary node `index`, whose box its parent holds as (lo, hi);
  // `depth` interior nodes lie above it.
  void child(uint ref, vec3 lo, vec3 hi, uint32_t index, int depth) {
    const BvhNode& b = bvh_.nodes[index];
    boxesDiffer += lo != b.boundsMin || hi != b.boundsMax;
    if (b.count > 0) {
      const size_t start = nextTriangle_;
      leaf(ref, lo, hi, depth);
      outOfOrder += start != b.offset || nextTriangle_ != size_t(b.offset) + b.count;
      return;
    }
    const GpuBvhNode* n = interior(ref, depth);
    if (!n) return;
    notContained += !boxContains(lo, hi, n->leftMin) || !boxContains(lo, hi, n->leftMax) ||
                    !boxContains(lo, hi, n->rightMin) || !boxContains(lo, hi, n->rightMax);
    child(n->left, n->leftMin, n->leftMax, index + 1, depth + 1);
    child(n->right, n->rightMin, n->rightMax, b.offset, depth + 1);
  }

  // A reference within a binary leaf of box (lo, hi): a leaf reference, or a split node.
  void leaf(uint ref, vec3 lo, vec3 hi, int depth) {
    if (isGpuBvhLeaf(ref)) {
      const uint first = gpuBvhLeafFirst(ref), count = gpuBvhLeafCount(ref);
      outOfOrder += first != nextTriangle_ || count == 0;
      for (uint i = first; i < first + count && i < bvh_.triangles.size(); ++i) {
        const Triangle& t = bvh_.triangles[i];
        notContained +=
            !boxContains(lo, hi, t.v0) || !boxContains(lo, hi, t.v1) || !boxContains(lo, hi, t.v2);
      }
      nextTriangle_ = std::min(size_t(first) + count, bvh_.triangles.size());
      return;
    }
    const GpuBvhNode* n = interior(ref, depth);
    if (!n) return;
    ++splitNodes;
    const vec3 inf(INFINITY);
    boxesDiffer +=
        n->leftMin != -inf || n->leftMax != inf || n->rightMin != -inf || n->rightMax != inf;
    leaf(n->left, lo, hi, depth + 1);
    leaf(n->right, lo, hi, depth + 1);
  }

  const GpuBvhNode* interior(uint ref, int depth) {
    if (isGpuBvhLeaf(ref) || ref == 0 || ref >= gpu_.nodes.size()) {
      ++badReferences;
      return nullptr;
    }
    ++references_[ref];
    maxDepth = std::max(maxDepth, depth + 1);
    return &gpu_.nodes[ref];
  }

  const Bvh& bvh_;
  const GpuBvh& gpu_;
  std::vector<int> references_;
  size_t nextTriangle_ = 0;
};

void expectValidLayout(const Bvh& bvh, const GpuBvh& gpu) {
  const LayoutCheck c(bvh, gpu);
  EXPECT_EQ(c.boxesDiffer, 0u);
  EXPECT_EQ(c.notContained, 0u);
  EXPECT_EQ(c.badReferences, 0u);
  EXPECT_EQ(c.outOfOrder, 0u);
  EXPECT_EQ(c.missedTriangles, 0u);
  EXPECT_EQ(c.maxDepth, gpu.maxDepth);
  EXPECT_LE(gpu.maxDepth, int(kBvhStackSize));
}

TEST(GpuBvhLayout, HoldsTheBinaryTreeEveryTriangleOnceInBoxesThatContainThem) {
  const std::vector<Triangle> bunny = test::loadBunny();
  for (BvhBuilder builder : {BvhBuilder::kLbvh, BvhBuilder::kBinnedSah, BvhBuilder::kPloc}) {
    SCOPED_TRACE("builder " + std::to_string(int(builder)));
    const Bvh bvh = buildBvh(bunny, BvhBuildOptions{.builder = builder});
    const GpuBvh gpu = buildGpuBvh(bvh);
    expectValidLayout(bvh, gpu);
    // One node per binary interior node, and node 0.
    EXPECT_EQ(gpu.nodes.size(), (bvh.nodes.size() - 1) / 2 + 1);
  }
  // A single leaf: node 0 refers to it directly.
  const Bvh one = buildBvh(test::makeSphere(vec3(0.0f), 1.0f, 2, 2));
  ASSERT_EQ(one.nodes.size(), 1u);
  expectValidLayout(one, buildGpuBvh(one));
}

TEST(GpuBvhLayout, SplitsLeavesTooLargeForAReference) {
  const std::vector<Triangle> sphere = test::makeSphere(vec3(0.0f), 1.0f, 40, 60);
  for (int leafSize : {16, 40, 1000, 10000}) {
    SCOPED_TRACE("leaf size " + std::to_string(leafSize));
    const Bvh bvh = buildBvh(sphere, BvhBuildOptions{.maxLeafSize = leafSize});
    const GpuBvh gpu = buildGpuBvh(bvh);
    const LayoutCheck c(bvh, gpu);
    EXPECT_GT(c.splitNodes, 0u);
    expectValidLayout(bvh, gpu);
  }
}

TEST(GpuBvhLayout, IsDeterministic) {
  const std::vector<Triangle> bunny = test::loadBunny();
  const GpuBvh a = buildGpuBvh(buildBvh(bunny));
  const GpuBvh b = buildGpuBvh(buildBvh(bunny));
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  EXPECT_EQ(std::memcmp(a.nodes.data(), b.nodes.data(), a.nodes.size() * sizeof(GpuBvhNode)), 0);
  EXPECT_EQ(a.maxDepth, b.maxDepth);
}

TEST(GpuBvhLayout, TraversalTexelsHoldTheNodesThenTheTrianglesThenAZeroTexel) {
  const Bvh bvh = buildBvh(test::loadBunny());
  const GpuBvh gpu = buildGpuBvh(bvh);
  const std::vector<uint32_t> words = gpuTraversalTexels(gpu, bvh.triangles);
  const size_t nodeWords = gpu.nodes.size() * 16, triangleWords = bvh.triangles.size() * 12;
  ASSERT_EQ(words.size(), nodeWords + triangleWords + 4);
  std::vector<GpuBvhNode> nodes(gpu.nodes.size());
  std::memcpy(nodes.data(), words.data(), nodeWords * sizeof(uint32_t));
  // Node 0's reserved0: the texel where the triangles start; every other word as built.
  EXPECT_EQ(nodes[0].reserved0, uint32_t(nodeWords / 4));
  nodes[0].reserved0 = gpu.nodes[0].reserved0;
  EXPECT_EQ(std::memcmp(nodes.data(), gpu.nodes.data(), nodeWords * sizeof(uint32_t)), 0);
  EXPECT_EQ(
      std::memcmp(words.data() + nodeWords, bvh.triangles.data(), triangleWords * sizeof(uint32_t)),
      0);
  for (size_t i = nodeWords + triangleWords; i < words.size(); ++i) EXPECT_EQ(words[i], 0u);
}

// A binary tree of `depth` interior nodes in a chain, each with a one-triangle leaf on the
// right, ending in a leaf of `lastLeaf` triangles (boxes: the unit cube).
Bvh chainTree(int depth, uint32_t lastLeaf) {
  Bvh bvh;
  const vec3 lo(0.0f), hi(1.0f);
  for (int i = 0; i < depth; ++i) bvh.nodes.push_back(BvhNode{lo, 0, hi, 0});
  bvh.nodes.push_back(BvhNode{lo, 0, hi, lastLeaf});
  uint32_t triangle = lastLeaf;
  for (int i = depth - 1; i >= 0; --i) {  // right children in depth-first order
    bvh.nodes[size_t(i)].offset = uint32_t(bvh.nodes.size());
    bvh.nodes.push_back(BvhNode{lo, triangle++, hi, 1});
  }
  bvh.triangles.assign(triangle, Triangle{lo, 0, hi, kNoEmitter, vec3(0, 1, 0), 0});
  bvh.maxDepth = depth;
  return bvh;
}

TEST(GpuBvhLayout, SplitLeavesTooDeepForTheStackAreRefused) {
  // 63 levels and a leaf of 40 triangles split twice: 65 interior levels, one too many.
  EXPECT_THROW(buildGpuBvh(chainTree(63, 40)), InputError);
  // Without the split, or with one split less, it fits.
  expectValidLayout(chainTree(64, 4), buildGpuBvh(chainTree(64, 4)));
  expectValidLayout(chainTree(62, 30), buildGpuBvh(chainTree(62, 30)));
}

// A chain of `depth` interior nodes built by hand, on which a ray along +z through (0.2, 0.2)
// pushes an entry at every node but the last: each node's left child, the rest of the chain,
// starts at z = 1 (the bottom leaf, a small triangle the ray misses), nearer than its right
// child, a leaf of one large triangle at z = 2 + level. The closest hit is the first one
// pushed, at the bottom of the stack: the stack must hold depth - 1 entries to find it.
Bvh stackFillingChain(int depth) {
  const auto big = [](float z) {
    return Triangle{vec3(-1, -1, z), 0, vec3(3, -1, z), kNoEmitter, vec3(-1, 3, z), 0};
  };
  Bvh bvh;
  // Triangles in depth-first leaf order: the bottom leaf, then the right leaves upwards.
  bvh.triangles.push_back(
      Triangle{vec3(0.5f, 0.5f, 1), 0, vec3(0.6f, 0.5f, 1), kNoEmitter, vec3(0.5f, 0.6f, 1), 0});
  for (int level = depth - 1; level >= 0; --level) bvh.triangles.push_back(big(2.0f + level));
  for (uint i = 0; i < bvh.triangles.size(); ++i) bvh.triangles[i].primitive = i;
  const auto box = [](const Triangle& t, vec3& lo, vec3& hi) {
    lo = min(t.v0, min(t.v1, t.v2));
    hi = max(t.v0, max(t.v1, t.v2));
  };
  const vec3 chainLo(-1, -1, 1), chainHi(3, 3, 2.0f + float(depth - 1));
  for (int level = 0; level < depth; ++level) bvh.nodes.push_back(BvhNode{chainLo, 0, chainHi, 0});
  BvhNode bottom{vec3(0), 0, vec3(0), 1};
  box(bvh.triangles[0], bottom.boundsMin, bottom.boundsMax);
  bvh.nodes.push_back(bottom);
  for (int level = depth - 1; level >= 0; --level) {
    const uint32_t triangle = uint32_t(depth - level);
    bvh.nodes[size_t(level)].offset = uint32_t(bvh.nodes.size());
    BvhNode leaf{vec3(0), triangle, vec3(0), 1};
    box(bvh.triangles[triangle], leaf.boundsMin, leaf.boundsMax);
    bvh.nodes.push_back(leaf);
  }
  bvh.maxDepth = depth;
  return bvh;
}

TEST(GpuTraversal, TheStackHoldsTheDeepestTraversal) {
  // The shader's stack is sized from the tree (gpuStackRows); every depth up to the largest
  // the layout allows, so that each remainder of the rows of four comes up.
  for (int depth = 1; depth <= int(kBvhStackSize); ++depth) {
    SCOPED_TRACE("depth " + std::to_string(depth));
    const Bvh bvh = stackFillingChain(depth);
    expectValidLayout(bvh, buildGpuBvh(bvh));
    const Ray ray{vec3(0.2f, 0.2f, 0.0f), vec3(0, 0, 1)};
    const std::optional<Hit> cpu = closestHit(bvh, ray);
    ASSERT_TRUE(cpu.has_value());
    ASSERT_EQ(cpu->t, 2.0f);
    const std::vector<RayResult> gpu =
        traceChecked(bvh, {RayQuery{ray.origin, INFINITY, ray.direction, 0u}});
    EXPECT_EQ(gpu[0].found, 1u);
    EXPECT_EQ(gpu[0].t, 2.0f);
    EXPECT_EQ(gpu[0].triangle, cpu->triangle);
  }
}

TEST(GpuTraversal, WatertightAtSharedEdgesAndVertices) {
  // The CPU test's 1.26 million rays, on the device.
  const vec3 center(0.3f, -0.2f, 0.1f);
  const Bvh bvh = buildBvh(test::makeSphere(center, 1.0f, 200, 350));
  const vec3 origins[] = {center, center + vec3(0.2f, 0.1f, -0.3f),
                          center + vec3(-0.61f, 0.33f, 0.05f)};
  std::vector<RayQuery> queries;
  for (const vec3& o : origins) {
    for (const Triangle& t : bvh.triangles) {
      for (vec3 target : {t.v0, 0.5f * (t.v0 + t.v1), 0.5f * (t.v1 + t.v2)}) {
        queries.push_back(RayQuery{o, INFINITY, target - o, 0u});
      }
    }
  }
  ASSERT_GE(queries.size(), 1000000u);
  const std::vector<RayResult> results = traceChecked(bvh, queries);
  size_t leaks = 0;
  for (const RayResult& r : results) leaks += r.found == 0u;
  EXPECT_EQ(leaks, 0u);
}

TEST(GpuTraversal, WatertightOnAClosedScannedMesh) {
  // The CPU test's rays into the closed bunny, on the device.
  const Bvh bvh = buildBvh(test::loadBunny());
  const std::vector<RayQuery> queries =
      test::aimedRays(bvh.triangles, test::interiorPoints(bvh, 8, 6));
  ASSERT_GE(queries.size(), 1000000u);
  const std::vector<RayResult> results = traceChecked(bvh, queries);
  const float outward = test::outwardSign(bvh.triangles);
  size_t leaks = 0;
  for (size_t i = 0; i < queries.size(); ++i) {
    const RayResult& r = results[i];
    leaks += test::escaped(bvh.triangles, outward, queries[i], r.found != 0u, r.t, r.triangle);
  }
  EXPECT_EQ(leaks, 0u);
}

TEST(GpuTraversal, ClosestAndAnyHitMatchTheCpuOnTheBunny) {
  const Bvh bvh = buildBvh(test::loadBunny());
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> uni(-1.5f, 1.5f);
  std::vector<RayQuery> queries;
  for (int i = 0; i < 100000; ++i) {
    const vec3 o(uni(rng), uni(rng), uni(rng));
    const Triangle& t = bvh.triangles[size_t(i * 7919) % bvh.triangles.size()];
    const vec3 d = i % 2 ? normalize((t.v0 + t.v1 + t.v2) / 3.0f - o)
                         : normalize(vec3(uni(rng), uni(rng), uni(rng)));
    const bool shadow = i % 3 == 0;
    queries.push_back(RayQuery{o, shadow ? std::abs(uni(rng)) : INFINITY, d, shadow ? 1u : 0u});
  }
  const std::vector<RayResult> gpu = traceChecked(bvh, queries);
  size_t differ = 0, hits = 0;
  for (size_t i = 0; i < queries.size(); ++i) {
    const RayQuery& q = queries[i];
    const Ray ray{q.origin, q.direction};
    if (q.anyHit) {
      differ += anyHit(bvh, ray, q.tMax) != (gpu[i].found != 0u);
      continue;
    }
    const auto cpu = closestHit(bvh, ray, q.tMax);
    hits += cpu.has_value();
    // Same arithmetic in both (no fused multiply-adds): the same distance, bit for bit, and
    // the same triangle.
    if (cpu.has_value() != (gpu[i].found != 0u) ||
        (cpu && (cpu->t != gpu[i].t || cpu->triangle != gpu[i].triangle))) {
      ++differ;
    }
  }
  EXPECT_EQ(differ, 0u);
  EXPECT_GT(hits, 20000u);
}

// Rays through the bunny's shared vertices and edges, from inside: there, two or more
// triangles are often hit at the same distance, and the one reported is the first the
// traversal accepts, so the GPU must visit the leaves, and test the triangles, in the binary
// traversal's order to report the CPU's triangle.
// Rays through the bunny's shared vertices and edges, where two triangles often report the
// same distance: the GPU reports the triangle the CPU does (the closest-hit rule, isCloserHit
// in sampling.h, does not depend on the tree), here with each backend's own tree, as a render
// builds them: the CPU's wide tree over PLOC with leaves of 8, the GPU's LBVH with leaves of 3.
TEST(GpuTraversal, TiesGoToTheTriangleTheCpuReports) {
  const std::vector<Triangle> bunny = test::loadBunny();
  const Bvh bvh = buildBvh(bunny, BvhBuildOptions{3, BvhBuilder::kLbvh});
  const Bvh cpuBvh = buildBvh(bunny, BvhBuildOptions{8, BvhBuilder::kPloc});
  const WideBvh cpuWide = buildWideBvh(cpuBvh);
  const std::vector<RayQuery> queries =
      test::aimedRays(bvh.triangles, test::interiorPoints(bvh, 4, 2));
  ASSERT_GE(queries.size(), 100000u);
  const std::vector<RayResult> gpu = traceChecked(bvh, queries);
  size_t differ = 0;
  for (size_t i = 0; i < queries.size(); ++i) {
    const auto cpu = closestHit(cpuWide, Ray{queries[i].origin, queries[i].direction});
    differ += cpu.has_value() != (gpu[i].found != 0u) ||
              (cpu && (cpu->t != gpu[i].t || cpuBvh.triangles[cpu->triangle].primitive !=
                                                 bvh.triangles[gpu[i].triangle].primitive));
  }
  EXPECT_EQ(differ, 0u);
  // The rays do tie: every 100th one against every triangle.
  size_t ties = 0;
  for (size_t i = 0; i < queries.size(); i += 100) {
    const RayPrecomputed ray(Ray{queries[i].origin, queries[i].direction});
    float closest = INFINITY;
    int atClosest = 0;
    for (const Triangle& t : bvh.triangles) {
      Hit hit;
      if (!intersectTriangle(ray, t, INFINITY, hit)) continue;
      atClosest = hit.t < closest ? 1 : atClosest + (hit.t == closest);
      closest = std::min(closest, hit.t);
    }
    ties += atClosest > 1;
  }
  EXPECT_GT(ties, 100u);
}

// Leaves of up to 40 triangles, split for the layout's references (kGpuBvhMaxLeafCount):
// the same answers as the CPU on the binary tree.
TEST(GpuTraversal, SplitLeavesGiveTheCpusAnswers) {
  const Bvh bvh = buildBvh(test::loadBunny(), BvhBuildOptions{.maxLeafSize = 40});
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> uni(-1.5f, 1.5f);
  std::vector<RayQuery> queries;
  for (int i = 0; i < 20000; ++i) {
    const vec3 o(uni(rng), uni(rng), uni(rng));
    const Triangle& t = bvh.triangles[size_t(i * 7919) % bvh.triangles.size()];
    const bool shadow = i % 3 == 0;
    queries.push_back(RayQuery{o, shadow ? std::abs(uni(rng)) : INFINITY,
                               normalize((t.v0 + t.v1 + t.v2) / 3.0f - o), shadow ? 1u : 0u});
  }
  const std::vector<RayResult> gpu = traceChecked(bvh, queries);
  size_t differ = 0;
  for (size_t i = 0; i < queries.size(); ++i) {
    const RayQuery& q = queries[i];
    const Ray ray{q.origin, q.direction};
    if (q.anyHit) {
      differ += anyHit(bvh, ray, q.tMax) != (gpu[i].found != 0u);
      continue;
    }
    const auto cpu = closestHit(bvh, ray, q.tMax);
    differ += cpu.has_value() != (gpu[i].found != 0u) ||
              (cpu && (cpu->t != gpu[i].t || cpu->triangle != gpu[i].triangle));
  }
  EXPECT_EQ(differ, 0u);
}

TEST(GpuTraversal, AxisParallelRaysInBoxFacePlanes) {
  // Rays with exactly zero direction components, starting in the planes of box faces.
  const Bvh bvh = buildBvh(test::makeSphere(vec3(0.5f), 0.5f, 8, 12));
  const BvhNode& root = bvh.nodes[0];
  std::vector<RayQuery> queries;
  for (vec3 d : {vec3(1, 0, 0), vec3(-1, 0, 0), vec3(0, 1, 0), vec3(0, -1, 0), vec3(0, 0, 1),
                 vec3(0, 0, -1)}) {
    queries.push_back(RayQuery{vec3(0.5f), INFINITY, d, 0u});  // from the centre
  }
  queries.push_back(RayQuery{vec3(root.boundsMin.x, -1.0f, 0.5f), INFINITY, vec3(0, 1, 0), 0u});
  queries.push_back(RayQuery{vec3(0.5f, root.boundsMax.y, -1.0f), INFINITY, vec3(0, 0, 1), 0u});
  const std::vector<RayResult> gpu = traceRaysVulkan(bvh, queries, kValidated);
  for (size_t i = 0; i < queries.size(); ++i) {
    const auto cpu = closestHit(bvh, Ray{queries[i].origin, queries[i].direction});
    EXPECT_EQ(cpu.has_value(), gpu[i].found != 0u) << "ray " << i;
    if (cpu) EXPECT_EQ(cpu->t, gpu[i].t) << "ray " << i;
  }
  for (size_t i = 0; i < 6; ++i) EXPECT_EQ(gpu[i].found, 1u) << "ray " << i;
}

}  // namespace
}  // namespace pt
