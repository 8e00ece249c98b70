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

namespace pt::test {

// Rays per brute-force comparison: 100k in the normal build. The sanitizer build, which
// looks for memory errors and undefined behaviour rather than wrong answers, and runs the
// brute force about 20x slower, checks the first 20k of the same rays.
#if defined(__SANITIZE_ADDRESS__)
inline constexpr int kBruteForceRays = 20000;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr int kBruteForceRays = 20000;
#else
inline constexpr int kBruteForceRays = 100000;
#endif
#else
inline constexpr int kBruteForceRays = 100000;
#endif

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

// The closest hit of every ray, every triangle considered (the watertight test), chosen by
// the traversals' rule (isCloserHit: the smallest t, then the smallest Triangle::primitive),
// on all cores. A conservative bounding-sphere test skips the exact test where it cannot hit.
inline std::vector<BruteHit> bruteForceClosestHits(const std::vector<Triangle>& mesh,
                                                   const std::vector<Ray>& rays) {
  std::vector<vec4> spheres;  // centre, squared radius
  for (const Triangle& t : mesh) {
    const vec3 c = (t.v0 + t.v1 + t.v2) / 3.0f;
    const float r2 =
        std::max({dot(t.v0 - c, t.v0 - c), dot(t.v1 - c, t.v1 - c), dot(t.v2 - c, t.v2 - c)});
    spheres.emplace_back(c, r2 * 1.001f + 1e-12f);
  }
  auto closest = [&](const Ray& ray) {
    const RayPrecomputed r(ray);
    BruteHit best;
    const float invLength2 = 1.0f / dot(ray.direction, ray.direction);  // any length
    for (size_t k = 0; k < mesh.size(); ++k) {
      const vec3 v = vec3(spheres[k]) - ray.origin;
      const float vv = dot(v, v), tc = dot(v, ray.direction);
      // Squared distance of the centre from the ray's line, with slack for rounding.
      if (vv - tc * tc * invLength2 > spheres[k].w + 1e-5f * vv) continue;
      Hit h;
      if (!intersectTriangle(r, mesh[k], INFINITY, h)) continue;
      const bool tie = best.found && h.t == best.t;
      if (isCloserHit(h.t, mesh[k].primitive, best.t, best.found ? best.primitive : kNoPrimitive)) {
        best.found = true;
        best.t = h.t;
        best.primitive = mesh[k].primitive;
        best.barycentrics = h.barycentrics;
        if (!tie) best.atClosest = 0;
      }
      if (best.t == h.t) ++best.atClosest;
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
