// Watertightness probes for closed meshes, shared by the CPU and the GPU traversal tests:
// the Stanford bunny (a real scan; the glmark2-data copy is closed: every edge is shared by
// exactly two consistently oriented triangles), points inside a closed mesh, and rays aimed
// from those points exactly at every vertex and edge midpoint, where a test that is not
// watertight lets rays slip between neighbouring triangles.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "bvh/traverse.h"
#include "scene/load_scene.h"
#include "scene/scene.h"
#include "test_util.h"

namespace pt::test {

inline const char* const kBunnyObj = "/usr/share/glmark2/models/bunny.obj";

inline std::vector<Triangle> loadBunny() {
  const std::string file = kBunnyObj;
  const std::string scene = R"({"materials": [{"name": "white", "reflectance": [0.5, 0.5, 0.5]}],
    "shapes": [{"type": "obj", "material": "white", "file": ")" +
                            file + "\"}]}";
  const TempDir dir;
  return loadScene(dir.write("bunny.json", scene)).triangles;
}

// Vertices are matched by exact position: a closed mesh shares them bit for bit.
using PositionKey = std::tuple<float, float, float>;
inline PositionKey positionKey(vec3 v) {
  return PositionKey(v.x, v.y, v.z);
}

// How many edges are not shared by exactly two triangles that traverse them in opposite
// directions (0 for a closed, consistently oriented mesh). Vertices are matched by position.
inline size_t openOrMisorientedEdges(const std::vector<Triangle>& tris) {
  const auto key = positionKey;
  std::map<std::pair<PositionKey, PositionKey>, int> use;
  for (const Triangle& t : tris) {
    const vec3 v[3] = {t.v0, t.v1, t.v2};
    for (int i = 0; i < 3; ++i) ++use[{key(v[i]), key(v[(i + 1) % 3])}];
  }
  size_t bad = 0;
  for (const auto& [edge, count] : use) {
    const auto reverse = use.find({edge.second, edge.first});
    bad += count != 1 || reverse == use.end() || reverse->second != 1;
  }
  return bad;
}

// +1 when the winding makes geometric normals point out of the closed mesh, else -1.
inline float outwardSign(const std::vector<Triangle>& tris) {
  double signedVolume = 0;
  for (const Triangle& t : tris) signedVolume += double(dot(t.v0, cross(t.v1, t.v2)));
  return signedVolume > 0 ? 1.0f : -1.0f;
}

// Points of a grid over the mesh's bounds that lie inside the closed mesh: seen from such a
// point, the first surface in each of 14 directions is crossed from the inside.
inline std::vector<vec3> interiorPoints(const Bvh& bvh, int gridSize, size_t maxPoints) {
  const float outward = outwardSign(bvh.triangles);
  const vec3 lo = bvh.nodes[0].boundsMin, hi = bvh.nodes[0].boundsMax;
  std::vector<vec3> inside;
  for (int i = 1; i < gridSize; ++i) {
    for (int j = 1; j < gridSize; ++j) {
      for (int k = 1; k < gridSize; ++k) {
        const vec3 p = lo + (hi - lo) * vec3(i, j, k) / float(gridSize);
        bool isInside = true;
        for (int d = 0; d < 14 && isInside; ++d) {
          // The six axes, then the eight diagonals (slightly skewed in z).
          const vec3 dir = d < 6 ? vec3(d % 3 == 0, d % 3 == 1, d % 3 == 2) * (d < 3 ? 1.0f : -1.0f)
                                 : vec3(d & 1 ? 1 : -1, d & 2 ? 1 : -1, d & 4 ? 0.7f : -0.7f);
          const auto hit = closestHit(bvh, Ray{p, dir});
          if (!hit) {
            isInside = false;
            break;
          }
          const Triangle& t = bvh.triangles[hit->triangle];
          isInside = outward * dot(cross(t.v1 - t.v0, t.v2 - t.v0), dir) > 0;
        }
        if (isInside) inside.push_back(p);
      }
    }
  }
  // Spread the chosen points over the whole set.
  std::vector<vec3> chosen;
  for (size_t n = 0; n < maxPoints && n < inside.size(); ++n) {
    chosen.push_back(inside[n * inside.size() / std::min(maxPoints, inside.size())]);
  }
  return chosen;
}

// From each origin, a ray aimed at every triangle's first vertex and at the midpoints of
// two of its edges (with shared vertices, that covers every vertex and edge of a closed
// mesh). The direction is target - origin, so the surface lies at t = 1. Only targets where
// the ray crosses the surface are kept: every triangle around the vertex or edge faces
// away from the origin. (Where some face it, the target lies on a silhouette seen from the
// origin; a ray there may graze the surface without crossing it, and then rightly goes on
// to hit the far side.)
inline std::vector<RayQuery> aimedRays(const std::vector<Triangle>& tris,
                                       const std::vector<vec3>& origins) {
  const auto key = positionKey;
  std::map<PositionKey, std::vector<uint32_t>> aroundVertex;
  std::map<std::pair<PositionKey, PositionKey>, std::vector<uint32_t>> aroundEdge;  // sorted ends
  for (uint32_t i = 0; i < tris.size(); ++i) {
    const vec3 v[3] = {tris[i].v0, tris[i].v1, tris[i].v2};
    for (int k = 0; k < 3; ++k) {
      aroundVertex[key(v[k])].push_back(i);
      aroundEdge[std::minmax(key(v[k]), key(v[(k + 1) % 3]))].push_back(i);
    }
  }
  const double outward = outwardSign(tris);
  auto crosses = [&](vec3 o, vec3 target, const std::vector<uint32_t>& around) {
    for (uint32_t i : around) {
      const glm::dvec3 v0(tris[i].v0), v1(tris[i].v1), v2(tris[i].v2);
      if (outward * dot(cross(v1 - v0, v2 - v0), glm::dvec3(target) - glm::dvec3(o)) <= 0) {
        return false;
      }
    }
    return true;
  };
  std::vector<RayQuery> queries;
  queries.reserve(origins.size() * tris.size() * 3);
  for (const vec3& o : origins) {
    for (const Triangle& t : tris) {
      const std::pair<vec3, const std::vector<uint32_t>*> targets[] = {
          {t.v0, &aroundVertex[key(t.v0)]},
          {0.5f * (t.v0 + t.v1), &aroundEdge[std::minmax(key(t.v0), key(t.v1))]},
          {0.5f * (t.v1 + t.v2), &aroundEdge[std::minmax(key(t.v1), key(t.v2))]}};
      for (const auto& [target, around] : targets) {
        if (crosses(o, target, *around)) queries.push_back(RayQuery{o, INFINITY, target - o, 0u});
      }
    }
  }
  return queries;
}

// Whether a ray from inside slipped through the surface at its target. It did when it finds
// nothing, or when the first surface it finds lies beyond the target (t = 1) and faces the
// ray, so that the ray meets it from outside. (The tolerance on t covers the rounding of
// the target point; hits on the surface around the target face away from the ray, and so
// count as stopped even when a nearly grazing angle puts t a little past 1.)
inline bool escaped(const std::vector<Triangle>& tris, float outward, const RayQuery& ray,
                    bool found, float t, uint32_t triangle) {
  if (!found) return true;
  if (t <= 1.0f + 1e-4f) return false;
  const Triangle& hit = tris[triangle];
  const glm::dvec3 v0(hit.v0), v1(hit.v1), v2(hit.v2);
  return outward * dot(cross(v1 - v0, v2 - v0), glm::dvec3(ray.direction)) < 0;
}

}  // namespace pt::test
