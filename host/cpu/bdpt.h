// The CPU reference's bidirectional path tracer (pbrt-v4's BDPTIntegrator): a camera subpath and
// a light subpath per pixel sample, every connection strategy (s, t) between them weighed by
// MIS, light tracing (t = 1) splatted onto the film. Its steps at a vertex are
// shaders/bdpt_vertex.h's and bdpt_connect.h's; what is this file's own is how rays are traced
// and how the image is scheduled and written. docs/bdpt.md says what it does and does not do.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "bdpt_vertex.h"
#include "cpu/integrator.h"
#include "image/image.h"
#include "render/prepare.h"

namespace pt {

// Parses --strategy's "S,T" (S >= 0, T >= 1, not 1,1); nullopt for anything else.
std::optional<BdptStrategy> parseBdptStrategy(const std::string& text);

// Throws InputError naming `what` (the scene file) where the scene asks for what the
// bidirectional path tracer does not do yet: participating media, sphere lights, a pixel
// filter other than the box.
void checkBdptScene(const SceneData& scene, const std::string& what);

// The maximum depth BDPT renders with: the scene's, at most kBdptMaxDepth.
uint bdptMaxDepth(const SceneData& scene);

// One connection's contribution to the image: strategy (s, t), its value before the MIS weight
// and the weight. A light-tracing connection (t = 1) lands at filmPoint (the whole film's
// coordinates), the others in the sample's own pixel.
struct BdptContribution {
  int s = 0, t = 0;
  vec3 L{0.0f};
  float weight = 0.0f;
  bool splat = false;
  vec2 filmPoint{0.0f};
};

// Traces the camera and light subpaths of pixel sample (pixel, sampleIndex) of the image (the
// crop's pixel). `rays` counts the rays traced. Exposed for tests of the MIS weights.
void bdptSubpaths(const SceneData& scene, uvec2 pixel, uint32_t sampleIndex, BdptPath& camera,
                  BdptPath& light, uint64_t& rays);

// Traces the two subpaths of pixel sample (pixel, sampleIndex) of the image (the crop's pixel)
// and hands every connection that contributes to `sink` (those of `strategy` alone, where it
// names one). `rays` counts the rays traced. Exposed for tests that weigh strategies.
void bdptSample(const SceneData& scene, uvec2 pixel, uint32_t sampleIndex,
                const BdptStrategy& strategy, uint64_t& rays,
                const std::function<void(const BdptContribution&)>& sink);

// Renders as renderCpu does (passes of one sample index, every pixel, exact sums), the camera
// subpaths' strategies into each pixel's samples and the splats of a pass added to the pixels'
// sums once the pass is done: the film divides them by the samples per pixel, as pbrt-v4 scales
// its splats. The same seed gives the same bits whatever the thread count.
CpuRenderStats renderBdpt(const SceneData& scene, const CpuRenderOptions& options, Film& film);

}  // namespace pt
