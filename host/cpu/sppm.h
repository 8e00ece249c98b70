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
#include "image/sppm_pixels.h"
#include "render/prepare.h"
#include "render/render_options.h"

namespace pt {

// The photons traced per iteration: the scene's photonsperiteration, or (-1) one per pixel of
// the image, as pbrt-v4.
uint32_t sppmPhotonsPerIteration(const SceneData& scene);

// Throws InputError "<what>sppm with a WxH film needs ..." where the film and the state
// renderSppm keeps for every pixel do not fit in the memory available: the command line checks
// before it allocates either.
void checkSppmFitsInMemory(int width, int height, const std::string& what);

// The state the render of `pixelCount` pixels starts from, in `local` or in the caller's
// options.sppmPixels (RenderOptions: continued when it holds a state, firstSample then its
// iterations; otherwise every pixel at the scene's initial radius, from iteration 0).
SppmPixels& sppmStartState(const SceneData& scene, const RenderOptions& options, size_t pixelCount,
                           SppmPixels& local);

// A pixel's state after an iteration in which it gathered `m` photons of flux `phi`
// (sppm_vertex.h's sppmUpdatePixel) and direct light `ld`.
void sppmUpdateRecord(SppmPixelRecord& r, vec3 phi, uint32_t m, vec3 ld);

// Sets `film` to every pixel's estimate after `iterations` iterations of `photons` photons,
// one sample a pixel (an invalid one where the pixel took a NaN or infinite value).
void sppmEstimateToFilm(const SppmPixels& pixels, uint32_t iterations, uint32_t photons,
                        Film& film);

// Renders options.spp iterations, from the state options.sppmPixels holds after
// options.firstSample of them (RenderOptions), and sets the film to each pixel's estimate as
// its one sample. A stop (options.stop) ends it after the last whole iteration, stats.samplesDone
// of them this call. The same seed gives the same bits whatever the thread count, and however
// the iterations are split between calls: the flux a pixel gathers is summed exactly
// (ExactSum), so the order photons arrive in does not matter.
CpuRenderStats renderSppm(const SceneData& scene, const CpuRenderOptions& options, Film& film);

}  // namespace pt
