// Packing sparse voxel grids (voxel_grid.h).
#include "scene/voxel_grid.h"

#include <algorithm>
#include <limits>

#include <glm/common.hpp>

#include "common/check.h"

namespace pt {

std::vector<float> packVoxelGrid(const VoxelBricks& grid) {
  const std::size_t mapEntries = std::size_t(grid.bricks.x) * grid.bricks.y * grid.bricks.z;
  PT_CHECK(grid.map.size() == mapEntries, "voxel grid: brick map of the wrong size");
  PT_CHECK(grid.values.size() % kBrickVoxels == 0, "voxel grid: partial brick");
  const std::size_t constantsAt = kVoxelGridHeader + mapEntries;
  const std::size_t bricksAt = constantsAt + grid.constants.size();
  const std::size_t total = bricksAt + grid.values.size();
  if (total >= std::size_t(std::numeric_limits<uint32_t>::max())) {
    throw InputError("a voxel grid of " + std::to_string(total) +
                     " floats is beyond 32-bit offsets");
  }
  std::vector<float> out(total, 0.0f);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) out[std::size_t(4 * r + c)] = float(grid.indexFromMedium[c][r]);
  }
  for (int a = 0; a < 3; ++a) {
    out[std::size_t(12 + a)] = glm::uintBitsToFloat(uint32_t(grid.origin[a]));
    out[std::size_t(15 + a)] = glm::uintBitsToFloat(grid.bricks[a]);
  }
  out[18] = grid.background;
  out[19] = glm::uintBitsToFloat(uint32_t(constantsAt));
  out[20] = glm::uintBitsToFloat(uint32_t(bricksAt));
  out[21] = glm::uintBitsToFloat(uint32_t(total));
  for (std::size_t i = 0; i < mapEntries; ++i)
    out[kVoxelGridHeader + i] = glm::uintBitsToFloat(grid.map[i]);
  std::copy(grid.constants.begin(), grid.constants.end(),
            out.begin() + std::ptrdiff_t(constantsAt));
  std::copy(grid.values.begin(), grid.values.end(), out.begin() + std::ptrdiff_t(bricksAt));
  return out;
}

std::size_t packedVoxelGridFloats(const float* grid) {
  return glm::floatBitsToUint(grid[21]);
}

glm::dmat4 voxelGridIndexFromMedium(const float* grid) {
  glm::dmat4 m(1.0);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) m[c][r] = double(grid[4 * r + c]);
  }
  return m;
}

float voxelGridMax(const float* grid, glm::ivec3 lo, glm::ivec3 hi) {
  const glm::ivec3 origin(int32_t(glm::floatBitsToUint(grid[12])),
                          int32_t(glm::floatBitsToUint(grid[13])),
                          int32_t(glm::floatBitsToUint(grid[14])));
  const glm::ivec3 bricks(int(glm::floatBitsToUint(grid[15])), int(glm::floatBitsToUint(grid[16])),
                          int(glm::floatBitsToUint(grid[17])));
  const float* map = grid + kVoxelGridHeader;
  const float* constants = grid + glm::floatBitsToUint(grid[19]);
  const float* values = grid + glm::floatBitsToUint(grid[20]);
  float best = -std::numeric_limits<float>::infinity();
  // The part of the range beyond the bricks sees the background.
  const glm::ivec3 end = origin + 8 * bricks;  // one past the last voxel
  for (int a = 0; a < 3; ++a) {
    if (lo[a] < origin[a] || hi[a] >= end[a]) best = std::max(best, grid[18]);
  }
  const glm::ivec3 first = glm::max(lo, origin), last = glm::min(hi, end - 1);
  if (first.x > last.x || first.y > last.y || first.z > last.z) return best;
  const glm::ivec3 b0 = (first - origin) >> 3, b1 = (last - origin) >> 3;
  for (int bz = b0.z; bz <= b1.z; ++bz) {
    for (int by = b0.y; by <= b1.y; ++by) {
      for (int bx = b0.x; bx <= b1.x; ++bx) {
        const uint32_t entry =
            glm::floatBitsToUint(map[(std::size_t(bz) * std::size_t(bricks.y) + std::size_t(by)) *
                                         std::size_t(bricks.x) +
                                     std::size_t(bx)]);
        if (entry & kConstantBrick) {
          best = std::max(best, constants[entry & ~kConstantBrick]);
          continue;
        }
        // The part of the range inside this brick.
        const glm::ivec3 corner = origin + 8 * glm::ivec3(bx, by, bz);
        const glm::ivec3 v0 = glm::max(first, corner) - corner;
        const glm::ivec3 v1 = glm::min(last, corner + 7) - corner;
        const float* brick = values + std::size_t(entry) * kBrickVoxels;
        for (int z = v0.z; z <= v1.z; ++z) {
          for (int y = v0.y; y <= v1.y; ++y) {
            for (int x = v0.x; x <= v1.x; ++x) best = std::max(best, brick[(z * 8 + y) * 8 + x]);
          }
        }
      }
    }
  }
  return best;
}

}  // namespace pt
