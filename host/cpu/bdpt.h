// The CPU reference's bidirectional path tracer (pbrt-v4's BDPTIntegrator): a camera subpath and
// a light subpath per pixel sample, every connection strategy (s, t) between them weighed by
// MIS, light tracing (t = 1) splatted onto the film. Its steps at a vertex are
// shaders/bdpt_vertex.h's and bdpt_connect.h's; what is this file's own is how rays are traced
// and how the image is scheduled and written. docs/bdpt.md says what it does and does not do.
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <string>

#include "bdpt_splat.h"
#include "bdpt_vertex.h"
#include "cpu/integrator.h"
#include "image/image.h"
#include "render/prepare.h"

namespace pt {

// Parses --strategy's "S,T" (S >= 0, T >= 1, not 1,1); nullopt for anything else.
std::optional<BdptStrategy> parseBdptStrategy(const std::string& text);

// Throws InputError naming `what` (the scene file) where the scene asks for what the
// integrators that trace light subpaths (bdpt, and sppm's photons: `integrator`) do not do yet:
// participating media.
void checkBdptScene(const SceneData& scene, const std::string& what,
                    const std::string& integrator = "bdpt");

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

// How a light-tracing splat at a film point spreads over the image's pixels: bdpt_splat.h's
// footprint and weights, over the image (the crop's pixels).
struct BdptSplatter {
  explicit BdptSplatter(const Camera& camera);

  // Calls f(x, y, weight) for each pixel (image coordinates) that takes a splat at filmPoint
  // (the whole film's coordinates).
  template <typename F>
  void forPixels(vec2 filmPoint, F&& f) const {
    const BdptSplatPixels p = bdptSplatPixels(cam, filmPoint);
    for (int y = p.low.y; y <= p.high.y; ++y) {
      for (int x = p.low.x; x <= p.high.x; ++x) {
        const int ix = x - int(cam.cropX);
        const int iy = y - int(cam.cropY);
        if (ix < 0 || iy < 0 || ix >= int(cam.width) || iy >= int(cam.height)) continue;
        const float w = bdptSplatWeight(cam, scale, filmPoint, x, y);
        if (w != 0.0f) f(ix, iy, w);
      }
    }
  }

  const Camera& cam;
  float scale;  // bdptSplatScale
};

// 1 / the camera's filter's integral (camera_filter.h), rounded to float: what bdptSplatScale
// takes.
float bdptInverseFilterIntegral(const Camera& camera);

// Traces the camera and light subpaths of pixel sample (pixel, sampleIndex) of the image (the
// crop's pixel); returns the camera sample's filter weight (filter.h's FilmSample::weight),
// which the camera subpath's strategies carry. `rays` counts the rays traced. Exposed for tests
// of the MIS weights.
float bdptSubpaths(const SceneData& scene, uvec2 pixel, uint32_t sampleIndex, BdptPath& camera,
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
