// The CPU reference path tracer: plain C++, written for clarity, in progressive passes over
// the image, multithreaded over tiles. (renderCpu traces with integrator_lanes.h, the same
// steps for eight paths at a time: the same bits.)
// Its steps at a path vertex are path_vertex.h's, which the shader calls too; it reads the
// same flat arrays and draws the same random numbers, so a difference image between the two
// backends points at a bug in what is each one's own (traversal, scheduling) or in a compiler. (The
// BVH it traverses in a eight-wide copy, SceneData::wideBvh, whose answers are the binary tree's
// bit for bit, and takes each triangle's normal, area and offset scale from SceneData::cpuCopies,
// computed once as it would compute them.)
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <mutex>

#include "bvh/traverse.h"
#include "image/image.h"
#include "path_vertex.h"
#include "render/prepare.h"
#include "render/render_options.h"

namespace pt {

struct CpuRenderOptions : RenderOptions {
  int threads = 0;  // 0: every CPU this process may run on (its affinity mask)
};

struct CpuRenderStats : RenderStats {
  int threads = 0;  // threads used
};

// The CPUs this process may run on: what Slurm, taskset or a container allotted, which can be
// fewer than the machine has (std::thread::hardware_concurrency counts those).
int availableCpus();

// The pinhole's ray through film point (x, y) in [0, filmWidth) x [0, filmHeight), row 0 at
// the top (the whole film's coordinates; no filter, no lens).
Ray cameraRay(const Camera& camera, vec2 filmPoint);

// Radiance arriving at the camera along one path sample of image pixel (x, y) (of the crop,
// when there is one), times the camera sample's weight (filter.h). Exposed for
// `--debug-pixel` and for tests that evaluate single paths; `rays` is incremented by the rays
// traced. With debugPrint, the path's vertices and light samples go to stderr in the shader's
// --debug-pixel format.
vec3 sampleRadiance(const SceneData& scene, uvec2 pixel, uint32_t sampleIndex, uint64_t& rays,
                    bool debugPrint = false);

// Asked at each scattering vertex of a path (shading point s, its random numbers' key, after
// `depth` scattering events counting this one, beta: the path's throughput up to s times the
// camera sample's weight), before its light sample: true makes the path's next ray its last,
// which adds the emission it finds (weighed against the light sample, MIS) and ends the path.
using PathEnd =
    std::function<bool(const SurfacePoint& s, const VertexKey& key, uint depth, vec3 beta)>;

// sampleRadiance's path on a surface-only scene, ended early where `end` (unless null) asks:
// stochastic progressive photon mapping's camera paths (cpu/sppm.h), which end past their
// visible point.
vec3 sampleRadianceUntil(const SceneData& scene, uvec2 pixel, uint32_t sampleIndex, uint64_t& rays,
                         const PathEnd* end, bool debugPrint = false);

// The closest surface along a path's ray after `depth` scattering events, and on a shadow ray's
// segment t in [0, 1) whose light sample drew uLight; alpha cut-outs passed by. A path ray is
// searched up to tMax.
std::optional<Hit> closestSurface(const SceneData& scene, const Ray& ray, Intersection test,
                                  uvec2 pixel, uint32_t sampleIndex, uint depth,
                                  float tMax = INFINITY);
std::optional<Hit> closestShadowHit(const SceneData& scene, const Ray& ray, Intersection test,
                                    vec2 uLight);

// Asks the cache for what the shading point of `hit` reads (its triangle, shading constants,
// vertex normals, texture coordinates and medium interface) all at once: on a large mesh each is a
// cache miss, and read where the shading needs them, one after another, their latencies add up.
// closestSurface does it for the hits it returns.
void prefetchHitRecords(const SceneData& scene, const Hit& hit);

// Alpha cut-outs (texture.h's alphaKeepsHit) as the traversal's filter of one ray's hits; u is
// the ray's number (texture.h's pathAlphaRandom, shadowAlphaRandom).
struct AlphaCutouts {
  const SceneData* scene;
  const uint64_t* cutouts;  // CpuSceneCopies::cutouts
  TextureTables tables;
  float u;
  // The cut-outs of a path's ray after `depth` scattering events, and of the shadow ray of a
  // light sample drawn with uLight.
  static AlphaCutouts ofPathRay(const SceneData& scene, uvec2 pixel, uint32_t sampleIndex,
                                uint depth);
  static AlphaCutouts ofShadowRay(const SceneData& scene, vec2 uLight);
  static bool accept(const void* context, uint32_t triangle, const Hit& hit);
  HitFilter filter() const { return HitFilter{accept, this}; }
};

// Traces the shadow ray of light sample ls (path_vertex.h), drawn with uLight: true when
// nothing blocks it (alpha cut-outs passed by). Adds it to `rays`.
bool traceShadowRay(const SceneData& scene, const LightSample& ls, vec2 uLight, uint64_t& rays);

// --debug-pixel's line about a light sample found clear (the shader prints the same).
void printLightSample(const SceneData& scene, uint depth, const LightSample& ls, float weight);

// Renders into film (which must have the camera's resolution), adding spp samples per pixel
// in passes of one sample index each; stopped early (options.stop), it adds whole passes
// only, stats.samplesDone of them. Uses every CPU the process may run on unless told. A scene
// whose integrator is kIntegratorBdpt is rendered by renderBdpt (cpu/bdpt.h).
CpuRenderStats renderCpu(const SceneData& scene, const CpuRenderOptions& options, Film& film);

// Reports progress from the thread that has just finished a tile (tilesDone of tileCount in
// pass passIndex), unless another thread is reporting (progressMutex).
void reportTileProgress(const CpuRenderOptions& options, std::mutex& progressMutex, int passIndex,
                        int tilesDone, int tileCount);

// The end of a CPU render: whether it stopped early (stats.samplesDone of options.spp), the
// last progress report, the rays traced, the film's invalid samples, the render's time since
// `start` and the call's since `callStart`.
void finishCpuRenderStats(const CpuRenderOptions& options, const Film& film, uint64_t rays,
                          std::chrono::steady_clock::time_point start,
                          std::chrono::steady_clock::time_point callStart, CpuRenderStats& stats);

}  // namespace pt
