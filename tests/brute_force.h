// The brute-force reference of the traversal tests (bvh_test.cpp, wide_bvh_test.cpp): random
// rays around a mesh, and their closest hits found by testing every triangle.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <thread>
#include <vector>

#include "bvh/traverse.h"
#include "common/shared.h"
#include "sanitizer_build.h"

namespace pt::test {

// Rays per brute-force comparison: 100k in the normal build; the sanitizer build, which looks
// for memory errors and undefined behaviour rather than wrong answers and runs the traversals
// about 20x slower, checks the first 20k of the same rays.
inline constexpr int kBruteForceRays = kSanitizerBuild ? 20000 : 100000;
// The watertightness probes (a million rays aimed at vertices and edges) take every ray in the
// normal build and every fifth in the sanitizer build, their thresholds scaled alike.
inline constexpr size_t kProbeStride = kSanitizerBuild ? 5 : 1;

struct BruteHit {
  bool found = false;
  float t = INFINITY;
  uint primitive = 0;
  vec3 barycentrics{0.0f};
  int atClosest = 0;  // triangles the ray meets at distance t (2 or more: a tie)
};

struct RandomRays {
  std::vector<Ray> rays;
  // Per ray, a number in [0, 2): an any-hit range as a fraction of the closest distance,
  // which may or may not contain the closest hit.
  std::vector<float> shadowFraction;
};

// Origins in [-2, 2]^3 around the mesh; even rays aimed at a random point of a random
// triangle (most hit), odd rays in random directions (many miss).
inline RandomRays raysAroundMesh(const std::vector<Triangle>& mesh, int count, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  RandomRays set;
  set.rays.resize(size_t(count));
  set.shadowFraction.resize(size_t(count));
  for (int i = 0; i < count; ++i) {
    const vec3 o(uni(rng) * 4 - 2, uni(rng) * 4 - 2, uni(rng) * 4 - 2);
    vec3 d;
    if (i % 2 == 0) {
      const Triangle& t = mesh[size_t(uni(rng) * float(mesh.size())) % mesh.size()];
      const vec2 b = sampleTriangleBarycentrics(vec2(uni(rng), uni(rng)));
      d = normalize((1 - b.x - b.y) * t.v0 + b.x * t.v1 + b.y * t.v2 - o);
    } else {
      d = normalize(vec3(uni(rng) - 0.5f, uni(rng) - 0.5f, uni(rng) - 0.5f));
    }
    set.rays[size_t(i)] = Ray{o, d};
    set.shadowFraction[size_t(i)] = uni(rng) * 2.0f;
  }
  return set;
}

// A bounding sphere (centre, squared radius) that holds points, widened for rounding.
inline vec4 boundingSphere(const vec3* points, size_t count) {
  vec3 c(0.0f);
  for (size_t i = 0; i < count; ++i) c += points[i];
  c /= float(count);
  float r2 = 0.0f;
  for (size_t i = 0; i < count; ++i) r2 = std::max(r2, dot(points[i] - c, points[i] - c));
  return vec4(c, r2 * 1.001f + 1e-12f);
}

// Whether the ray's line passes within a sphere, with slack for rounding: false only where
// no point of the sphere is on it.
inline bool lineMeetsSphere(const Ray& ray, float invLength2, vec4 sphere) {
  const vec3 v = vec3(sphere) - ray.origin;
  const float vv = dot(v, v), tc = dot(v, ray.direction);
  // The squared distance of the centre from the line.
  return !(vv - tc * tc * invLength2 > sphere.w + 1e-5f * vv);
}

// The closest hit of every ray, every triangle considered (the watertight test), chosen by
// the traversals' rule (isCloserHit: the smallest t, then the smallest Triangle::primitive),
// on all cores (in any order of the triangles: the rule picks one hit of a tie whatever the
// order). Conservative bounding-sphere tests (of blocks of nearby triangles, then of each) skip the
// exact test where it cannot hit: no tree is built, so the reference shares nothing with the
// hierarchies it checks.
inline std::vector<BruteHit> bruteForceClosestHits(const std::vector<Triangle>& mesh,
                                                   const std::vector<Ray>& rays) {
  // Triangles in the order of their centroids along a Z-order curve (so that a block is
  // small), then blocked.
  constexpr size_t kBlock = 32;
  vec3 lo(INFINITY), hi(-INFINITY);
  for (const Triangle& t : mesh) {
    const vec3 c = (t.v0 + t.v1 + t.v2) / 3.0f;
    lo = min(lo, c);
    hi = max(hi, c);
  }
  auto zOrder = [&](const Triangle& t) {
    const vec3 c = ((t.v0 + t.v1 + t.v2) / 3.0f - lo) / max(hi - lo, vec3(1e-30f));
    uint64_t code = 0;
    for (int axis = 0; axis < 3; ++axis) {
      const auto q = uint64_t(std::clamp(c[axis], 0.0f, 1.0f) * 1023.0f);
      for (int bit = 0; bit < 10; ++bit) code |= ((q >> bit) & 1u) << (3 * bit + axis);
    }
    return code;
  };
  std::vector<std::pair<uint64_t, size_t>> keyed;
  for (size_t k = 0; k < mesh.size(); ++k) keyed.emplace_back(zOrder(mesh[k]), k);
  std::sort(keyed.begin(), keyed.end());
  std::vector<Triangle> sorted;
  for (const auto& [code, k] : keyed) sorted.push_back(mesh[k]);
  std::vector<vec4> spheres, blockSpheres;
  std::vector<vec3> blockPoints;
  for (size_t k = 0; k < sorted.size(); ++k) {
    const Triangle& t = sorted[k];
    const vec3 points[3] = {t.v0, t.v1, t.v2};
    spheres.push_back(boundingSphere(points, 3));
    blockPoints.insert(blockPoints.end(), points, points + 3);
    if (blockPoints.size() == 3 * kBlock || k + 1 == sorted.size()) {
      blockSpheres.push_back(boundingSphere(blockPoints.data(), blockPoints.size()));
      blockPoints.clear();
    }
  }
  auto closest = [&](const Ray& ray) {
    const RayPrecomputed r(ray);
    BruteHit best;
    const float invLength2 = 1.0f / dot(ray.direction, ray.direction);  // any length
    for (size_t block = 0; block < blockSpheres.size(); ++block) {
      if (!lineMeetsSphere(ray, invLength2, blockSpheres[block])) continue;
      const size_t end = std::min(sorted.size(), (block + 1) * kBlock);
      for (size_t k = block * kBlock; k < end; ++k) {
        if (!lineMeetsSphere(ray, invLength2, spheres[k])) continue;
        Hit h;
        if (!intersectTriangle(r, sorted[k], INFINITY, h)) continue;
        const bool tie = best.found && h.t == best.t;
        if (isCloserHit(h.t, sorted[k].primitive, best.t,
                        best.found ? best.primitive : kNoPrimitive)) {
          best.found = true;
          best.t = h.t;
          best.primitive = sorted[k].primitive;
          best.barycentrics = h.barycentrics;
          if (!tie) best.atClosest = 0;
        }
        if (best.t == h.t) ++best.atClosest;
      }
    }
    return best;
  };
  std::vector<BruteHit> hits(rays.size());
  const size_t n = std::max(1u, std::thread::hardware_concurrency());
  std::vector<std::thread> pool;
  for (size_t w = 0; w < n; ++w) {
    pool.emplace_back([&, w] {
      for (size_t i = w; i < rays.size(); i += n) hits[i] = closest(rays[i]);
    });
  }
  for (std::thread& th : pool) th.join();
  return hits;
}

}  // namespace pt::test
