#include "render/light_bvh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <tuple>
#include <utility>

#include <glm/glm.hpp>

#include "common/numbers.h"
#include "path_vertex.h"

namespace pt {
namespace {

using glm::dvec3;

// pbrt-v4's LightBounds, in double while the tree is built.
struct Bounds {
  dvec3 lo{std::numeric_limits<double>::infinity()};
  dvec3 hi{-std::numeric_limits<double>::infinity()};
  double phi = 0.0;  // 0: empty
  dvec3 w{0.0, 0.0, 1.0};
  double cosThetaO = 1.0;
  double cosThetaE = 1.0;
  bool twoSided = false;

  dvec3 centroid() const { return 0.5 * (lo + hi); }
};

// pbrt-v4's cos(pi / 2), in single precision as it computes it: a light's emission reaches
// 90 degrees beyond its normals.
const double kCosHalfPi = double(std::cos(3.14159265f / 2.0f));

// Rotates v about the unit axis k by angle theta (Rodrigues).
dvec3 rotate(dvec3 v, dvec3 k, double theta) {
  const double c = std::cos(theta), s = std::sin(theta);
  return v * c + glm::cross(k, v) * s + k * glm::dot(k, v) * (1.0 - c);
}

// pbrt-v4's DirectionCone Union: the smallest cone (axis, cosine) holding both.
std::pair<dvec3, double> coneUnion(dvec3 wa, double cosA, dvec3 wb, double cosB) {
  const double thetaA = std::acos(std::clamp(cosA, -1.0, 1.0));
  const double thetaB = std::acos(std::clamp(cosB, -1.0, 1.0));
  const double thetaD = std::acos(std::clamp(glm::dot(wa, wb), -1.0, 1.0));
  if (std::min(thetaD + thetaB, kPiD) <= thetaA) return {wa, cosA};
  if (std::min(thetaD + thetaA, kPiD) <= thetaB) return {wb, cosB};
  const double thetaO = 0.5 * (thetaA + thetaD + thetaB);
  if (thetaO >= kPiD) return {wa, -1.0};
  const dvec3 axis = glm::cross(wa, wb);
  if (glm::dot(axis, axis) == 0.0) return {wa, -1.0};
  return {glm::normalize(rotate(wa, glm::normalize(axis), thetaO - thetaA)), std::cos(thetaO)};
}

// pbrt-v4's Union of two LightBounds.
Bounds unite(const Bounds& a, const Bounds& b) {
  if (a.phi == 0.0) return b;
  if (b.phi == 0.0) return a;
  Bounds u;
  u.lo = glm::min(a.lo, b.lo);
  u.hi = glm::max(a.hi, b.hi);
  u.phi = a.phi + b.phi;
  std::tie(u.w, u.cosThetaO) = coneUnion(a.w, a.cosThetaO, b.w, b.cosThetaO);
  u.cosThetaE = std::min(a.cosThetaE, b.cosThetaE);
  u.twoSided = a.twoSided || b.twoSided;
  return u;
}

double maxOf(vec3 v) {
  return double(std::max(v.x, std::max(v.y, v.z)));
}

// A light at a point: pbrt-v4's PointLight and SpotLight bounds.
Bounds pointBounds(vec3 p, dvec3 w, double phi, double cosThetaO, double cosThetaE) {
  Bounds b;
  b.lo = b.hi = dvec3(p);
  b.w = w;
  b.phi = phi;
  b.cosThetaO = cosThetaO;
  b.cosThetaE = cosThetaE;
  return b;
}

// The bounds of one emitter, or phi 0 for a distant or infinite light.
Bounds emitterBounds(const Emitter& e, const std::vector<Triangle>& triangles,
                     const std::vector<Material>& materials, const std::vector<Light>& lights) {
  if ((e.triangle & kEmitterLight) == 0u) {
    // pbrt-v4's DiffuseAreaLight on a triangle: the cone of its one emitting normal.
    const Triangle& tri = triangles[e.triangle];
    const Material& m = materials[tri.material];
    const dvec3 v0(tri.v0), v1(tri.v1), v2(tri.v2);
    const dvec3 edgeCross = glm::cross(v1 - v0, v2 - v0);
    Bounds b;
    b.lo = glm::min(v0, glm::min(v1, v2));
    b.hi = glm::max(v0, glm::max(v1, v2));
    b.phi = maxOf(m.emission) * kPiD * 0.5 * glm::length(edgeCross);
    b.w = dvec3(triangleShadingOf(tri).normal);  // the side it emits on
    b.cosThetaO = 1.0;
    b.cosThetaE = kCosHalfPi;
    b.twoSided = m.twoSided != 0u;
    return b;
  }
  const Light& light = lights[e.triangle & ~kEmitterLight];
  switch (light.type) {
    case kLightPoint:
      return pointBounds(light.position, dvec3(0.0, 0.0, 1.0), 4.0 * kPiD * maxOf(light.radiance),
                         -1.0, kCosHalfPi);
    case kLightSpot: {
      const double cosStart = light.cosFalloffStart, cosEnd = light.cosFalloffEnd;
      double cosThetaE = std::cos(std::acos(cosEnd) - std::acos(cosStart));
      // pbrt-v4's slop for the rounding of the importance's cosine.
      if (cosThetaE == 1.0 && cosEnd != cosStart) cosThetaE = 0.999;
      return pointBounds(light.position, dvec3(light.direction), 4.0 * kPiD * maxOf(light.radiance),
                         cosStart, cosThetaE);
    }
    case kLightSphere: {
      // pbrt-v4's DiffuseAreaLight on a sphere: normals in every direction.
      Bounds b;
      const double r = light.radius;
      b.lo = dvec3(light.position) - r;
      b.hi = dvec3(light.position) + r;
      b.phi = maxOf(light.radiance) * kPiD * 4.0 * kPiD * r * r;
      b.cosThetaO = -1.0;
      b.cosThetaE = kCosHalfPi;
      return b;
    }
    default:
      return Bounds{};
  }
}

// pbrt-v4's BVHLightSampler::EvaluateCost: power times the solid-angle measure of the cone
// times the surface area of the box, stretched along the split's axis.
double splitCost(const Bounds& b, dvec3 extent, int dim) {
  const double thetaO = std::acos(std::clamp(b.cosThetaO, -1.0, 1.0));
  const double thetaE = std::acos(std::clamp(b.cosThetaE, -1.0, 1.0));
  const double thetaW = std::min(thetaO + thetaE, kPiD);
  const double sinThetaO = std::sqrt(std::max(0.0, 1.0 - b.cosThetaO * b.cosThetaO));
  const double mOmega = 2.0 * kPiD * (1.0 - b.cosThetaO) +
                        kPiD / 2.0 *
                            (2.0 * thetaW * sinThetaO - std::cos(thetaO - 2.0 * thetaW) -
                             2.0 * thetaO * sinThetaO + b.cosThetaO);
  const double kr = std::max(extent.x, std::max(extent.y, extent.z)) / extent[dim];
  const dvec3 d = b.hi - b.lo;
  const double area = 2.0 * (d.x * d.y + d.x * d.z + d.y * d.z);
  return b.phi * mOmega * kr * area;
}

struct Builder {
  std::vector<std::pair<uint32_t, Bounds>> items;  // emitter, bounds
  std::vector<LightBvhNode> nodes;
  std::vector<LightBox> boxes;
  std::vector<uint32_t> leafOf;

  LightBvhNode toNode(const Bounds& b) const {
    LightBvhNode n{};
    const vec3 lo(b.lo), hi(b.hi);
    n.centre = 0.5f * (lo + hi);
    n.radius = 0.5f * glm::length(hi - lo);
    n.phi = float(b.phi);
    n.w = vec3(b.w);
    n.cosThetaO = float(b.cosThetaO);
    n.sinThetaO = float(std::sqrt(std::max(0.0, 1.0 - b.cosThetaO * b.cosThetaO)));
    n.cosThetaE = float(b.cosThetaE);
    n.flags = b.twoSided ? kLightBvhTwoSided : 0u;
    return n;
  }

  // pbrt-v4's buildBVH over items [start, end) below `parent`: 12 buckets per axis of the
  // centroids' box, the split of least splitCost; the middle where none helps (or deeper than
  // 64 levels, which bounds the recursion). Returns the node and its bounds.
  std::pair<uint32_t, Bounds> build(size_t start, size_t end, uint32_t parent, int depth) {
    const uint32_t at = uint32_t(nodes.size());
    if (end - start == 1) {
      LightBvhNode leaf = toNode(items[start].second);
      leaf.child = items[start].first;
      leaf.flags |= kLightBvhLeaf;
      leaf.parent = parent;
      nodes.push_back(leaf);
      boxes.push_back(LightBox{vec3(items[start].second.lo), vec3(items[start].second.hi)});
      leafOf[items[start].first] = at;
      return {at, items[start].second};
    }
    dvec3 lo(std::numeric_limits<double>::infinity()), hi(-lo);
    dvec3 cLo = lo, cHi = hi;
    for (size_t i = start; i < end; ++i) {
      const Bounds& b = items[i].second;
      lo = glm::min(lo, b.lo);
      hi = glm::max(hi, b.hi);
      cLo = glm::min(cLo, b.centroid());
      cHi = glm::max(cHi, b.centroid());
    }
    constexpr int kBuckets = 12;
    const auto bucketOf = [&](const Bounds& b, int dim) {
      const int k = int(kBuckets * ((b.centroid()[dim] - cLo[dim]) / (cHi[dim] - cLo[dim])));
      return std::clamp(k, 0, kBuckets - 1);
    };
    double minCost = std::numeric_limits<double>::infinity();
    int splitBucket = -1, splitDim = -1;
    for (int dim = 0; dim < 3 && depth < 64; ++dim) {
      if (cHi[dim] == cLo[dim]) continue;
      std::array<Bounds, kBuckets> buckets{};
      for (size_t i = start; i < end; ++i) {
        Bounds& bucket = buckets[size_t(bucketOf(items[i].second, dim))];
        bucket = unite(bucket, items[i].second);
      }
      for (int s = 1; s < kBuckets - 1; ++s) {
        Bounds below, above;
        for (int j = 0; j <= s; ++j) below = unite(below, buckets[size_t(j)]);
        for (int j = s + 1; j < kBuckets; ++j) above = unite(above, buckets[size_t(j)]);
        const double cost = splitCost(below, hi - lo, dim) + splitCost(above, hi - lo, dim);
        if (cost > 0.0 && cost < minCost) {
          minCost = cost;
          splitBucket = s;
          splitDim = dim;
        }
      }
    }
    size_t mid = (start + end) / 2;
    if (splitDim >= 0) {
      const auto first = items.begin() + std::ptrdiff_t(start);
      const auto last = items.begin() + std::ptrdiff_t(end);
      mid = size_t(std::partition(first, last,
                                  [&](const auto& item) {
                                    return bucketOf(item.second, splitDim) <= splitBucket;
                                  }) -
                   items.begin());
      if (mid == start || mid == end) mid = (start + end) / 2;
    }
    nodes.push_back(LightBvhNode{});
    boxes.emplace_back();
    const auto [first, firstBounds] = build(start, mid, at, depth + 1);
    const auto [second, secondBounds] = build(mid, end, at, depth + 1);
    const Bounds all = unite(firstBounds, secondBounds);
    LightBvhNode node = toNode(all);
    node.child = second;
    node.parent = parent;
    const LightBvhNode& a = nodes[first];
    const LightBvhNode& b = nodes[second];
    if (a.centre == b.centre && a.radius == b.radius && a.w == b.w && a.cosThetaO == b.cosThetaO &&
        a.cosThetaE == b.cosThetaE &&
        (a.flags & kLightBvhTwoSided) == (b.flags & kLightBvhTwoSided)) {
      node.flags |= kLightBvhSameBounds;
    }
    nodes[at] = node;
    boxes[at] = LightBox{vec3(all.lo), vec3(all.hi)};
    return {at, all};
  }
};

}  // namespace

LightBvh buildLightBvh(const std::vector<Emitter>& emitters, const std::vector<Triangle>& triangles,
                       const std::vector<Material>& materials, const std::vector<Light>& lights) {
  LightBvh bvh;
  Builder b;
  b.leafOf.assign(emitters.size(), kNoEmitter);
  std::vector<uint32_t> unbounded;
  for (uint32_t i = 0; i < emitters.size(); ++i) {
    const Bounds bounds = emitterBounds(emitters[i], triangles, materials, lights);
    if (bounds.phi > 0.0) {
      b.items.emplace_back(i, bounds);
    } else {
      unbounded.push_back(i);
    }
  }
  if (b.items.empty()) return bvh;
  b.nodes.reserve(2 * b.items.size() - 1);
  b.build(0, b.items.size(), 0u, 0);
  bvh.nodes = std::move(b.nodes);
  bvh.boxes = std::move(b.boxes);
  bvh.words = std::move(b.leafOf);
  bvh.words.insert(bvh.words.end(), unbounded.begin(), unbounded.end());
  bvh.unbounded = uint32_t(unbounded.size());
  return bvh;
}

bool choosesByPowerAlone(const LightBvh& tree) {
  return std::all_of(tree.nodes.begin(), tree.nodes.end(), [](const LightBvhNode& n) {
    return (n.flags & (kLightBvhLeaf | kLightBvhSameBounds)) != 0u;
  });
}

}  // namespace pt
