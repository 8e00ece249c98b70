// CPU traversal of the flat BVH; see traverse.h.
#include "bvh/traverse.h"

#include <cmath>
#include <utility>

namespace pt {
namespace {

// kMinDirection and kFarScale come from shaders/sampling.h, shared with the shader.

float safeInverse(float d) {
  return 1.0f / (std::fabs(d) < kMinDirection ? std::copysign(kMinDirection, d) : d);
}

}  // namespace

RayPrecomputed::RayPrecomputed(const Ray& ray) : origin(ray.origin), direction(ray.direction) {
  const vec3 d = ray.direction;
  invDirection = vec3(safeInverse(d.x), safeInverse(d.y), safeInverse(d.z));
  // Woop et al. 2013: make the largest axis z, and swap x and y when it points down z so
  // that the triangle's winding, and so the sign of the edge functions, is kept.
  const vec3 a = abs(d);
  kz = a.x > a.y ? (a.x > a.z ? 0 : 2) : (a.y > a.z ? 1 : 2);
  kx = (kz + 1) % 3;
  ky = (kx + 1) % 3;
  if (d[kz] < 0.0f) std::swap(kx, ky);
  sx = d[kx] / d[kz];
  sy = d[ky] / d[kz];
  sz = 1.0f / d[kz];
}

bool intersectTriangle(const RayPrecomputed& ray, const Triangle& tri, float tMax, Hit& hit) {
  // Vertices relative to the origin, sheared so the ray becomes the +z axis.
  const vec3 a = tri.v0 - ray.origin;
  const vec3 b = tri.v1 - ray.origin;
  const vec3 c = tri.v2 - ray.origin;
  const float ax = a[ray.kx] - ray.sx * a[ray.kz];
  const float ay = a[ray.ky] - ray.sy * a[ray.kz];
  const float bx = b[ray.kx] - ray.sx * b[ray.kz];
  const float by = b[ray.ky] - ray.sy * b[ray.kz];
  const float cx = c[ray.kx] - ray.sx * c[ray.kz];
  const float cy = c[ray.ky] - ray.sy * c[ray.kz];
  // Scaled barycentrics: 2D edge functions of the projected edges against the origin.
  float u = cx * by - cy * bx;
  float v = ax * cy - ay * cx;
  float w = bx * ay - by * ax;
  // An edge function of exactly zero may be a rounding artefact; the paper recomputes it in
  // double precision so that neighbouring triangles agree on which side the ray passes.
  if (u == 0.0f || v == 0.0f || w == 0.0f) {
    u = float(double(cx) * double(by) - double(cy) * double(bx));
    v = float(double(ax) * double(cy) - double(ay) * double(cx));
    w = float(double(bx) * double(ay) - double(by) * double(ax));
  }
  // Both faces are hit: reject only when the signs are mixed.
  if ((u < 0.0f || v < 0.0f || w < 0.0f) && (u > 0.0f || v > 0.0f || w > 0.0f)) return false;
  const float det = u + v + w;
  if (det == 0.0f) return false;
  // Scaled hit distance; compare against the range scaled by det to avoid a division.
  const float az = ray.sz * a[ray.kz];
  const float bz = ray.sz * b[ray.kz];
  const float cz = ray.sz * c[ray.kz];
  const float t = u * az + v * bz + w * cz;
  if (det > 0.0f ? (t <= 0.0f || t >= tMax * det) : (t >= 0.0f || t <= tMax * det)) return false;
  const float invDet = 1.0f / det;
  hit.t = t * invDet;
  hit.barycentrics = vec3(u, v, w) * invDet;
  return true;
}

bool intersectTriangleFast(const RayPrecomputed& ray, const Triangle& tri, float tMax, Hit& hit) {
  const vec3 e1 = tri.v1 - tri.v0;
  const vec3 e2 = tri.v2 - tri.v0;
  const vec3 p = cross(ray.direction, e2);
  const float det = dot(e1, p);
  if (det == 0.0f) return false;
  const float invDet = 1.0f / det;
  const vec3 s = ray.origin - tri.v0;
  const float u = dot(s, p) * invDet;
  if (u < 0.0f || u > 1.0f) return false;
  const vec3 q = cross(s, e1);
  const float v = dot(ray.direction, q) * invDet;
  if (v < 0.0f || u + v > 1.0f) return false;
  const float t = dot(e2, q) * invDet;
  if (t <= 0.0f || t >= tMax) return false;
  hit.t = t;
  hit.barycentrics = vec3(1.0f - u - v, u, v);
  return true;
}

bool intersectBox(const RayPrecomputed& ray, vec3 lo, vec3 hi, float tMax, float& tNear) {
  const vec3 t0 = (lo - ray.origin) * ray.invDirection;
  const vec3 t1 = (hi - ray.origin) * ray.invDirection;
  const vec3 tMin = min(t0, t1);
  const vec3 tMaxV = max(t0, t1);
  const float enter = std::max(std::max(tMin.x, tMin.y), std::max(tMin.z, 0.0f));
  const float exit = std::min(std::min(tMaxV.x, tMaxV.y), std::min(tMaxV.z, tMax)) * kFarScale;
  tNear = enter;
  return enter <= exit;
}

namespace {

// One loop for both query kinds. Near child first: both children's boxes are tested, the
// nearer is visited next and the farther pushed. A popped node is visited without
// re-testing its box (it was hit when pushed).
template <bool kAnyHit, bool kWatertight>
bool traverse(const Bvh& bvh, const Ray& ray, float tMax, const HitFilter* filter, Hit& best) {
  const RayPrecomputed r(ray);
  float tNear = 0.0f;
  const BvhNode& root = bvh.nodes[0];
  if (!intersectBox(r, root.boundsMin, root.boundsMax, tMax, tNear)) return false;
  uint32_t stack[kBvhStackSize];
  uint32_t stackSize = 0;
  uint32_t nodeIndex = 0;
  HitSearch search(tMax, filter);
  for (;;) {
    const BvhNode& node = bvh.nodes[nodeIndex];
    if (node.count > 0) {
      // Leaf: test its triangles, taking each hit that isCloserHit prefers.
      for (uint32_t i = node.offset; i < node.offset + node.count; ++i) {
        const Triangle& tri = bvh.triangles[i];
        Hit hit;
        const bool hitTriangle = kWatertight ? intersectTriangle(r, tri, search.range, hit)
                                             : intersectTriangleFast(r, tri, search.range, hit);
        if (hitTriangle && search.offer(hit, i, tri.primitive) && kAnyHit) {
          best = search.best;
          return true;
        }
      }
    } else {
      // Interior: visit the nearer child that the ray enters, push the other.
      const uint32_t left = nodeIndex + 1;
      const uint32_t right = node.offset;
      float tLeft = 0.0f, tRight = 0.0f;
      const bool hitLeft = intersectBox(r, bvh.nodes[left].boundsMin, bvh.nodes[left].boundsMax,
                                        search.range, tLeft);
      const bool hitRight = intersectBox(r, bvh.nodes[right].boundsMin, bvh.nodes[right].boundsMax,
                                         search.range, tRight);
      if (hitLeft && hitRight) {
        const bool leftFirst = tLeft <= tRight;
        stack[stackSize++] = leftFirst ? right : left;
        nodeIndex = leftFirst ? left : right;
        continue;
      }
      if (hitLeft || hitRight) {
        nodeIndex = hitLeft ? left : right;
        continue;
      }
    }
    if (stackSize == 0) break;
    nodeIndex = stack[--stackSize];
  }
  best = search.best;
  return search.found;
}

}  // namespace

std::optional<Hit> closestHit(const Bvh& bvh, const Ray& ray, float tMax, Intersection test,
                              const HitFilter* filter) {
  Hit hit;
  const bool found = test == Intersection::kWatertight
                         ? traverse</*kAnyHit=*/false, true>(bvh, ray, tMax, filter, hit)
                         : traverse</*kAnyHit=*/false, false>(bvh, ray, tMax, filter, hit);
  if (found) return hit;
  return std::nullopt;
}

bool anyHit(const Bvh& bvh, const Ray& ray, float tMax, Intersection test,
            const HitFilter* filter) {
  Hit hit;
  return test == Intersection::kWatertight
             ? traverse</*kAnyHit=*/true, true>(bvh, ray, tMax, filter, hit)
             : traverse</*kAnyHit=*/true, false>(bvh, ray, tMax, filter, hit);
}

}  // namespace pt
