// Ray queries on the flat BVH: watertight ray/triangle intersection (Woop, Benthin and Wald
// 2013), a slab test that stays correct for axis-parallel rays (Ize 2013 for the rounding of
// the far distance), and iterative stack-based traversal, near child first, with a
// closest-hit and an any-hit (shadow ray) mode. The shader implements the same algorithms
// in GLSL; this is the CPU reference's own copy.
#pragma once

#include <cstdint>
#include <optional>

#include "bvh/bvh.h"

namespace pt {

struct Ray {
  vec3 origin;
  vec3 direction;  // need not be unit length; t is measured in units of |direction|
};

// Per-ray constants of the watertight test and the slab test, computed once per ray.
struct RayPrecomputed {
  vec3 origin;
  vec3 direction;
  vec3 invDirection;  // 1 / direction, with |direction| clamped away from 0 (no inf, no NaN)
  int kx, ky, kz;     // kz: axis of the largest |direction|; (kx, ky) keep the winding
  float sx, sy, sz;   // shear constants
  explicit RayPrecomputed(const Ray& ray);
  RayPrecomputed() = default;  // for callers that set several up at once (integrator_lanes)
};

struct Hit {
  float t = 0.0f;
  vec3 barycentrics{0.0f};  // weights of v0, v1, v2
  uint triangle = 0;        // index into Bvh::triangles
  uint primitive = 0;       // that triangle's Triangle::primitive (its place in scene order)
};

// Decides, for a query, whether a hit on Bvh::triangles[triangle] counts: false drops it, as if
// the ray had passed that triangle (alpha cut-outs: any-hit semantics within the traversal,
// for closest-hit and any-hit queries alike). Called only for hits that would be taken.
struct HitFilter {
  bool (*accept)(const void* context, uint32_t triangle, const Hit& hit);
  const void* context;
};

// A query's state as its triangle tests update it, for the CPU traversals: the closest hit
// by the rule every traversal follows (isCloserHit in sampling.h: the answer does not depend
// on the tree or the visiting order), and the range that boxes and triangles are tested
// against (searchRange).
struct HitSearch {
  float tMax;   // the query's range, exact
  float range;  // what boxes and triangles are tested against
  Hit best;     // the closest hit so far (t = tMax and primitive kNoPrimitive before the first)
  bool found = false;
  const HitFilter* filter = nullptr;  // none: every hit counts
  explicit HitSearch(float queryTMax, const HitFilter* hitFilter = nullptr)
      : tMax(queryTMax), range(queryTMax), filter(hitFilter) {
    best.t = queryTMax;
    best.primitive = kNoPrimitive;
  }
  // Offers a hit on Bvh::triangles[index], whose Triangle::primitive is `primitive`; takes it
  // and returns true if isCloserHit prefers it to the closest so far.
  bool offer(const Hit& hit, uint32_t index, uint32_t primitive) {
    if (!isCloserHit(hit.t, primitive, best.t, best.primitive)) return false;
    if (filter != nullptr && !filter->accept(filter->context, index, hit)) return false;
    best = hit;
    best.triangle = index;
    best.primitive = primitive;
    range = searchRange(best.t, tMax);
    found = true;
    return true;
  }
};

// Watertight intersection; accepts hits from both sides with 0 < t < tMax.
bool intersectTriangle(const RayPrecomputed& ray, const Triangle& tri, float tMax, Hit& hit);

// Moller and Trumbore (1997): fewer operations, not watertight (rays through shared edges
// and vertices can pass between triangles). Only for measuring what watertightness costs.
bool intersectTriangleFast(const RayPrecomputed& ray, const Triangle& tri, float tMax, Hit& hit);

enum class Intersection { kWatertight, kFast };

// Slab test; on a hit, tNear is the entry distance (clamped to 0).
bool intersectBox(const RayPrecomputed& ray, vec3 lo, vec3 hi, float tMax, float& tNear);

std::optional<Hit> closestHit(const Bvh& bvh, const Ray& ray, float tMax = INFINITY,
                              Intersection test = Intersection::kWatertight,
                              const HitFilter* filter = nullptr);

// True if anything lies on the ray with 0 < t < tMax. Stops at the first hit found.
bool anyHit(const Bvh& bvh, const Ray& ray, float tMax,
            Intersection test = Intersection::kWatertight, const HitFilter* filter = nullptr);

}  // namespace pt
