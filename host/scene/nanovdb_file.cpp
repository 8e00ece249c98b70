// Reading NanoVDB files into sparse voxel grids (nanovdb_file.h).
#include "scene/nanovdb_file.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <fstream>
#include <iterator>
#include <sstream>
#include <unordered_map>
#include <utility>
#include <vector>

#include <iostream>  // before GridValidator.h, which uses std::cerr without it

#include <nanovdb/NanoVDB.h>
#include <nanovdb/util/GridValidator.h>
#include <nanovdb/util/IO.h>

#include "common/check.h"

namespace pt {

namespace {

// The most bricks a grid's map may have (a map entry per 8^3 voxels of its bounds).
constexpr double kMaxBricks = 64.0 * 1024.0 * 1024.0;

using Handle = nanovdb::GridHandle<nanovdb::HostBuffer>;

// The node arrays and child offsets of `grid` (in a buffer of `size` bytes) checked before
// anything follows them: each level's nodes inside the buffer and aligned, every child offset
// of the root and the internal nodes landing on a node of the level below. NanoVDB's own
// validator follows the offsets first and checks them after (a damaged file made it read
// through a misaligned pointer), and its checksum may cover only the headers.
std::string structureProblem(const nanovdb::NanoGrid<float>& grid, std::size_t size) {
  using Root = nanovdb::NanoRoot<float>;
  using Upper = nanovdb::NanoUpper<float>;
  using Lower = nanovdb::NanoLower<float>;
  using Leaf = nanovdb::NanoLeaf<float>;
  // Positions are byte offsets from the grid, checked before they become pointers.
  const auto* begin = reinterpret_cast<const char*>(&grid);
  const auto within = [&](std::uint64_t at, std::uint64_t bytes) {
    return at <= size && bytes <= size - at && at % NANOVDB_DATA_ALIGNMENT == 0;
  };
  const std::uint64_t treeAt = sizeof(nanovdb::GridData);
  if (!within(0, treeAt + sizeof(nanovdb::TreeData<3>))) return "its header is truncated";
  const auto& tree = *reinterpret_cast<const nanovdb::TreeData<3>*>(begin + treeAt);
  const std::uint64_t sizes[4] = {sizeof(Leaf), sizeof(Lower), sizeof(Upper), sizeof(Root)};
  std::uint64_t first[4];
  for (int level = 0; level < 4; ++level) {
    const std::uint64_t count = level < 3 ? tree.mNodeCount[level] : 1;
    first[level] = treeAt + tree.mNodeOffset[level];
    if (count == 0) continue;
    if (tree.mNodeOffset[level] > size || count > size / sizes[level] ||
        !within(first[level], count * sizes[level])) {
      return "its nodes of level " + std::to_string(level) + " lie outside it";
    }
  }
  // An offset `delta` from the node at `from` must land on a node of `level`'s array.
  const auto isNode = [&](std::uint64_t from, std::int64_t delta, int level) {
    const std::uint64_t to = from + std::uint64_t(delta);  // wraps for bad offsets: refused
    return to >= first[level] && (to - first[level]) % sizes[level] == 0 &&
           (to - first[level]) / sizes[level] < tree.mNodeCount[level];
  };
  const auto& root = *reinterpret_cast<const Root::DataType*>(begin + first[3]);
  if (root.mTableSize > (size - first[3] - sizeof(Root)) / sizeof(Root::Tile)) {
    return "its root's table lies outside it";
  }
  for (uint32_t i = 0; i < root.mTableSize; ++i) {
    const std::int64_t child = root.tile(i)->child;
    if (child != 0 && !isNode(first[3], child, 2)) {
      return "a child offset of its root points outside its nodes";
    }
  }
  // The internal nodes of `level` (Node: Upper or Lower): their children on the level below.
  const auto childrenAreNodes = [&]<typename Node>(int level) {
    for (uint32_t k = 0; k < tree.mNodeCount[level]; ++k) {
      const std::uint64_t at = first[level] + k * sizeof(Node);
      const auto& node = *reinterpret_cast<const typename Node::DataType*>(begin + at);
      for (uint32_t t = 0; t < Node::SIZE; ++t) {
        if (node.mChildMask.isOn(t) && !isNode(at, node.mTable[t].child, level - 1)) return false;
      }
    }
    return true;
  };
  if (!childrenAreNodes.operator()<Upper>(2) || !childrenAreNodes.operator()<Lower>(1)) {
    return "a child offset of an internal node points outside its nodes";
  }
  return "";
}

// The largest grid a file may ask to allocate (uncompressed).
constexpr std::uint64_t kMaxGridBytes = std::uint64_t(4) << 30;

// The file's segments walked before NanoVDB's reader sees them (it trusts their sizes and
// reads grid names up to a zero byte that may not be there): every header, description, name
// and grid within the file, names terminated, sizes that agree with the codec.
std::string containerProblem(const std::string& bytes) {
  namespace io = nanovdb::io;
  const std::uint64_t size = bytes.size();
  std::uint64_t at = 0;
  while (at < size) {
    io::Header header;
    if (size - at < sizeof header) return "a segment header is cut short";
    std::memcpy(&header, bytes.data() + at, sizeof header);
    at += sizeof header;
    if (header.magic != NANOVDB_MAGIC_NUMBER) return "";  // NanoVDB's reader says what it is
    if (header.version.getMajor() != NANOVDB_MAJOR_VERSION_NUMBER) {
      return "written by NanoVDB " + std::to_string(header.version.getMajor()) + "." +
             std::to_string(header.version.getMinor()) + "; this renderer reads the files of " +
             "NanoVDB " + std::to_string(NANOVDB_MAJOR_VERSION_NUMBER) + ".x";
    }
    if (header.codec != io::Codec::NONE && header.codec != io::Codec::ZIP &&
        header.codec != io::Codec::BLOSC) {
      return "a segment has an unknown compression codec";
    }
    std::vector<std::uint64_t> dataSizes;
    for (uint32_t g = 0; g < header.gridCount; ++g) {
      io::MetaData meta;
      if (size - at < sizeof meta) return "a grid's description is cut short";
      std::memcpy(&meta, bytes.data() + at, sizeof meta);
      at += sizeof meta;
      if (meta.nameSize == 0 || meta.nameSize > size - at || bytes[at + meta.nameSize - 1] != 0) {
        return "a grid's name runs past the end of the file or is not terminated";
      }
      at += meta.nameSize;
      if (meta.gridSize > kMaxGridBytes) return "a grid claims more than 4 GiB";
      if (header.codec == io::Codec::NONE && meta.fileSize != meta.gridSize) {
        return "an uncompressed grid's sizes disagree";
      }
      dataSizes.push_back(meta.fileSize);
    }
    for (std::uint64_t dataSize : dataSizes) {
      if (dataSize > size - at) return "a grid runs past the end of the file";
      if (header.codec == io::Codec::ZIP) {
        std::uint64_t packed = 0;
        if (dataSize < sizeof packed) return "a compressed grid is cut short";
        std::memcpy(&packed, bytes.data() + at, sizeof packed);
        if (packed != dataSize - sizeof packed) return "a compressed grid's sizes disagree";
      }
      at += dataSize;
    }
  }
  return "";
}

// Grid `name` of `file` (its bytes `bytes`), validated; an empty handle where the file has no
// grid of that name.
Handle readGrid(const std::filesystem::path& file, const std::string& bytes,
                const std::string& name) {
  if (const std::string problem = containerProblem(bytes); !problem.empty()) {
    throw InputError(file.string() + ": " + problem);
  }
  Handle handle;
  try {
    std::istringstream in(bytes);
    handle = nanovdb::io::readGrid<nanovdb::HostBuffer>(in, name);
  } catch (const std::exception& e) {
    throw InputError(file.string() + ": " + e.what());
  }
  if (!handle) return handle;
  const nanovdb::GridMetaData* meta = handle.gridMetaData();
  if (meta == nullptr || handle.size() < sizeof(nanovdb::GridData) ||
      meta->gridSize() > handle.size()) {
    throw InputError(file.string() + ": grid '" + name + "' is truncated");
  }
  const nanovdb::NanoGrid<float>* grid = handle.grid<float>();
  if (grid == nullptr) {
    const auto type = static_cast<uint32_t>(meta->gridType());
    throw InputError(file.string() + ": grid '" + name +
                     "' does not hold 32-bit floats (its type: " +
                     (type < static_cast<uint32_t>(nanovdb::GridType::End)
                          ? std::string(nanovdb::toStr(meta->gridType()))
                          : "unknown, number " + std::to_string(type)) +
                     ")");
  }
  std::string problem = structureProblem(*grid, std::size_t(meta->gridSize()));
  if (problem.empty()) problem = nanovdb::GridValidator<float>::check(*grid, true);
  if (!problem.empty()) {
    throw InputError(file.string() + ": grid '" + name + "' is damaged: " + problem);
  }
  if (!grid->isFogVolume() && !grid->isUnknown()) {
    throw InputError(file.string() + ": grid '" + name +
                     "' is not a fog volume (pbrt-v4 reads densities and temperatures from "
                     "fog volumes)");
  }
  return handle;
}

// The world-to-index map of `grid` as a matrix (NanoVDB's world is the medium's space).
glm::dmat4 indexFromMedium(const nanovdb::NanoGrid<float>& grid) {
  const nanovdb::Map& map = grid.map();
  glm::dmat4 inverse(1.0);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) inverse[c][r] = map.mInvMatD[3 * r + c];
  }
  glm::dmat4 translate(1.0);
  translate[3] = glm::dvec4(-map.mVecD[0], -map.mVecD[1], -map.mVecD[2], 1.0);
  return inverse * translate;
}

// The grid's bricks over the index-space box that covers the medium-space box [lo, hi] and the
// voxels its trilinear lookups there reach.
VoxelBricks bricksOf(const std::filesystem::path& file, const std::string& name,
                     const nanovdb::NanoGrid<float>& grid, const glm::dvec3& lo,
                     const glm::dvec3& hi) {
  VoxelBricks out;
  out.indexFromMedium = indexFromMedium(grid);
  out.background = grid.tree().background();
  glm::dvec3 iMin(INFINITY), iMax(-INFINITY);
  for (int corner = 0; corner < 8; ++corner) {
    const glm::dvec3 p((corner & 1) ? hi.x : lo.x, (corner & 2) ? hi.y : lo.y,
                       (corner & 4) ? hi.z : lo.z);
    const glm::dvec3 i = glm::dvec3(out.indexFromMedium * glm::dvec4(p, 1.0));
    iMin = glm::min(iMin, i);
    iMax = glm::max(iMax, i);
  }
  glm::dvec3 first = glm::floor(iMin) - 1.0, last = glm::floor(iMax) + 1.0;
  // The index box of the grid's values; beyond it every value is the background or a tile's.
  const double limit = 1 << 30;
  for (int a = 0; a < 3; ++a) {
    if (!(first[a] >= -limit && last[a] <= limit)) {
      throw InputError(file.string() + ": grid '" + name +
                       "': its bounds reach beyond 2^30 voxels from the origin");
    }
  }
  const glm::ivec3 origin = glm::ivec3(glm::floor(first / 8.0)) * 8;
  const glm::ivec3 end = glm::ivec3(glm::floor(last / 8.0)) * 8 + 8;
  const glm::ivec3 bricks = (end - origin) / 8;
  if (double(bricks.x) * double(bricks.y) * double(bricks.z) > kMaxBricks) {
    throw InputError(file.string() + ": grid '" + name + "' covers " + std::to_string(bricks.x) +
                     " x " + std::to_string(bricks.y) + " x " + std::to_string(bricks.z) +
                     " bricks of 8^3 voxels, more than this renderer holds");
  }
  out.origin = origin;
  out.bricks = glm::uvec3(bricks);
  out.map.assign(std::size_t(bricks.x) * std::size_t(bricks.y) * std::size_t(bricks.z), 0u);

  // The leaves by brick.
  const auto& tree = grid.tree();
  std::unordered_map<std::size_t, const nanovdb::NanoLeaf<float>*> leaves;
  const nanovdb::NanoLeaf<float>* leaf = tree.getFirstLeaf();
  const auto brickIndex = [&](const nanovdb::Coord& c) -> std::optional<std::size_t> {
    const glm::ivec3 b = (glm::ivec3(c[0], c[1], c[2]) - origin) >> 3;
    if (glm::any(glm::lessThan(b, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(b, bricks))) {
      return std::nullopt;
    }
    return (std::size_t(b.z) * std::size_t(bricks.y) + std::size_t(b.y)) * std::size_t(bricks.x) +
           std::size_t(b.x);
  };
  for (uint32_t i = 0; i < tree.nodeCount(0); ++i) {
    if (auto index = brickIndex(leaf[i].origin())) leaves.emplace(*index, &leaf[i]);
  }
  std::unordered_map<float, uint32_t> constants;
  auto accessor = grid.getAccessor();
  for (int bz = 0; bz < bricks.z; ++bz) {
    for (int by = 0; by < bricks.y; ++by) {
      for (int bx = 0; bx < bricks.x; ++bx) {
        const std::size_t index =
            (std::size_t(bz) * std::size_t(bricks.y) + std::size_t(by)) * std::size_t(bricks.x) +
            std::size_t(bx);
        const glm::ivec3 corner = origin + 8 * glm::ivec3(bx, by, bz);
        const auto found = leaves.find(index);
        if (found == leaves.end()) {
          // No leaf: the whole brick lies in one tile (or the background).
          const float v = accessor.getValue(nanovdb::Coord(corner.x, corner.y, corner.z));
          const auto [it, added] = constants.emplace(v, uint32_t(out.constants.size()));
          if (added) out.constants.push_back(v);
          out.map[index] = kConstantBrick | it->second;
          continue;
        }
        out.map[index] = uint32_t(out.values.size() / kBrickVoxels);
        // NanoVDB's leaf order is z fastest; the brick's is x fastest.
        for (uint32_t z = 0; z < 8; ++z) {
          for (uint32_t y = 0; y < 8; ++y) {
            for (uint32_t x = 0; x < 8; ++x) {
              out.values.push_back(found->second->getValue((x << 6) | (y << 3) | z));
            }
          }
        }
      }
    }
  }
  return out;
}

}  // namespace

NanoVdbMediumGrids readNanoVdbMedium(const std::filesystem::path& file,
                                     const std::string& densityName,
                                     const std::string& temperatureName) {
  std::string bytes;
  {
    std::ifstream in(file, std::ios::binary);
    if (!in) {
      throw InputError(file.string() + ": Unable to open file named \"" + file.string() +
                       "\" for input");
    }
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    if (in.bad()) throw InputError(file.string() + ": could not be read");
  }
  const Handle density = readGrid(file, bytes, densityName);
  if (!density) {
    throw InputError(file.string() + ": no grid named '" + densityName + "'");
  }
  const Handle temperature = readGrid(file, bytes, temperatureName);
  NanoVdbMediumGrids out;
  const auto unite = [&](const nanovdb::NanoGrid<float>& g) {
    const auto& box = g.worldBBox();
    for (int a = 0; a < 3; ++a) {
      out.boundsMin[a] = std::min(out.boundsMin[a], box.min()[a]);
      out.boundsMax[a] = std::max(out.boundsMax[a], box.max()[a]);
    }
  };
  out.boundsMin = glm::dvec3(INFINITY);
  out.boundsMax = glm::dvec3(-INFINITY);
  unite(*density.grid<float>());
  if (temperature) unite(*temperature.grid<float>());
  for (int a = 0; a < 3; ++a) {
    if (!(out.boundsMin[a] < out.boundsMax[a]) || !std::isfinite(out.boundsMin[a]) ||
        !std::isfinite(out.boundsMax[a])) {
      throw InputError(file.string() + ": grid '" + densityName +
                       "' has empty or infinite bounds (no active voxels?)");
    }
  }
  out.density = bricksOf(file, densityName, *density.grid<float>(), out.boundsMin, out.boundsMax);
  // Densities scale probabilities: non-negative and finite, as every medium's coefficients.
  const auto check = [&](const std::string& name, const VoxelBricks& g, bool negativeToo) {
    const auto bad = [&](float v) { return !std::isfinite(v) || (negativeToo && v < 0.0f); };
    float worst = g.background;
    for (float v : g.values) worst = bad(v) ? v : worst;
    for (float v : g.constants) worst = bad(v) ? v : worst;
    if (bad(worst)) {
      throw InputError(file.string() + ": grid '" + name + "' holds " + std::to_string(worst) +
                       (negativeToo ? " (densities must be non-negative and finite)"
                                    : " (temperatures must be finite)"));
    }
  };
  check(densityName, out.density, true);
  if (temperature) {
    out.temperature =
        bricksOf(file, temperatureName, *temperature.grid<float>(), out.boundsMin, out.boundsMax);
    check(temperatureName, *out.temperature, false);
    float lo = INFINITY, hi = -INFINITY;
    for (float v : out.temperature->values) lo = std::min(lo, v), hi = std::max(hi, v);
    for (float v : out.temperature->constants) lo = std::min(lo, v), hi = std::max(hi, v);
    lo = std::min(lo, out.temperature->background);
    hi = std::max(hi, out.temperature->background);
    out.temperatureMin = lo;
    out.temperatureMax = hi;
  }
  return out;
}

}  // namespace pt
