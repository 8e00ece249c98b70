// The cells of SPPM's hash grid over the visible points (host/cpu/sppm_grid.h builds it on the
// host), written once for the grid's build and both backends' photons: the grid's shape, the
// cell a point lies in and the bucket a cell hashes to. The GPU's photons find the buckets the
// host listed its points in only if both compute the cells with the same operations.
#ifndef PT_SPPM_GRID_CELL_H
#define PT_SPPM_GRID_CELL_H

#include "sampling.h"
#include "shared_types.h"

#ifdef __cplusplus
namespace pt {
#endif

// A uniform grid over the box [lower, lower + extent] of `resolution` cells, hashed into a
// table of `buckets` buckets listing `entries` points (none: the grid is empty).
struct SppmGridShape {
  vec3 lower;        // 12 bytes
  uint buckets;      //  4 bytes
  vec3 extent;       // 12 bytes
  uint entries;      //  4 bytes
  ivec3 resolution;  // 12 bytes
  uint reserved;     //  4 bytes
};                   // 48 bytes

// The cell coordinate along one axis of a point's coordinate p: in float, as pbrt-v4, but the
// bounds' upper face inside (its last cell's); a NaN coordinate lands outside. `inside` is
// cleared where p lies outside the bounds (the cell then clamped to them).
PT_INLINE int sppmGridAxis(float p, float lower, float extent, int resolution,
                           PT_INOUT(bool) inside) {
  float offset = extent > 0.0f ? (p - lower) / extent : 0.0f;
  float scaled = float(resolution) * offset;
  bool within = scaled >= 0.0f && scaled <= float(resolution);
  inside = inside && within;
  return within ? min(int(scaled), resolution - 1) : (scaled > 0.0f ? resolution - 1 : 0);
}

// The cell of p, clamped to the grid; false where p lies outside its bounds.
PT_INLINE bool sppmGridCell(PT_IN(SppmGridShape) g, vec3 p, PT_OUT(ivec3) cell) {
  bool inside = true;
  cell.x = sppmGridAxis(p.x, g.lower.x, g.extent.x, g.resolution.x, inside);
  cell.y = sppmGridAxis(p.y, g.lower.y, g.extent.y, g.resolution.y, inside);
  cell.z = sppmGridAxis(p.z, g.lower.z, g.extent.z, g.resolution.z, inside);
  return inside;
}

// The bucket of a cell: pcg4d's mix of its three coordinates, reduced to the table.
PT_INLINE uint sppmGridBucket(PT_IN(SppmGridShape) g, ivec3 cell) {
  uvec4 h = pcg4d(uvec4(uint(cell.x), uint(cell.y), uint(cell.z), 0x5BD1E995u));
  return h.x % g.buckets;
}

#ifdef __cplusplus
}  // namespace pt
#endif

#endif  // PT_SPPM_GRID_CELL_H
