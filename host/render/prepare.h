// Scene -> the flat arrays both backends read: the BVH (nodes, triangles in leaf order),
// materials, the emitter alias table and the per-render parameters, plus the set of
// effects the scene calls for. The Vulkan backend uploads exactly these arrays; the CPU
// reference traverses them in place.
#pragma once

#include <string>
#include <vector>

#include "bvh/bvh.h"
#include "scene/scene.h"

namespace pt {

// Command-line overrides of the scene's camera and integrator settings (unset = scene's).
struct RenderSettings {
  int width = 0, height = 0;  // 0: from the scene
  int spp = 0;                // 0: from the scene
  long long seed = -1;        // -1: from the scene
  int maxDepth = -1;          // -1: from the scene
  int maxLeafSize = 4;
  BvhBuilder builder = BvhBuilder::kLbvh;
  bool fastIntersection = false;  // Moller-Trumbore instead of the watertight test
  int strategy = -1;              // kStrategy*, -1: from the scene
  int russianRoulette = -1;       // 0 off, 1 on, -1: from the scene
  int sampler = -1;               // kSampler*, -1: from the scene
};

// Which effects the scene calls for; the rest are compiled or switched out.
struct EffectSet {
  bool diffuse = false;        // some surface is Lambertian with non-zero reflectance
  bool mirror = false;         // some surface is an ideal mirror
  bool lightSampling = false;  // next-event estimation (needs emitters, a diffuse surface)
  bool bsdfEmission = false;   // emission found by BSDF-sampled rays is counted (MIS/BSDF)
  bool mis = false;            // both of the above, weighed by the power heuristic
  bool russianRoulette = false;
  bool watertight = true;        // false: the faster, leaky Moller-Trumbore test
  bool sobol = false;            // Owen-scrambled Sobol numbers instead of independent ones
  std::string toString() const;  // e.g. "diffuse+mirror+nee+mis+rr" (+"fast-isect", "sobol")
};

struct SceneData {
  Bvh bvh;
  std::vector<Material> materials;
  std::vector<Emitter> emitters;  // alias table; empty when nothing emits
  RenderParams params{};
  int spp = 0;
  EffectSet effects;
  vec3 shift{0.0f};  // subtracted from every coordinate of a scene far from the origin
};

SceneData prepareScene(const Scene& scene, const RenderSettings& settings);

// Builds the alias table over the emissive triangles (in the given order), with pmf
// proportional to emitted power (area x luminance of the emission), and stores each
// triangle's emitter index in Triangle::emitter. Exposed for tests.
std::vector<Emitter> buildEmitters(std::vector<Triangle>& triangles,
                                   const std::vector<Material>& materials);

}  // namespace pt
