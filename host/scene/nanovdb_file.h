// NanoVDB files (.nvdb) for pbrt-v4's "nanovdb" medium, read with NanoVDB's own reader
// (Debian's libnanovdb-dev) and turned into the renderer's sparse voxel grids (voxel_grid.h).
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include <glm/vec3.hpp>

#include "scene/voxel_grid.h"

namespace pt {

// The grids a nanovdb medium reads from one file, in the medium's space.
struct NanoVdbMediumGrids {
  VoxelBricks density;
  std::optional<VoxelBricks> temperature;  // where the file has a grid of that name
  // pbrt-v4's bounds: the density grid's world bounding box, united with the temperature
  // grid's (NanoVDB's "world" is the medium's space).
  glm::dvec3 boundsMin{0.0}, boundsMax{0.0};
  // The smallest and largest value of the temperature grid within the bounds (0 without one).
  float temperatureMin = 0.0f, temperatureMax = 0.0f;
};

// Reads the float grids named `densityName` (required) and `temperatureName` (optional) of
// `file`. Each must be a fog volume (or of unknown class), as pbrt-v4 requires, with 32-bit
// float values, and pass NanoVDB's validation (checksum, node offsets). Throws InputError
// "<file>: <problem>".
NanoVdbMediumGrids readNanoVdbMedium(const std::filesystem::path& file,
                                     const std::string& densityName,
                                     const std::string& temperatureName);

}  // namespace pt
