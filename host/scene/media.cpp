// The media helpers both readers share (media.h): pbrt-v4's presets, the checks, the storage.
#include "scene/media.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <glm/matrix.hpp>

#include "common/check.h"
#include "noise_permutation.h"
#include "scene/json_reader.h"
#include "scene/pbrt/spectra.h"
#include "scene/voxel_grid.h"

namespace pt {

namespace {

// name, sigma'_s, sigma_a (RGB, per mm), as pbrt-v4's media.cpp lists them.
const MediumPreset kPresets[] = {
    // Jensen, Marschner, Levoy and Hanrahan, "A Practical Model for Subsurface Light
    // Transport", SIGGRAPH 2001.
    {"Apple", {2.29f, 2.39f, 1.97f}, {0.0030f, 0.0034f, 0.046f}},
    {"Chicken1", {0.15f, 0.21f, 0.38f}, {0.015f, 0.077f, 0.19f}},
    {"Chicken2", {0.19f, 0.25f, 0.32f}, {0.018f, 0.088f, 0.20f}},
    {"Cream", {7.38f, 5.47f, 3.15f}, {0.0002f, 0.0028f, 0.0163f}},
    {"Ketchup", {0.18f, 0.07f, 0.03f}, {0.061f, 0.97f, 1.45f}},
    {"Marble", {2.19f, 2.62f, 3.00f}, {0.0021f, 0.0041f, 0.0071f}},
    {"Potato", {0.68f, 0.70f, 0.55f}, {0.0024f, 0.0090f, 0.12f}},
    {"Skimmilk", {0.70f, 1.22f, 1.90f}, {0.0014f, 0.0025f, 0.0142f}},
    {"Skin1", {0.74f, 0.88f, 1.01f}, {0.032f, 0.17f, 0.48f}},
    {"Skin2", {1.09f, 1.59f, 1.79f}, {0.013f, 0.070f, 0.145f}},
    {"Spectralon", {11.6f, 20.4f, 14.9f}, {0.00f, 0.00f, 0.00f}},
    {"Wholemilk", {2.55f, 3.21f, 3.77f}, {0.0011f, 0.0024f, 0.014f}},
    // Narasimhan, Gupta, Donner, Ramamoorthi, Nayar and Jensen, "Acquiring Scattering
    // Properties of Participating Media by Dilution", SIGGRAPH 2006.
    {"Lowfat Milk", {0.89187f, 1.5136f, 2.532f}, {0.002875f, 0.00575f, 0.0115f}},
    {"Reduced Milk", {2.4858f, 3.1669f, 4.5214f}, {0.0025556f, 0.0051111f, 0.012778f}},
    {"Regular Milk", {4.5513f, 5.8294f, 7.136f}, {0.0015333f, 0.0046f, 0.019933f}},
    {"Espresso", {0.72378f, 0.84557f, 1.0247f}, {4.7984f, 6.5751f, 8.8493f}},
    {"Mint Mocha Coffee", {0.31602f, 0.38538f, 0.48131f}, {3.772f, 5.8228f, 7.82f}},
    {"Lowfat Soy Milk", {0.30576f, 0.34233f, 0.61664f}, {0.0014375f, 0.0071875f, 0.035937f}},
    {"Regular Soy Milk", {0.59223f, 0.73866f, 1.4693f}, {0.0019167f, 0.0095833f, 0.065167f}},
    {"Lowfat Chocolate Milk", {0.64925f, 0.83916f, 1.1057f}, {0.0115f, 0.0368f, 0.1564f}},
    {"Regular Chocolate Milk", {1.4585f, 2.1289f, 2.9527f}, {0.010063f, 0.043125f, 0.14375f}},
    {"Coke", {8.9053e-05f, 8.372e-05f, 0.0f}, {0.10014f, 0.16503f, 0.2468f}},
    {"Pepsi", {6.1697e-05f, 4.2564e-05f, 0.0f}, {0.091641f, 0.14158f, 0.20729f}},
    {"Sprite", {6.0306e-06f, 6.4139e-06f, 6.5504e-06f}, {0.001886f, 0.0018308f, 0.0020025f}},
    {"Gatorade", {0.0024574f, 0.003007f, 0.0037325f}, {0.024794f, 0.019289f, 0.008878f}},
    {"Chardonnay", {1.7982e-05f, 1.3758e-05f, 1.2023e-05f}, {0.010782f, 0.011855f, 0.023997f}},
    {"White Zinfandel", {1.7501e-05f, 1.9069e-05f, 1.288e-05f}, {0.012072f, 0.016184f, 0.019843f}},
    {"Merlot", {2.1129e-05f, 0.0f, 0.0f}, {0.11632f, 0.25191f, 0.29434f}},
    {"Budweiser Beer", {2.4356e-05f, 2.4079e-05f, 1.0564e-05f}, {0.011492f, 0.024911f, 0.057786f}},
    {"Coors Light Beer", {5.0922e-05f, 4.301e-05f, 0.0f}, {0.006164f, 0.013984f, 0.034983f}},
    {"Clorox", {0.0024035f, 0.0031373f, 0.003991f}, {0.0033542f, 0.014892f, 0.026297f}},
    {"Apple Juice", {0.00013612f, 0.00015836f, 0.000227f}, {0.012957f, 0.023741f, 0.052184f}},
    {"Cranberry Juice", {0.00010402f, 0.00011646f, 7.8139e-05f}, {0.039437f, 0.094223f, 0.12426f}},
    {"Grape Juice", {5.382e-05f, 0.0f, 0.0f}, {0.10404f, 0.23958f, 0.29325f}},
    {"Ruby Grapefruit Juice", {0.011002f, 0.010927f, 0.011036f}, {0.085867f, 0.18314f, 0.25262f}},
    {"White Grapefruit Juice", {0.22826f, 0.23998f, 0.32748f}, {0.0138f, 0.018831f, 0.056781f}},
    {"Shampoo", {0.0007176f, 0.0008303f, 0.0009016f}, {0.014107f, 0.045693f, 0.061717f}},
    {"Strawberry Shampoo", {0.00015671f, 0.00015947f, 1.518e-05f}, {0.01449f, 0.05796f, 0.075823f}},
    {"Head & Shoulders Shampoo",
     {0.023805f, 0.028804f, 0.034306f},
     {0.084621f, 0.15688f, 0.20365f}},
    {"Lemon Tea Powder", {0.040224f, 0.045264f, 0.051081f}, {2.4288f, 4.5757f, 7.2127f}},
    {"Orange Powder", {0.00015617f, 0.00017482f, 0.0001762f}, {0.001449f, 0.003441f, 0.007863f}},
    {"Pink Lemonade Powder",
     {0.00012103f, 0.00013073f, 0.00012528f},
     {0.001165f, 0.002366f, 0.003195f}},
    {"Cappuccino Powder", {1.8436f, 2.5851f, 2.1662f}, {35.844f, 49.547f, 61.084f}},
    {"Salt Powder", {0.027333f, 0.032451f, 0.031979f}, {0.28415f, 0.3257f, 0.34148f}},
    {"Sugar Powder", {0.00022272f, 0.00025513f, 0.000271f}, {0.012638f, 0.031051f, 0.050124f}},
    {"Suisse Mocha Powder", {2.7979f, 3.5452f, 4.3365f}, {17.502f, 27.004f, 35.433f}},
    {"Pacific Ocean Surface Water",
     {0.0001764f, 0.00032095f, 0.00019617f},
     {0.031845f, 0.031324f, 0.030147f}},
};

constexpr double kFloatMax = static_cast<double>(std::numeric_limits<float>::max());

bool fitsFloat(double v) {
  return std::fabs(v) <= kFloatMax;
}

std::string number(double v) {
  return scene_detail::formatNumber(v);
}

std::string point(const glm::dvec3& p) {
  return "(" + number(p.x) + ", " + number(p.y) + ", " + number(p.z) + ")";
}

std::optional<MediumProblem> problem(std::string param, std::string message,
                                     std::optional<std::size_t> index = std::nullopt) {
  return MediumProblem{std::move(param), index, std::move(message)};
}

// A colour or a scale: each component non-negative and finite.
std::optional<MediumProblem> checkNonNegative(const char* param, const double* values,
                                              std::size_t count) {
  for (std::size_t i = 0; i < count; ++i) {
    if (!(values[i] >= 0.0) || !fitsFloat(values[i])) {
      return problem(
          param,
          "expected a non-negative number that fits a 32-bit float, got " + number(values[i]),
          count > 1 ? std::optional<std::size_t>(i) : std::nullopt);
    }
  }
  return std::nullopt;
}

std::optional<MediumProblem> checkColour(const char* param, vec3 c) {
  const double v[3] = {c.x, c.y, c.z};
  return checkNonNegative(param, v, 3);
}

// `values` times `scale` (both checked non-negative) within 32-bit floats.
std::optional<MediumProblem> checkScaled(const char* param, const char* scaleName, double max,
                                         double scale) {
  if (!fitsFloat(max * scale)) {
    return problem(scaleName, std::string("'") + param + "' times '" + scaleName +
                                  "' does not fit a 32-bit float");
  }
  return std::nullopt;
}

// A grid of `perVoxel` floats per voxel: none (when allowed), or one value per voxel, each
// finite and (unless `signedValues`) non-negative.
std::optional<MediumProblem> checkGrid(const char* param, const std::vector<float>& grid,
                                       std::size_t perVoxel, double voxels,
                                       bool signedValues = false) {
  if (grid.empty()) return std::nullopt;
  const char* what = perVoxel == 3 ? " RGB value" : " value";
  if (grid.size() % perVoxel != 0) {
    return problem(param, "has " + std::to_string(grid.size()) + " numbers, not RGB triples");
  }
  const std::size_t count = grid.size() / perVoxel;
  if (static_cast<double>(count) != voxels) {
    return problem(param, "has " + std::to_string(count) + what + (count == 1 ? "" : "s") +
                              "; expected nx * ny * nz = " + number(voxels));
  }
  for (std::size_t i = 0; i < grid.size(); ++i) {
    if (!std::isfinite(grid[i]) || (!signedValues && !(grid[i] >= 0.0f))) {
      return problem(
          param,
          std::string(signedValues ? "expected a number" : "expected a non-negative number") +
              " that fits a 32-bit float, got " + number(grid[i]),
          i);
    }
  }
  return std::nullopt;
}

// "temperatureoffset" and "temperaturescale" (nanovdb, a uniformgrid with temperatures).
std::optional<MediumProblem> checkTemperatureMapping(const MediumParams& m) {
  for (const auto& [name, v] : {std::pair{"temperatureoffset", m.temperatureOffset},
                                std::pair{"temperaturescale", m.temperatureScale}}) {
    if (!fitsFloat(v)) return problem(name, "expected a number that fits a 32-bit float");
  }
  return std::nullopt;
}

// A uniformgrid's temperature grid: one finite value per voxel (kelvin; those the offset and
// scale take to 100 K or below emit nothing), without "Le" (pbrt-v4's rule), and the offset
// and scale within 32-bit floats.
std::optional<MediumProblem> checkTemperatures(const MediumParams& m, double voxels) {
  if (m.temperature.empty()) return std::nullopt;
  if (maxComponent(m.Le) > 0.0f) {
    return problem("temperature",
                   "a medium emits by \"Le\" or by \"temperature\", not both "
                   "(pbrt-v4's rule)");
  }
  if (auto p = checkGrid("temperature", m.temperature, 1, voxels, /*signedValues=*/true)) return p;
  return checkTemperatureMapping(m);
}

// The hottest temperature of a grid whose values lie in [lo, hi] once offset and scaled
// (pbrt-v4 emits above 100 K).
double hottestKelvin(double lo, double hi, const MediumParams& m) {
  return std::max((lo - m.temperatureOffset) * m.temperatureScale,
                  (hi - m.temperatureOffset) * m.temperatureScale);
}

float gridMax(const std::vector<float>& grid) {
  float m = 0.0f;
  for (float v : grid) m = std::max(m, v);
  return m;
}

// Appends floats to the scene's grid buffer, returning the offset of the first.
uint appendGrid(Scene& scene, const std::vector<float>& values) {
  const std::size_t offset = scene.mediumGrids.size();
  PT_CHECK(offset + values.size() < static_cast<std::size_t>(kNoGrid),
           "medium grids beyond 32-bit offsets");
  scene.mediumGrids.insert(scene.mediumGrids.end(), values.begin(), values.end());
  return static_cast<uint>(offset);
}

// An RGB grid scaled, or `count` voxels of `scale` where the grid is missing.
std::vector<float> scaledRgbGrid(const std::vector<float>& grid, double scale, std::size_t count) {
  std::vector<float> out(3 * count, static_cast<float>(scale));
  if (!grid.empty()) {
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = static_cast<float>(grid[i] * scale);
  }
  return out;
}

// The blackbody table of a nanovdb medium whose temperatures reach `hottest` kelvin
// (shared_types.h): pbrt-v4's BlackbodySpectrum (Planck's law divided by its peak) as linear
// sRGB as its film records it: pbrt-v4 normalizes a light's spectrum to luminance 1 (and an
// emissive medium's Le), but not this one, and its film sums the matching functions times the
// radiance without dividing by the integral of y-bar (106.86): XYZ = sum of x-bar, y-bar,
// z-bar times the spectrum, per nanometre.
std::vector<float> blackbodyTable(double hottest) {
  std::vector<float> table(kBlackbodyTableFloats);
  table[0] = static_cast<float>(hottest);
  const double top = double(table[0]);
  for (uint i = 0; i < kBlackbodyEntries; ++i) {
    const double kelvin = 100.0 + (top - 100.0) * double(i) / double(kBlackbodyEntries - 1);
    const glm::dvec3 rgb = spectra::xyzToLinearSrgb() * spectra::toXyz(spectra::blackbody(kelvin)) *
                           spectra::cieYIntegral();
    for (int c = 0; c < 3; ++c) table[1 + 3 * i + uint(c)] = static_cast<float>(rgb[c]);
  }
  return table;
}

}  // namespace

const MediumPreset* findMediumPreset(std::string_view name) {
  for (const MediumPreset& p : kPresets) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

std::vector<std::string_view> mediumPresetNames() {
  std::vector<std::string_view> names;
  for (const MediumPreset& p : kPresets) names.push_back(p.name);
  return names;
}

std::optional<MediumProblem> checkMedium(const MediumParams& m) {
  if (auto p = checkColour("sigma_a", m.sigmaA)) return p;
  if (auto p = checkColour("sigma_s", m.sigmaS)) return p;
  if (auto p = checkNonNegative("scale", &m.scale, 1)) return p;
  if (!(m.g >= -1.0 && m.g <= 1.0)) {
    return problem("g", "expected a number in [-1, 1], got " + number(m.g));
  }
  if (auto p = checkColour("Le", m.Le)) return p;
  if (auto p = checkNonNegative("Lescale", &m.LeScale, 1)) return p;
  if (m.type != kMediumRgbGrid) {
    if (auto p = checkScaled("sigma_a", "scale", maxComponent(m.sigmaA), m.scale)) return p;
    if (auto p = checkScaled("sigma_s", "scale", maxComponent(m.sigmaS), m.scale)) return p;
  }
  if (m.type == kMediumHomogeneous) {
    return checkScaled("Le", "Lescale", maxComponent(m.Le), m.LeScale);
  }
  if (m.type == kMediumNanoVdb) {
    PT_CHECK(m.nanovdb != nullptr, "checkMedium: a nanovdb medium without its grids");
    return checkTemperatureMapping(m);
  }
  if (m.type == kMediumCloud) {
    if (auto p = checkNonNegative("density", &m.cloudDensity, 1)) return p;
    for (const auto& [name, v] :
         {std::pair{"wispiness", m.wispiness}, std::pair{"frequency", m.frequency}}) {
      if (!fitsFloat(v)) return problem(name, "expected a number that fits a 32-bit float");
    }
  }
  const std::int64_t sizes[3] = {m.nx, m.ny, m.nz};
  const char* const sizeNames[3] = {"nx", "ny", "nz"};
  for (int a = 0; a < 3; ++a) {
    if (sizes[a] < 1 || sizes[a] > std::numeric_limits<int>::max()) {
      return problem(sizeNames[a],
                     "expected a number of voxels of at least 1, got " + std::to_string(sizes[a]));
    }
  }
  // Exact below 2^53, and beyond that no grid has as many values.
  const double voxels = double(m.nx) * double(m.ny) * double(m.nz);
  if (!(m.p0.x < m.p1.x && m.p0.y < m.p1.y && m.p0.z < m.p1.z)) {
    return problem(
        "p1", "expected p0 < p1 on every axis, got p0 " + point(m.p0) + " and p1 " + point(m.p1));
  }
  for (const auto& [name, p] : {std::pair{"p0", m.p0}, std::pair{"p1", m.p1}}) {
    for (int a = 0; a < 3; ++a) {
      if (!fitsFloat(p[a])) return problem(name, "does not fit 32-bit floats: " + point(p));
    }
  }
  if (m.type == kMediumCloud) return std::nullopt;
  if (m.type == kMediumUniformGrid) {
    if (m.density.empty()) return problem("density", "is required: one value per voxel");
    if (auto p = checkGrid("density", m.density, 1, voxels)) return p;
    if (auto p = checkGrid("Lescale", m.LeScaleGrid, 1, voxels)) return p;
    return checkTemperatures(m, voxels);
  }
  PT_CHECK(m.type == kMediumRgbGrid, "checkMedium: unknown medium type");
  if (m.sigmaAGrid.empty() && m.sigmaSGrid.empty()) {
    return problem("sigma_a", "an rgbgrid needs \"sigma_a\" or \"sigma_s\" (or both)");
  }
  if (!m.LeGrid.empty() && m.sigmaAGrid.empty()) {
    return problem("Le", "an rgbgrid with \"Le\" needs \"sigma_a\" too (pbrt-v4's rule)");
  }
  if (auto p = checkGrid("sigma_a", m.sigmaAGrid, 3, voxels)) return p;
  if (auto p = checkGrid("sigma_s", m.sigmaSGrid, 3, voxels)) return p;
  if (auto p = checkGrid("Le", m.LeGrid, 3, voxels)) return p;
  if (auto p = checkScaled("sigma_a", "scale", std::max(1.0f, gridMax(m.sigmaAGrid)), m.scale)) {
    return p;
  }
  if (auto p = checkScaled("sigma_s", "scale", std::max(1.0f, gridMax(m.sigmaSGrid)), m.scale)) {
    return p;
  }
  return checkScaled("Le", "Lescale", gridMax(m.LeGrid), m.LeScale);
}

std::size_t voxelCount(const MediumParams& m) {
  return static_cast<std::size_t>(m.nx) * static_cast<std::size_t>(m.ny) *
         static_cast<std::size_t>(m.nz);
}

uint addMedium(Scene& scene, const std::string& name, const MediumParams& m) {
  Medium out{};
  out.type = m.type;
  out.g = static_cast<float>(m.g);
  out.density = kNoGrid;
  out.majorants = kNoGrid;  // prepareScene's
  out.emission = kNoGrid;
  setMediumTransform(out, glm::dmat4(1.0));
  const auto scaled = [](vec3 c, double s) { return vec3(glm::dvec3(c) * s); };
  if (m.type == kMediumHomogeneous) {
    out.sigmaA = scaled(m.sigmaA, m.scale);
    out.sigmaS = scaled(m.sigmaS, m.scale);
    out.Le = scaled(m.Le, m.LeScale);
    out.emissive = maxComponent(out.Le) > 0.0f ? kEmitsLe : kEmitsNothing;
  } else if (m.type == kMediumNanoVdb) {
    const NanoVdbMediumGrids& grids = *m.nanovdb;
    out.sigmaA = scaled(m.sigmaA, m.scale);
    out.sigmaS = scaled(m.sigmaS, m.scale);
    out.boundsMin = vec3(grids.boundsMin);
    out.boundsMax = vec3(grids.boundsMax);
    out.size = uvec3(kNanoVdbMajorantRes);
    out.Le = vec3(float(m.LeScale), float(m.temperatureOffset), float(m.temperatureScale));
    out.density = appendGrid(scene, packVoxelGrid(grids.density));
    const double hottest = hottestKelvin(grids.temperatureMin, grids.temperatureMax, m);
    if (grids.temperature && m.LeScale > 0.0 && hottest > 100.0) {
      out.emissive = kEmitsBlackbody;
      std::vector<float> emission = blackbodyTable(hottest);
      const std::vector<float> temperature = packVoxelGrid(*grids.temperature);
      emission.insert(emission.end(), temperature.begin(), temperature.end());
      out.emission = appendGrid(scene, emission);
    }
  } else if (m.type == kMediumCloud) {
    out.sigmaA = m.sigmaA;
    out.sigmaS = m.sigmaS;
    out.boundsMin = vec3(m.p0);
    out.boundsMax = vec3(m.p1);
    out.size = uvec3(1u);
    out.Le = vec3(float(m.cloudDensity), float(m.wispiness), float(m.frequency));
    std::vector<float> permutation(kNoisePermutationSize);
    for (uint i = 0; i < kNoisePermutationSize; ++i) {
      permutation[i] = glm::uintBitsToFloat(uint(kNoisePermutation[i]));
    }
    out.density = appendGrid(scene, permutation);
  } else {
    out.boundsMin = vec3(m.p0);
    out.boundsMax = vec3(m.p1);
    out.size = uvec3(uint(m.nx), uint(m.ny), uint(m.nz));
    const std::size_t voxels = voxelCount(m);
    if (m.type == kMediumUniformGrid) {
      out.sigmaA = scaled(m.sigmaA, m.scale);
      out.sigmaS = scaled(m.sigmaS, m.scale);
      out.Le = m.Le;
      out.emissive = maxComponent(m.Le) > 0.0f ? kEmitsLe : kEmitsNothing;
      out.density = appendGrid(scene, m.density);
      if (out.emissive && !m.LeScaleGrid.empty()) out.emission = appendGrid(scene, m.LeScaleGrid);
      // Emission by temperature, where some voxel is above 100 K once offset and scaled, and
      // the Lescale grid (if any) is not all zero.
      const auto [coolest, warmest] =
          std::minmax_element(m.temperature.begin(), m.temperature.end());
      const double hottest = m.temperature.empty() ? 0.0 : hottestKelvin(*coolest, *warmest, m);
      const bool scaled = m.LeScaleGrid.empty() || gridMax(m.LeScaleGrid) > 0.0f;
      if (hottest > 100.0 && scaled && fitsFloat(hottest)) {
        out.emissive = kEmitsBlackbody;
        out.Le = vec3(m.LeScaleGrid.empty() ? 0.0f : 1.0f, float(m.temperatureOffset),
                      float(m.temperatureScale));
        std::vector<float> emission = blackbodyTable(hottest);
        emission.insert(emission.end(), m.temperature.begin(), m.temperature.end());
        emission.insert(emission.end(), m.LeScaleGrid.begin(), m.LeScaleGrid.end());
        out.emission = appendGrid(scene, emission);
      }
    } else {
      out.sigmaA = vec3(1.0f);
      out.sigmaS = vec3(1.0f);
      std::vector<float> sigma = scaledRgbGrid(m.sigmaAGrid, m.scale, voxels);
      const std::vector<float> sigmaS = scaledRgbGrid(m.sigmaSGrid, m.scale, voxels);
      sigma.insert(sigma.end(), sigmaS.begin(), sigmaS.end());
      out.density = appendGrid(scene, sigma);
      out.emissive = !m.LeGrid.empty() && m.LeScale > 0.0 ? kEmitsLe : kEmitsNothing;
      if (out.emissive) {
        out.Le = vec3(1.0f);
        out.emission = appendGrid(scene, scaledRgbGrid(m.LeGrid, m.LeScale, voxels));
      }
    }
  }
  scene.media.push_back(out);
  scene.mediumNames.push_back(name);
  return static_cast<uint>(scene.media.size() - 1);
}

void setMediumTransform(Medium& m, const glm::dmat4& mediumFromWorld) {
  vec4* rows[3] = {&m.toMedium0, &m.toMedium1, &m.toMedium2};
  for (int i = 0; i < 3; ++i) {
    // glm indexes [column][row].
    *rows[i] = vec4(glm::dvec4(mediumFromWorld[0][i], mediumFromWorld[1][i], mediumFromWorld[2][i],
                               mediumFromWorld[3][i]));
  }
}

std::size_t densityFloats(const Medium& m, const std::vector<float>& grids) {
  const std::size_t voxels = std::size_t(m.size.x) * m.size.y * m.size.z;
  if (m.type == kMediumUniformGrid) return voxels;
  if (m.type == kMediumRgbGrid) return 6 * voxels;
  if (m.type == kMediumNanoVdb) return packedVoxelGridFloats(grids.data() + m.density);
  if (m.type == kMediumCloud) return kNoisePermutationSize;
  return 0;
}

std::size_t emissionFloats(const Medium& m, const std::vector<float>& grids) {
  if (m.emission == kNoGrid) return 0;
  if (m.type == kMediumNanoVdb) {
    return kBlackbodyTableFloats +
           packedVoxelGridFloats(grids.data() + m.emission + kBlackbodyTableFloats);
  }
  const std::size_t voxels = std::size_t(m.size.x) * m.size.y * m.size.z;
  if (m.emissive == kEmitsBlackbody) {
    return kBlackbodyTableFloats + (m.Le.x == 0.0f ? voxels : 2 * voxels);
  }
  return m.type == kMediumRgbGrid ? 3 * voxels : voxels;
}

void keepUsedMedia(Scene& scene) {
  PT_CHECK(
      scene.mediumInterfaces.empty() || scene.mediumInterfaces.size() == scene.triangles.size(),
      "medium interfaces not parallel to the triangles");
  std::vector<bool> used(scene.media.size(), false);
  const auto mark = [&](uint m) {
    if (m != kNoMedium) used.at(m) = true;
  };
  for (const MediumInterface& mi : scene.mediumInterfaces) {
    mark(mi.inside);
    mark(mi.outside);
  }
  mark(scene.cameraMedium);
  std::vector<uint> remap(scene.media.size(), kNoMedium);
  std::vector<Medium> media;
  std::vector<std::string> names;
  std::vector<float> grids;
  for (std::size_t i = 0; i < scene.media.size(); ++i) {
    if (!used[i]) continue;
    remap[i] = static_cast<uint>(media.size());
    Medium m = scene.media[i];
    const auto move = [&](uint& offset, std::size_t count) {
      if (offset == kNoGrid) return;
      const auto first = scene.mediumGrids.begin() + std::ptrdiff_t(offset);
      offset = static_cast<uint>(grids.size());
      grids.insert(grids.end(), first, first + std::ptrdiff_t(count));
    };
    move(m.density, densityFloats(m, scene.mediumGrids));
    move(m.emission, emissionFloats(m, scene.mediumGrids));
    media.push_back(m);
    names.push_back(scene.mediumNames[i]);
  }
  if (media.empty()) {
    scene.mediumInterfaces.clear();
  } else {
    for (MediumInterface& mi : scene.mediumInterfaces) {
      if (mi.inside != kNoMedium) mi.inside = remap[mi.inside];
      if (mi.outside != kNoMedium) mi.outside = remap[mi.outside];
    }
  }
  if (scene.cameraMedium != kNoMedium) scene.cameraMedium = remap[scene.cameraMedium];
  scene.media = std::move(media);
  scene.mediumNames = std::move(names);
  scene.mediumGrids = std::move(grids);
}

}  // namespace pt
