// The CPU reference's stochastic progressive photon mapping (Hachisuka and Jensen 2009;
// pbrt-v4's SPPMIntegrator). Each iteration: a camera pass (every pixel's path to its first
// diffuse vertex, the visible point, gathering the emission it finds and light samples on the
// way, as the path tracer's paths do), a hash grid over the visible points (cpu/sppm_grid.h), a
// photon pass (photons from the lights, chosen by power, traced by BSDF sampling and Russian
// roulette, each surface hit after the first adding its flux to the visible points within their
// radius), then every pixel's update of its photon count, radius and flux. Its steps at a vertex
// are shaders/sppm_vertex.h's. Consistent, not unbiased: the image converges as the radii shrink.
// docs/sppm.md says what it does and does not do.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cpu/integrator.h"
#include "image/image.h"
#include "render/prepare.h"

namespace pt {

// The photons traced per iteration: the scene's photonsperiteration, or (-1) one per pixel of
// the image, as pbrt-v4.
uint32_t sppmPhotonsPerIteration(const SceneData& scene);

// The state of one pixel after a render, for tests: its radius, photon count and flux, and the
// sum of its iterations' direct light.
struct SppmPixelReport {
  float radius = 0.0f;
  float n = 0.0f;
  vec3 tau{0.0f};
  vec3 ldSum{0.0f};
};

// Throws InputError "<what>sppm with a WxH film needs ..." where the film and the state
// renderSppm keeps for every pixel do not fit in the memory available: the command line checks
// before it allocates either.
void checkSppmFitsInMemory(int width, int height, const std::string& what);

// Renders options.spp iterations (from sample index 0: iterations build on all before them, so
// a render cannot be continued or split) and adds each pixel's estimate to the film as its one
// sample. A stop (options.stop) ends it after the last whole iteration, stats.samplesDone of
// them. The same seed gives the same bits whatever the thread count: the flux a pixel gathers is
// summed exactly (ExactSum), so the order photons arrive in does not matter. `pixels`, where
// given, receives every pixel's final state (row-major).
CpuRenderStats renderSppm(const SceneData& scene, const CpuRenderOptions& options, Film& film,
                          std::vector<SppmPixelReport>* pixels = nullptr);

}  // namespace pt
