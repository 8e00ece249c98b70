// pbrt-v4's light BVH (its BVHLightSampler, after Conty Estevez and Kulla 2018), written once
// for the CPU and the shader: the importance of a node's lights for a shading point, and the
// choice between a node's two children. The tree (struct LightBvhNode, shared_types.h) is
// built on the host (render/light_bvh.h); path_vertex.h walks it: down from the root to choose
// an emitter for a light sample, and from an emitter's leaf up to the root for the
// probability that light sampling had chosen the emitter a ray found (MIS).
//
// Where we differ from pbrt-v4: its nodes store their bounds quantized to 16 bits and their
// cosines to 15 (a slightly wider cone and box); ours are floats. A point at the exact centre
// of a node's bounds takes the node's axis as its direction to the lights, where pbrt-v4's
// normalization of a zero vector gives NaN; a point on the sphere about the bounds counts as
// inside it (pbrt-v4: outside, at a right angle).
#ifndef PT_LIGHT_BVH_H
#define PT_LIGHT_BVH_H

#include "shared_types.h"

#ifdef __cplusplus
namespace pt {
#endif

// cos(a - b) of angles a, b in [0, pi] given by their sines and cosines, 1 where a < b.
PT_INLINE float cosSubClamped(float sinA, float cosA, float sinB, float cosB) {
  return cosA > cosB ? 1.0f : cosA * cosB + sinA * sinB;
}
// sin(a - b) likewise, 0 where a < b.
PT_INLINE float sinSubClamped(float sinA, float cosA, float sinB, float cosB) {
  return cosA > cosB ? 0.0f : sinA * cosB - cosA * sinB;
}

// How much the lights bounded by `node` may light point p, whose surface has normal n (a zero
// vector at a point of a medium): pbrt-v4's LightBounds::Importance. The power phi over the
// squared distance to the bounds' centre (not less than half the bounds' diagonal, as
// pbrt-v4 clamps it), times a bound on the cosine at the lights (the angle between their
// cone of normals and the direction to p, less the angle the bounds subtend from p) and at
// p's surface; zero where every light faces away beyond its emission angle theta_e.
PT_INLINE float lightBoundsImportance(PT_IN(LightBvhNode) node, vec3 p, vec3 n) {
  vec3 fromCentre = p - node.centre;
  float d2 = dot(fromCentre, fromCentre);
  float invD = 1.0f / sqrt(d2);
  vec3 wi = d2 > 0.0f ? fromCentre * invD : node.w;
  float halfDiagonal = node.radius;
  // pbrt-v4's BoundSubtendedDirections: the cone of directions from p to the bounds' sphere
  // (all directions from inside it), its sine the sphere's radius over the distance.
  float sinThetaB = 0.0f;
  float cosThetaB = -1.0f;
  if (d2 > halfDiagonal * halfDiagonal) {
    sinThetaB = min(halfDiagonal * invD, 1.0f);
    cosThetaB = sqrt(max(0.0f, 1.0f - sinThetaB * sinThetaB));
  }
  d2 = max(d2, halfDiagonal);
  float cosThetaW = dot(node.w, wi);
  if ((node.flags & kLightBvhTwoSided) != 0u) cosThetaW = abs(cosThetaW);
  float sinThetaW = sqrt(max(0.0f, 1.0f - cosThetaW * cosThetaW));
  // The angle between the cone of normals and wi, less the cone's spread, less theta_b.
  float cosThetaX = cosSubClamped(sinThetaW, cosThetaW, node.sinThetaO, node.cosThetaO);
  float sinThetaX = sinSubClamped(sinThetaW, cosThetaW, node.sinThetaO, node.cosThetaO);
  float cosThetaP = cosSubClamped(sinThetaX, cosThetaX, sinThetaB, cosThetaB);
  if (cosThetaP <= node.cosThetaE) return 0.0f;
  float importance = node.phi * cosThetaP / d2;
  if (n != vec3(0.0f)) {
    float cosThetaI = abs(dot(wi, n));
    float sinThetaI = sqrt(max(0.0f, 1.0f - cosThetaI * cosThetaI));
    importance *= cosSubClamped(sinThetaI, cosThetaI, sinThetaB, cosThetaB);
  }
  return max(importance, 0.0f);
}

// One step down the tree: child 1 with probability c1 / (c0 + c1), else child 0 (pbrt-v4's
// SampleDiscrete over two weights, not both zero), from u in [0, 1), which is rescaled to
// [0, 1) within the chosen child's share for the next step. The child's probability in pmf.
PT_INLINE bool chooseSecondChild(float c0, float c1, PT_INOUT(float) u, PT_OUT(float) pmf) {
  float sum = c0 + c1;
  float up = u * sum;
  bool second = c1 > 0.0f && (c0 == 0.0f || up >= c0);
  if (second) {
    pmf = c1 / sum;
    u = min((up - c0) / c1, 0.99999994f);
  } else {
    pmf = c0 / sum;
    u = min(up / c0, 0.99999994f);
  }
  return second;
}

#ifdef __cplusplus
}  // namespace pt
#endif

#endif  // PT_LIGHT_BVH_H
