// The spatial hash grid over the visible points of one photon mapping iteration (pbrt-v4's SPPM
// grid): a uniform grid over the bounds of the points' radius-bounded boxes, its cell size about
// the largest radius, the cells hashed into a table of a prime size near the point count, each
// point listed once in the bucket of every cell its box overlaps (pbrt-v4 lists it once per
// cell, twice where two of its cells share a bucket). A photon looks up its own cell's bucket
// and checks the distance to each point listed there. Built serially in point order, so the
// lists, and every answer, are the same on every run.
#pragma once

#include <cstdint>
#include <vector>

#include "common/shared.h"

namespace pt {

class SppmGrid {
 public:
  // Builds the grid over points[i] with search radius radii[i]; points with `present[i]` false
  // (no visible point this iteration) are left out.
  SppmGrid(const std::vector<vec3>& points, const std::vector<float>& radii,
           const std::vector<char>& present);

  // Calls f(i) for every point listed in the bucket of p's cell, each once: a superset of the
  // points within their radius of p (none where p lies outside the grid's bounds).
  template <typename F>
  void forCandidates(vec3 p, F&& f) const {
    ivec3 cell;
    if (!empty() && toCell(p, cell)) {
      const uint32_t h = hashOf(cell);
      for (uint32_t k = start_[h]; k < start_[h + 1]; ++k) f(entries_[k]);
    }
  }

  // Calls f(i) for every point i within radii[i] of p (distance squared <= radius squared, as
  // pbrt-v4 tests), in the order they are listed.
  template <typename F>
  void forWithin(vec3 p, F&& f) const {
    forCandidates(p, [&](uint32_t i) {
      const vec3 d = points_[i] - p;
      const float r = radii_[i];
      if (dot(d, d) <= r * r) f(i);
    });
  }

  bool empty() const { return entries_.empty(); }
  ivec3 resolution() const { return resolution_; }
  size_t entryCount() const { return entries_.size(); }  // (point, cell) pairs listed

 private:
  // The cell of p, clamped to the grid; false where p lies outside its bounds.
  bool toCell(vec3 p, ivec3& cell) const;
  uint32_t hashOf(ivec3 cell) const;

  const std::vector<vec3>& points_;
  const std::vector<float>& radii_;
  vec3 lower_{0.0f}, extent_{0.0f};
  ivec3 resolution_{1};
  uint32_t buckets_ = 1;         // the hash table's size: a prime near the point count
  std::vector<uint32_t> start_;  // the hash table: bucket h's entries are [start_[h], start_[h+1])
  std::vector<uint32_t> entries_;  // point indices, bucket by bucket
};

// The smallest prime >= n (the hash table's size, as pbrt-v4's NextPrime).
uint32_t nextPrime(uint32_t n);

}  // namespace pt
