// What both scene readers share about participating media (shaders/shared_types.h, Medium):
// pbrt-v4's named measured media, the checks of a medium's parameters, storing a medium and its
// grids in the Scene, and keeping only the media something uses. Reading the parameters is each
// reader's (scene/pbrt/pbrt_media.cpp, scene/json_media.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "common/shared.h"
#include "scene/nanovdb_file.h"
#include "scene/scene.h"

namespace pt {

// pbrt-v4's table of measured media (its GetMediumScatteringProperties: Jensen et al. 2001,
// Narasimhan et al. 2006): the reduced scattering coefficient sigma'_s and the absorption
// sigma_a, RGB, as published (per millimetre). pbrt-v4 takes sigma'_s as sigma_s and both per
// unit of scene distance without conversion ("scale" converts); so does this renderer.
struct MediumPreset {
  std::string_view name;
  vec3 sigmaPrimeS;
  vec3 sigmaA;
};
const MediumPreset* findMediumPreset(std::string_view name);
std::vector<std::string_view> mediumPresetNames();

// A medium's parameters under pbrt-v4's names and with its defaults (media.cpp, the Create
// functions), as either reader gives them. Colours are linear RGB: a pbrt file's spectra are
// already their RGB (Le a light's colour at luminance 1, as pbrt-v4 normalizes it).
struct MediumParams {
  uint type = kMediumHomogeneous;  // kMedium*
  vec3 sigmaA{1.0f};               // homogeneous, uniformgrid: "sigma_a" (before "scale")
  vec3 sigmaS{1.0f};               // "sigma_s"
  double scale = 1.0;              // "scale" of sigma_a and sigma_s
  double g = 0.0;                  // Henyey-Greenstein asymmetry
  vec3 Le{0.0f};                   // homogeneous, uniformgrid: "Le"
  double LeScale = 1.0;            // homogeneous, rgbgrid, nanovdb: "Lescale"
  // Grids: voxels along x, y and z, and the bounds p0, p1 they fill in the medium's space. Every
  // grid is pbrt-v4's SampledGrid order, x fastest: voxel (x, y, z) is value (z * ny + y) * nx + x
  // (for RGB grids, three floats each).
  std::int64_t nx = 1, ny = 1, nz = 1;
  glm::dvec3 p0{0.0}, p1{1.0};
  std::vector<float> density;      // uniformgrid: "density", one per voxel
  std::vector<float> LeScaleGrid;  // uniformgrid: "Lescale", one per voxel, or none
  std::vector<float> temperature;  // uniformgrid: "temperature" in kelvin, one per voxel, or none
  std::vector<float> sigmaAGrid;   // rgbgrid: "sigma_a", RGB per voxel, or none
  std::vector<float> sigmaSGrid;   // rgbgrid: "sigma_s", likewise
  std::vector<float> LeGrid;       // rgbgrid: "Le", likewise
  // nanovdb: the grids of its "filename" (read by the reader, which knows where the file is),
  // and its emission: Lescale times the blackbody at (T - temperatureoffset) *
  // temperaturescale, T the temperature grid's value (a uniformgrid's with "temperature"
  // likewise, its Lescale a grid).
  std::shared_ptr<const NanoVdbMediumGrids> nanovdb;
  double temperatureOffset = 0.0;  // "temperatureoffset" (or pbrt-v4's "temperaturecutoff")
  double temperatureScale = 1.0;   // "temperaturescale"
  // cloud (bounds p0, p1): "density", "wispiness", "frequency".
  double cloudDensity = 1.0;
  double wispiness = 1.0;
  double frequency = 5.0;
};

// What is wrong with a medium: the parameter at fault (pbrt-v4's name), the index of the value
// at fault within it where one is, and the problem, a clause for the reader's message.
struct MediumProblem {
  std::string param;
  std::optional<std::size_t> index;
  std::string message;
};

// The first problem of `m`, or none: coefficients, scales and grid values non-negative and
// finite (also once scaled, in 32-bit floats), g in [-1, 1], nx, ny, nz at least 1, grid sizes
// nx * ny * nz (RGB grids three times that), p0 < p1, and pbrt-v4's rules on which grids go
// together. Both readers call it, each naming the parameter its own way.
std::optional<MediumProblem> checkMedium(const MediumParams& m);

// The number of voxels nx * ny * nz of a checked medium.
std::size_t voxelCount(const MediumParams& m);

// Appends a checked medium to scene.media (with `name` to scene.mediumNames) and its grids to
// scene.mediumGrids, returning its index. Scales are applied: sigmaA and sigmaS hold sigma_a and
// sigma_s times "scale", Le holds Le times "Lescale" (homogeneous). An rgbgrid has its scale
// and Lescale multiplied into its grids, so that its sigmaA, sigmaS and Le are 1 (where the
// transport multiplies the grid by them, and where it does not, the values are the same); a
// missing sigma_a or sigma_s grid is stored as ones (pbrt-v4's constant 1). A uniformgrid's
// Lescale grid is its emission grid, none without one; grids of a medium that does not emit
// are not stored. A nanovdb medium's grids are packed (voxel_grid.h), its emission a blackbody
// table over the temperatures its grid reaches and the grid; a uniformgrid's temperatures
// likewise, its Lescale grid after them. The transform is identity:
// setMediumTransform sets it.
uint addMedium(Scene& scene, const std::string& name, const MediumParams& m);

// Sets medium `m`'s world-to-medium rows from the matrix that maps world to medium space
// (affine: its last row is taken as 0 0 0 1).
void setMediumTransform(Medium& m, const glm::dmat4& mediumFromWorld);

// The floats of medium `m`'s density and emission grids (0 where it has none), `grids` the
// floats they are in.
std::size_t densityFloats(const Medium& m, const std::vector<float>& grids);
std::size_t emissionFloats(const Medium& m, const std::vector<float>& grids);

// Keeps the media that some triangle's interface or the camera names, in their order, their
// grids packed in the same order, and renumbers the references. Where none is left, media,
// mediumNames, mediumGrids and mediumInterfaces are emptied and cameraMedium is kNoMedium: a
// scene without media is then exactly what it was before media existed.
void keepUsedMedia(Scene& scene);

}  // namespace pt
