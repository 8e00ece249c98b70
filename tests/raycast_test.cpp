// The shader's BVH traversal (through shaders/raycast.comp) against the CPU traversal:
// watertightness at shared edges and vertices, closest and any hit on the bunny, and
// axis-parallel rays, all with the validation layers on.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "bvh/traverse.h"
#include "closed_mesh.h"
#include "render_compare.h"
#include "scene/scene.h"
#include "test_util.h"
#include "vulkan/raycast.h"

namespace pt {
namespace {

const ContextOptions kValidated{.validation = validationWanted()};

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
  RaycastStats stats;
  const std::vector<RayResult> results = traceRaysVulkan(bvh, queries, kValidated, &stats);
  EXPECT_EQ(stats.validationErrors, 0u);
  EXPECT_EQ(stats.truncated, 0u);
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
  RaycastStats stats;
  const std::vector<RayResult> results = traceRaysVulkan(bvh, queries, kValidated, &stats);
  EXPECT_EQ(stats.validationErrors, 0u);
  EXPECT_EQ(stats.truncated, 0u);
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
  RaycastStats stats;
  const std::vector<RayResult> gpu = traceRaysVulkan(bvh, queries, kValidated, &stats);
  EXPECT_EQ(stats.validationErrors, 0u);
  EXPECT_EQ(stats.truncated, 0u);
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
    // Same arithmetic in both (no fused multiply-adds): the same distance, bit for bit.
    if (cpu.has_value() != (gpu[i].found != 0u) || (cpu && cpu->t != gpu[i].t)) ++differ;
  }
  EXPECT_EQ(differ, 0u);
  EXPECT_GT(hits, 20000u);
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
