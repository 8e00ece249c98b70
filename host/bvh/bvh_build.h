// Pieces shared by the two BVH builders (bvh.cpp, bvh_sah.cpp); not part of the interface.
#pragma once

#include <cmath>
#include <vector>

#include "bvh/bvh.h"

namespace pt {

struct Bounds {
  vec3 lo{INFINITY};
  vec3 hi{-INFINITY};
  void grow(vec3 p) {
    lo = min(lo, p);
    hi = max(hi, p);
  }
  void grow(const Bounds& b) {
    lo = min(lo, b.lo);
    hi = max(hi, b.hi);
  }
  float surfaceArea() const {
    const vec3 d = max(hi - lo, vec3(0.0f));
    return 2.0f * (d.x * d.y + d.y * d.z + d.z * d.x);
  }
};

// Smallest number of levels below a node that a balanced split of `count` triangles needs.
inline int balancedLevels(size_t count, size_t leafSize) {
  int levels = 0;
  for (size_t leaves = (count + leafSize - 1) / leafSize; leaves > 1; leaves = (leaves + 1) / 2)
    ++levels;
  return levels;
}

// The binned-SAH builder behind buildBvh(options.builder = kBinnedSah).
Bvh buildBinnedSahBvh(std::vector<Triangle> triangles, size_t leafSize);

}  // namespace pt
