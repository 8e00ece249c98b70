// Command-line overrides of a scene's camera and integrator settings, shared by `render` and
// `converge` (their options are registered once, in main.cpp).
#pragma once

#include <string>

#include "render/prepare.h"

namespace pt {

struct SceneOverrides {
  int width = 0, height = 0;  // 0: the scene's
  int maxDepth = -1;          // -1: the scene's
  int leafSize = 4;
  long long seed = -1;                      // -1: the scene's
  std::string strategy;                     // mis, nee, bsdf; empty: the scene's
  std::string roulette;                     // on, off; empty: the scene's
  std::string builder = "lbvh";             // lbvh, sah
  std::string intersection = "watertight";  // watertight, fast
  std::string sampler;                      // independent, sobol; empty: the scene's

  RenderSettings toSettings() const {
    RenderSettings s;
    s.width = width;
    s.height = height;
    s.seed = seed;
    s.maxDepth = maxDepth;
    s.maxLeafSize = leafSize;
    if (strategy == "mis") s.strategy = int(kStrategyMis);
    if (strategy == "nee") s.strategy = int(kStrategyNee);
    if (strategy == "bsdf") s.strategy = int(kStrategyBsdf);
    if (!roulette.empty()) s.russianRoulette = roulette == "on" ? 1 : 0;
    s.builder = builder == "sah" ? BvhBuilder::kBinnedSah : BvhBuilder::kLbvh;
    s.fastIntersection = intersection == "fast";
    if (sampler == "independent") s.sampler = int(kSamplerIndependent);
    if (sampler == "sobol") s.sampler = int(kSamplerSobol);
    return s;
  }
};

}  // namespace pt
