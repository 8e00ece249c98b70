#include "render/prepare_media.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "common/check.h"
#include "scene/voxel_grid.h"

namespace pt {

namespace {

// A nanovdb medium's majorant grid (m.size cells over its bounds, x fastest): per cell, the
// largest density of the voxels that trilinear lookups in it reach (the index box of the cell's
// corners, floor to floor + 1), widened by a voxel on every side against rounding.
std::vector<float> voxelGridMajorants(const Medium& m, const float* grid) {
  const glm::dmat4 indexFromMedium = voxelGridIndexFromMedium(grid);
  const glm::dvec3 lo(m.boundsMin), extent = glm::dvec3(m.boundsMax) - glm::dvec3(m.boundsMin);
  std::vector<float> out(size_t(m.size.x) * m.size.y * m.size.z, 0.0f);
  for (uint z = 0; z < m.size.z; ++z) {
    for (uint y = 0; y < m.size.y; ++y) {
      for (uint x = 0; x < m.size.x; ++x) {
        const glm::dvec3 c0 = lo + extent * glm::dvec3(x, y, z) / glm::dvec3(m.size);
        const glm::dvec3 c1 = lo + extent * glm::dvec3(x + 1, y + 1, z + 1) / glm::dvec3(m.size);
        glm::dvec3 iMin(INFINITY), iMax(-INFINITY);
        for (int k = 0; k < 8; ++k) {
          const glm::dvec3 p((k & 1) ? c1.x : c0.x, (k & 2) ? c1.y : c0.y, (k & 4) ? c1.z : c0.z);
          const glm::dvec3 i = glm::dvec3(indexFromMedium * glm::dvec4(p, 1.0));
          iMin = glm::min(iMin, i);
          iMax = glm::max(iMax, i);
        }
        const glm::ivec3 first = glm::ivec3(glm::floor(iMin)) - 1;
        const glm::ivec3 last = glm::ivec3(glm::floor(iMax)) + 2;
        out[(size_t(z) * m.size.y + y) * m.size.x + x] = voxelGridMax(grid, first, last);
      }
    }
  }
  return out;
}

}  // namespace

std::vector<float> majorantGrid(const Medium& m, const std::vector<float>& grids) {
  if (m.type == kMediumCloud) return {1.0f};  // its density is at most 1
  if (m.type == kMediumNanoVdb) return voxelGridMajorants(m, grids.data() + m.density);
  const uint r = kMajorantGridRes;
  const size_t voxels = size_t(m.size.x) * m.size.y * m.size.z;
  // The largest value over the voxels whose interpolation reaches cell (x, y, z): a cell's
  // unit-cube bounds [i / r, (i + 1) / r] touch the voxel centres from floor(lo * n - 0.5)
  // to floor(hi * n - 0.5) + 1 (pbrt-v4's SampledGrid::MaxValue).
  auto voxelRange = [&](uint cell, uint n, int& first, int& last) {
    const float lo = float(cell) / float(r) * float(n) - 0.5f;
    const float hi = float(cell + 1) / float(r) * float(n) - 0.5f;
    first = std::max(int(std::floor(lo)), 0);
    last = std::min(int(std::floor(hi)) + 1, int(n) - 1);
  };
  auto voxelValue = [&](size_t index) {
    if (m.type == kMediumUniformGrid) return grids[m.density + index];
    float best = 0.0f;
    for (uint c = 0; c < 3; ++c) {
      const float a = grids[m.density + 3 * index + c];
      const float s = grids[m.density + 3 * voxels + 3 * index + c];
      best = std::max(best, m.sigmaA[int(c)] * a + m.sigmaS[int(c)] * s);
    }
    return best;
  };
  std::vector<float> out(size_t(r) * r * r, 0.0f);
  for (uint z = 0; z < r; ++z) {
    int z0, z1;
    voxelRange(z, m.size.z, z0, z1);
    for (uint y = 0; y < r; ++y) {
      int y0, y1;
      voxelRange(y, m.size.y, y0, y1);
      for (uint x = 0; x < r; ++x) {
        int x0, x1;
        voxelRange(x, m.size.x, x0, x1);
        float best = 0.0f;
        for (int k = z0; k <= z1; ++k) {
          for (int j = y0; j <= y1; ++j) {
            for (int i = x0; i <= x1; ++i) {
              const size_t index = (size_t(k) * m.size.y + size_t(j)) * m.size.x + size_t(i);
              best = std::max(best, voxelValue(index));
            }
          }
        }
        out[(size_t(z) * r + y) * r + x] = best;
      }
    }
  }
  return out;
}

void prepareMedia(Scene& scene, vec3 shift, SceneData& data) {
  if (scene.media.empty()) return;
  data.media = std::move(scene.media);
  data.mediumGrids = std::move(scene.mediumGrids);
  for (Medium& m : data.media) {
    if (m.type == kMediumHomogeneous) continue;
    // The medium's transform took world points; the renderer's points are shifted.
    m.toMedium0.w += dot(vec3(m.toMedium0), shift);
    m.toMedium1.w += dot(vec3(m.toMedium1), shift);
    m.toMedium2.w += dot(vec3(m.toMedium2), shift);
    const std::vector<float> majorants = majorantGrid(m, data.mediumGrids);
    m.majorants = uint32_t(data.mediumGrids.size());
    data.mediumGrids.insert(data.mediumGrids.end(), majorants.begin(), majorants.end());
  }
  PT_CHECK(scene.mediumInterfaces.empty() ||
           scene.mediumInterfaces.size() == data.bvh.triangles.size());
  data.mediumInterfaces = std::move(scene.mediumInterfaces);
  if (data.mediumInterfaces.empty()) {
    data.mediumInterfaces.assign(data.bvh.triangles.size(), MediumInterface{kNoMedium, kNoMedium});
  }
  // pbrt-v4 turns a triangle's normal to the side of its vertex normals where it has them (as
  // a dielectric's inside is told by them here too): the interface's sides follow.
  if (!data.normals.empty()) {
    for (const Triangle& t : data.bvh.triangles) {
      const TriangleNormals& n = data.normals[t.primitive];
      if (dot(cross(t.v1 - t.v0, t.v2 - t.v0), n.n0 + n.n1 + n.n2) < 0.0f) {
        MediumInterface& mi = data.mediumInterfaces[t.primitive];
        std::swap(mi.inside, mi.outside);
      }
    }
  }
  data.params.cameraMedium = scene.cameraMedium;
  data.params.mediaPresent = 1u;
  data.effects.media = true;
  for (const Medium& m : data.media) data.effects.mediumKinds |= 1u << m.type;
}

}  // namespace pt
