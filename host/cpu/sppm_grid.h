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
#include "sppm_grid_cell.h"

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
    if (!empty() && sppmGridCell(shape_, p, cell)) {
      const uint32_t h = sppmGridBucket(shape_, cell);
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
  ivec3 resolution() const { return shape_.resolution; }
  size_t entryCount() const { return entries_.size(); }  // (point, cell) pairs listed

  // The grid as the GPU's photons read it (shaders/sppm.glsl): its shape, the buckets' starts
  // (bucket h's entries are [starts[h], starts[h + 1])) and the entries, point indices.
  const SppmGridShape& shape() const { return shape_; }
  const std::vector<uint32_t>& bucketStarts() const { return start_; }
  const std::vector<uint32_t>& entries() const { return entries_; }

 private:
  const std::vector<vec3>& points_;
  const std::vector<float>& radii_;
  // Its bounds, resolution and the hash table's size: a prime near the point count.
  SppmGridShape shape_{vec3(0.0f), 1u, vec3(0.0f), 0u, ivec3(1), 0u};
  std::vector<uint32_t> start_;  // the hash table: bucket h's entries are [start_[h], start_[h+1])
  std::vector<uint32_t> entries_;  // point indices, bucket by bucket
};

// The smallest prime >= n (the hash table's size, as pbrt-v4's NextPrime).
uint32_t nextPrime(uint32_t n);

}  // namespace pt
