// The scene as loaded from JSON: camera, materials and a flat triangle list in load order.
// Knows nothing of BVHs or Vulkan; the BVH builder reorders the triangles later.
#pragma once

#include <filesystem>
#include <string>
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
  std::vector<std::string> warnings;  // e.g. dropped zero-area triangles, one line each
};

// Reads a scene file. Throws InputError with "<file>: <field or line>: <message>" for
// anything malformed (see docs/scene-format.md). Mesh paths are relative to the JSON file.
Scene loadScene(const std::filesystem::path& path);

// Builds the GPU camera for a film of width x height pixels.
Camera makeCamera(const CameraDesc& desc, int width, int height);

}  // namespace pt
