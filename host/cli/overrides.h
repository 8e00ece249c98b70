// Command-line overrides of a scene's camera and integrator settings, shared by `render` and
// `converge`: registered once (addOverrideOptions in main.cpp), turned into RenderSettings here.
// Choice names come from the option tables (common/named_values.h, bvh/bvh.h).
#pragma once

#include <optional>
#include <string>

#include "common/named_values.h"
#include "render/prepare.h"

namespace pt {

struct SceneOverrides {
  std::optional<int> width, height, maxDepth;  // unset: the scene's
  std::optional<uint32_t> seed;
  std::optional<int> leafSize;  // unset: the backend's default (kDefaultLeafSize*)
  // Names from the tables; empty: the scene's (strategy, roulette, sampler) or the default.
  // `strategy` may also be "S,T": one strategy of the bdpt integrator (cpu/bdpt.h).
  std::string integrator, strategy, roulette, sampler, lightSampler;
  std::string builder{nameOf(kBuilderNames, kDefaultBuilder)};
  std::string intersection{nameOf(kIntersectionNames, false)};
  std::optional<float> sppmRadius;  // the sppm integrator's parameters; unset: the scene's
  std::optional<int64_t> sppmPhotons;

  // Sets the scene's sppm parameters that were given.
  void applySppm(Scene& scene) const {
    if (sppmRadius) scene.integrator.sppm.radius = *sppmRadius;
    if (sppmPhotons) scene.integrator.sppm.photonsPerIteration = *sppmPhotons;
  }

  // The names were validated against the same tables when the command line was parsed.
  // `backend`: "cpu" or "vulkan", for the defaults that differ between them.
  RenderSettings toSettings(const std::string& backend) const {
    RenderSettings s;
    s.width = width;
    s.height = height;
    s.seed = seed;
    s.maxDepth = maxDepth;
    s.maxLeafSize =
        leafSize.value_or(backend == "cpu" ? kDefaultLeafSizeCpu : kDefaultLeafSizeVulkan);
    s.integrator = valueNamed(kIntegratorNames, integrator);
    s.strategy = valueNamed(kStrategyNames, strategy);
    s.russianRoulette = valueNamed(kRouletteNames, roulette);
    s.sampler = valueNamed(kSamplerNames, sampler);
    s.lightSampler = valueNamed(kLightSamplerNames, lightSampler);
    s.builder = valueNamed(kBuilderNames, builder).value_or(kDefaultBuilder);
    s.fastIntersection = valueNamed(kIntersectionNames, intersection).value_or(false);
    return s;
  }
};

}  // namespace pt
