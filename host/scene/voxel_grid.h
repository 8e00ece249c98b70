// Sparse voxel grids as the backends read them (shared_types.h's layout, shaders/medium.h's
// voxelGridValue): a brick map over 8^3-voxel bricks, each brick its values or a constant.
// The NanoVDB reader (nanovdb_file.h) fills a VoxelBricks; pack() lays it out in floats.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "common/shared.h"

namespace pt {

// A sparse grid before packing. Brick (x, y, z) covers the voxels origin + 8 (x, y, z) + [0, 8)^3.
struct VoxelBricks {
  glm::dmat4 indexFromMedium{1.0};  // a point of the medium's space to index coordinates
  glm::ivec3 origin{0};             // multiples of 8
  glm::uvec3 bricks{0};             // along x, y, z
  float background = 0.0f;          // beyond the bricks
  // Per brick, x fastest: a brick number (into `values`, 512 floats each, x fastest) or
  // kConstantBrick | an index into `constants`.
  std::vector<uint32_t> map;
  std::vector<float> constants;
  std::vector<float> values;
};

// The floats of the packed grid (header, map, constants, bricks), to be placed in the media's
// grid buffer. Throws InputError when the grid does not fit 32-bit offsets.
std::vector<float> packVoxelGrid(const VoxelBricks& grid);

// The floats a packed grid starting at `grid` occupies (its header says).
std::size_t packedVoxelGridFloats(const float* grid);

// The index-from-medium transform of a packed grid (its header's rows).
glm::dmat4 voxelGridIndexFromMedium(const float* grid);

// The largest value of a packed grid over the voxels [lo, hi] (inclusive; index coordinates),
// the background included where the range leaves the bricks.
float voxelGridMax(const float* grid, glm::ivec3 lo, glm::ivec3 hi);

}  // namespace pt
