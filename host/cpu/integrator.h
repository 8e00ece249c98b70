// The CPU reference path tracer: plain C++, written for clarity, in progressive passes over
// the image, multithreaded over tiles. (renderCpu traces with its vector transcription,
// integrator_lanes.h, eight paths at a time: the same bits.)
// It reads the same flat arrays and draws the same random numbers as the shader, so a
// difference image between the two backends points at a bug. (The BVH it traverses in a
// eight-wide copy, SceneData::wideBvh, whose answers are the binary tree's bit for bit, and
// takes each triangle's normal, area and offset scale from SceneData::cpuCopies, computed once
// as it would compute them.)
#pragma once

#include <cstdint>

#include "bvh/traverse.h"
#include "image/image.h"
#include "render/prepare.h"
#include "render/render_options.h"

namespace pt {

struct CpuRenderOptions : RenderOptions {
  int threads = 0;  // 0: every CPU this process may run on (its affinity mask)
};

struct CpuRenderStats : RenderStats {
  int threads = 0;  // threads used
};

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

// The path's state that a scattering event updates (sampleRadiance's variables of the same
// names).
struct PathState {
  vec3 L;               // radiance gathered so far
  vec3 beta;            // path throughput
  float etaScale;       // product of the squared relative indices refracted through
  float bsdfPdf;        // solid-angle pdf of the BSDF sample that produced the next ray
  bool specularBounce;  // the next ray leaves a specular bounce
};

// A path vertex on one of bsdf.h's materials (not diffuse or mirror), and what its scattering
// event needs: the hit triangle and point, the geometric normal ng, the shading normal ns, the
// direction towards the viewer wo, the ray offsets' scale, this event's random numbers (u) and
// the coordinates of its random streams (pixel, sample, dimension).
struct BsdfVertex {
  const Triangle* triangle;
  const Material* material;
  vec3 p, ng, ns, wo;
  float magnitude;
  BounceRandom u;
  uvec2 pixel;
  uint32_t sampleIndex;
  uint dim;
  uint depth;  // scattering events so far, this one included (for --debug-pixel)
};

// The scattering event at such a vertex, sampleRadiance's steps: light sampling with the
// BSDF's f and pdf (unless it has only delta lobes), then BSDF sampling. Adds the light's
// contribution to state.L, updates beta, etaScale, bsdfPdf and specularBounce, and returns
// the new direction in wi with the geometric normal on its side (where the next ray starts) in
// side; false when the path ends (no direction). sampleRadianceLanes runs it lane by lane, so
// both give the same bits.
bool scatterAtBsdfVertex(const SceneData& scene, const BsdfVertex& v, PathState& state, vec3& wi,
                         vec3& side, uint64_t& rays, bool debugPrint);

// Light sampling at a diffuse vertex (reflectance / pi = f) towards the analytic light (lights.h)
// that `emitter` names: sampleRadiance's next-event estimation for such a light, exposed for
// the lanes (integrator_lanes.h), which call it lane by lane. p, n (the shading normal facing
// the viewer), ng (geometric), the ray offset's scale, the path throughput; returns the
// contribution to L, weighed by MIS (misOn) unless the light is a delta.
vec3 sampleAnalyticLightDiffuse(const SceneData& scene, const Emitter& emitter, vec3 p, vec3 n,
                                vec3 ng, bool shadingNormals, float magnitude, vec3 beta, vec3 f,
                                vec2 uLight, bool misOn, Intersection test, uint64_t& rays,
                                bool debugPrint = false, uint depth = 0);

// The radiance a path gathers when its ray leaves the scene along `direction`: the infinite
// light's (none without one; an image's by direction), at full weight after a specular bounce
// (or from the camera), else weighed as BSDF-sampled emission is (MIS, or nothing with light
// sampling alone).
vec3 environmentSeen(const SceneData& scene, vec3 direction, vec3 beta, bool specularBounce,
                     float bsdfPdf);

// Renders into film (which must have the camera's resolution), adding spp samples per pixel
// in passes of one sample index each; stopped early (options.stop), it adds whole passes
// only, stats.samplesDone of them. Uses every CPU the process may run on unless told.
CpuRenderStats renderCpu(const SceneData& scene, const CpuRenderOptions& options, Film& film);

}  // namespace pt
