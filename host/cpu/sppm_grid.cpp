// The hash grid of SPPM's visible points; see sppm_grid.h.
#include "cpu/sppm_grid.h"

#include <algorithm>
#include <cmath>

#include "common/check.h"

namespace pt {
namespace {

// The most cells along an axis: keeps the cell coordinates and their products far from
// overflow where the radius has shrunk far below the scene's size (the table is hashed, so
// resolution costs no memory).
constexpr float kSppmGridMaxResolution = float(1 << 20);

}  // namespace

uint32_t nextPrime(uint32_t n) {
  auto isPrime = [](uint32_t v) {
    if (v < 2) return false;
    for (uint32_t d = 2; uint64_t(d) * d <= v; ++d) {
      if (v % d == 0) return false;
    }
    return true;
  };
  while (!isPrime(n)) ++n;
  return n;
}

SppmGrid::SppmGrid(const std::vector<vec3>& points, const std::vector<float>& radii,
                   const std::vector<char>& present)
    : points_(points), radii_(radii) {
  PT_CHECK(points.size() == radii.size() && points.size() == present.size());
  // The bounds of every point's box, and the largest radius.
  vec3 lo(INFINITY), hi(-INFINITY);
  float maxRadius = 0.0f;
  size_t count = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    if (!present[i]) continue;
    lo = min(lo, points[i] - vec3(radii[i]));
    hi = max(hi, points[i] + vec3(radii[i]));
    maxRadius = std::max(maxRadius, radii[i]);
    ++count;
  }
  start_.assign(2, 0u);
  if (count == 0 || !(maxRadius > 0.0f)) return;
  shape_.lower = lo;
  shape_.extent = hi - lo;
  const vec3 extent = shape_.extent;
  // pbrt-v4's resolution: the longest side in cells of the largest radius, the others in
  // proportion, at least one cell each.
  const float maxExtent = std::max(extent.x, std::max(extent.y, extent.z));
  const float base = std::min(std::floor(maxExtent / maxRadius), kSppmGridMaxResolution);
  for (int a = 0; a < 3; ++a) {
    shape_.resolution[a] = std::max(int(base * extent[a] / maxExtent), 1);
  }

  // Each point in the bucket of every cell its box overlaps: counted per bucket, then listed (a
  // counting sort, in point order within each bucket).
  shape_.buckets = nextPrime(uint32_t(count));
  const uint32_t size = shape_.buckets;
  std::vector<uint32_t> counts(size_t(size) + 1, 0u);
  // The buckets of the cells point i's box overlaps, each once: where two of its cells hash to
  // the same bucket, pbrt-v4 lists the point twice there and a photon in either cell counts
  // twice (on the 16x16 test image, where the table has 257 buckets, 2 % too much light).
  std::vector<uint32_t> buckets;
  auto forCells = [&](size_t i, auto&& f) {
    ivec3 a, b;
    sppmGridCell(shape_, points[i] - vec3(radii[i]), a);
    sppmGridCell(shape_, points[i] + vec3(radii[i]), b);
    buckets.clear();
    for (int z = a.z; z <= b.z; ++z) {
      for (int y = a.y; y <= b.y; ++y) {
        for (int x = a.x; x <= b.x; ++x) buckets.push_back(sppmGridBucket(shape_, ivec3(x, y, z)));
      }
    }
    std::sort(buckets.begin(), buckets.end());
    buckets.erase(std::unique(buckets.begin(), buckets.end()), buckets.end());
    for (uint32_t h : buckets) f(h);
  };
  for (size_t i = 0; i < points.size(); ++i) {
    if (present[i]) forCells(i, [&](uint32_t h) { ++counts[h + 1]; });
  }
  for (uint32_t h = 0; h < size; ++h) counts[h + 1] += counts[h];
  start_ = counts;
  entries_.resize(counts[size]);
  for (size_t i = 0; i < points.size(); ++i) {
    if (present[i]) forCells(i, [&](uint32_t h) { entries_[counts[h]++] = uint32_t(i); });
  }
  shape_.entries = uint32_t(entries_.size());
}

}  // namespace pt
