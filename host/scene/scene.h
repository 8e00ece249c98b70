// The scene as loaded from JSON: camera, materials and a flat triangle list in load order.
// Knows nothing of BVHs or Vulkan; the BVH builder reorders the triangles later.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "common/shared.h"

namespace pt {

// The camera as the user describes it; makeCamera turns it into the GPU struct.
struct CameraDesc {
  vec3 position{0.0f, 0.0f, 0.0f};
  vec3 target{0.0f, 0.0f, 1.0f};
  vec3 up{0.0f, 1.0f, 0.0f};
  float vfovDegrees = 45.0f;
  int width = 256;
  int height = 256;
};

// Integrator settings from the scene's "integrator" object (command-line flags override).
struct IntegratorSettings {
  int spp = 16;
  int maxDepth = 64;  // maximum number of scattering events on a path
  uint seed = 0;
  bool russianRoulette = true;
  int rrStartDepth = 3;  // Russian roulette from this many scattering events on
  uint strategy = kStrategyMis;
  uint sampler = kSamplerSobol;  // see docs/accuracy.md for what it buys
};

struct Scene {
  CameraDesc camera;
  IntegratorSettings integrator;
  std::vector<Material> materials;
  std::vector<std::string> materialNames;  // parallel to materials
  // Triangles in load order; Triangle::primitive is the index in this vector and
  // Triangle::emitter is kNoEmitter until buildEmitters assigns it.
  std::vector<Triangle> triangles;
  // Vertex normals per triangle, parallel to `triangles`, or empty when no mesh has normals
  // (triangles of meshes without them then repeat their geometric normal).
  std::vector<TriangleNormals> normals;
  std::vector<std::string> warnings;  // e.g. dropped zero-area triangles, one line each
};

// Reads a scene file. Throws InputError with "<file>: <field or line>: <message>" for
// anything malformed (see docs/scene-format.md). Mesh paths are relative to the JSON file.
Scene loadScene(const std::filesystem::path& path);

// A material of type `type` (kMaterial*) with the defaults of docs/scene-format.md (pbrt-v4's,
// for the types taken from pbrt-v4) and no emission. The JSON reader and the MTL mapping both
// start from it, so that a default is written in one place.
Material defaultMaterial(uint type);

// Makes `material` pbrt-v4's conductor of the given reflectance colour (its
// ConductorMaterial::GetBxDF): eta = 1 and k = 2 sqrt(r) / sqrt(1 - r) per channel, with r
// clamped to [0, 0.9999] so that white stays finite.
void setConductorReflectance(Material& material, vec3 reflectance);

// pbrt-v4's "roughness", "uroughness" and "vroughness" as a material stores them: Trowbridge-
// Reitz alphas, mapped by RoughnessToAlpha (alpha = sqrt(roughness)) when `remap` (pbrt-v4's
// "remaproughness", true by default). The JSON and pbrt readers both call it.
void setRoughness(Material& material, float uRoughness, float vRoughness, bool remap);

// diffusetransmission's "scale" as pbrt-v4 applies it: both colours scaled and the products
// clamped to [0, 1].
void scaleDiffuseTransmission(Material& material, float scale);

// The most random-walk steps or walks a coated material may ask for per evaluation: far more
// than pbrt-v4's defaults (10 and 1) need, and small enough that one evaluation stays short.
inline constexpr std::int64_t kMaxCoatedWalk = 1000;

// cos and sin of an angle in degrees, exact for multiples of 90 degrees so that axis-aligned
// geometry stays exactly axis-aligned (cos(radians(90)) is 6e-17, not 0). Both scene readers
// rotate with it.
std::pair<double, double> cosSinDegrees(double degrees);

// Builds the GPU camera for a film of width x height pixels.
Camera makeCamera(const CameraDesc& desc, int width, int height);

}  // namespace pt
