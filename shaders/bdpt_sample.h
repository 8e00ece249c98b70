// One pixel sample of bidirectional path tracing between the backends' ray tracing, written once
// for the CPU reference (host/cpu/bdpt.cpp) and the shader (shaders/bdpt.glsl): the step of a
// subpath's random walk once its ray has found a surface, which strategies (s, t) a sample
// takes and with which random numbers, and the weight of each. The per-vertex work is
// bdpt_vertex.h's and bdpt_connect.h's; tracing the rays and adding to the film are each
// backend's (docs/bdpt.md).
#ifndef PT_BDPT_SAMPLE_H
#define PT_BDPT_SAMPLE_H

#include "bdpt_connect.h"
#include "bdpt_vertex.h"
#include "filter.h"
#include "path_vertex.h"
#include "sampling.h"
#include "shared_types.h"

#ifdef __cplusplus
namespace pt {
#endif

// A subpath's walk between two vertices: the ray to trace next, the throughput and the ray's
// solid-angle density.
struct BdptWalk {
  vec3 origin;
  vec3 direction;
  vec3 beta;
  float pdf;
};

// The starts of a pixel sample's two subpaths (film pixel `pixel`): the camera sample (its ray
// through a point of the pixel's filter and of the lens, its filter weight), the camera's vertex
// and the walk that leaves it; a light's emission (pbrt-v4's GenerateCameraSubpath and
// GenerateLightSubpath before their walks), with the light subpath's first dimensions.
struct BdptStarts {
  CameraSample camera;
  BdptVertex cameraVertex;
  BdptWalk cameraWalk;
  BdptLightStart light;
};

PT_INLINE BdptStarts bdptStarts(PT_SCENE_PARAM bool sobol, uvec2 pixel, uint sampleIndex,
                                uint seed) {
  BdptStarts b;
  VertexKey key;
  key.pixel = pixel;
  key.sampleIndex = sampleIndex;
  key.dim = kDimPixel;
  b.camera = cameraSampleOf(PT_PARAMS.camera, sobol, pixel, sampleIndex, seed);
  b.cameraVertex = bdptCameraVertex(PT_PARAMS.camera, b.camera.lensOffset, vec3(1.0f), key);
  b.cameraWalk.origin = b.camera.origin;
  b.cameraWalk.direction = b.camera.direction;
  b.cameraWalk.beta = vec3(1.0f);
  b.cameraWalk.pdf = cameraDirectionPdf(PT_PARAMS.camera, b.camera.lensOffset, b.camera.direction);
  key.dim = bdptLightDim(0u);
  b.light = sampleBdptLightStart(
      PT_SCENE_ARG random2(sobol, pixel, sampleIndex, key.dim + kDimLightChoose, seed),
      random2(sobol, pixel, sampleIndex, key.dim + kDimLightPoint, seed),
      random2(sobol, pixel, sampleIndex, key.dim + kDimBsdf, seed), key);
  return b;
}

// The walk that leaves a light subpath's start.
PT_INLINE BdptWalk bdptLightWalk(PT_IN(BdptLightStart) start) {
  BdptWalk w;
  w.origin = start.origin;
  w.direction = start.direction;
  w.beta = start.beta;
  w.pdf = start.pdfDir;
  return w;
}

// The walk's ray found shading point s (on a triangle of emitter `emitter`): its vertex v, made
// from prev, whose reverse density the step sets (pbrt-v4's RandomWalk after the intersection).
// Unless v is the subpath's last (`last`), samples the BSDF there for the next ray (uLobe: the
// lobe, from the roulette dimension's second number as the path tracer takes it; uBsdf: the
// direction) for radiance (a camera subpath) or importance. False: the walk ends at v.
PT_INLINE bool bdptWalkStep(PT_SCENE_PARAM PT_IN(SurfacePoint) s, uint emitter, VertexKey key,
                            bool last, float uLobe, vec2 uBsdf, bool radiance,
                            PT_INOUT(BdptWalk) walk, PT_INOUT(BdptVertex) prev,
                            PT_OUT(BdptVertex) v) {
  v = bdptSurfaceVertex(s, emitter, key, walk.beta, walk.pdf, prev);
  if (last) return false;
  vec3 wi;
  if (!bdptScatter(PT_SCENE_ARG v, prev, uLobe, uBsdf, radiance, walk.beta, walk.pdf, wi)) {
    return false;
  }
  walk.origin = nextRayOrigin(s, wi);
  walk.direction = wi;
  return true;
}

// Whether a sample takes strategy (s, t): a path of depth s + t - 2 in [0, maxDepth], not s = t
// = 1, and, where one strategy is asked for alone (strategyS >= 0), that one.
PT_INLINE bool bdptTakesStrategy(uint s, uint t, uint maxDepth, int strategyS, int strategyT) {
  int depth = int(s + t) - 2;
  if ((s == 1u && t == 1u) || depth < 0 || depth > int(maxDepth)) return false;
  return strategyS < 0 || (int(s) == strategyS && int(t) == strategyT);
}

// The random numbers of strategy (s, t): the light sample of s = 1 takes those of camera vertex
// t - 1's light sample (uChoose, uLight); the lens point of t = 1 those of light vertex s - 1's
// light point (uLight; a pinhole needs none).
struct BdptStrategyRandom {
  vec2 uChoose;
  vec2 uLight;
};

PT_INLINE BdptStrategyRandom bdptStrategyRandom(bool sobol, uvec2 pixel, uint sampleIndex,
                                                uint seed, float lensRadius, uint s, uint t) {
  BdptStrategyRandom u;
  u.uChoose = vec2(0.0f);
  u.uLight = vec2(0.0f);
  if (s == 1u) {
    uint dim = bdptCameraDim(t - 1u);
    u.uChoose = random2(sobol, pixel, sampleIndex, dim + kDimLightChoose, seed);
    u.uLight = random2(sobol, pixel, sampleIndex, dim + kDimLightPoint, seed);
  } else if (t == 1u && lensRadius > 0.0f) {
    u.uLight = random2(sobol, pixel, sampleIndex, bdptLightDim(s - 1u) + kDimLightPoint, seed);
  }
  return u;
}

// Strategy (s, t)'s contribution before its weight: the camera's strategies carry the camera
// sample's filter weight (filter.h: 1 but for mitchell's negative lobes), as the path tracer's
// samples do; light tracing's splats (t = 1) take the filter's value where they land instead
// (bdpt_splat.h).
PT_INLINE vec3 bdptStrategyL(PT_IN(BdptConnection) c, uint t, float filterWeight) {
  return t == 1u ? c.L : c.L * filterWeight;
}

// Its weight: the MIS weight, or 1 for a strategy rendered alone (`weighed` false).
PT_INLINE float bdptStrategyWeight(PT_SCENE_PARAM PT_BDPT_PATHS_PARAM PT_IN(BdptConnection) c,
                                   uint s, uint t, bool weighed) {
  return weighed ? bdptMisWeight(PT_SCENE_ARG PT_BDPT_PATHS_ARG c.sampled, s, t) : 1.0f;
}

#ifdef __cplusplus
}  // namespace pt
#endif

#endif  // PT_BDPT_SAMPLE_H
