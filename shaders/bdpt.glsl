// Bidirectional path tracing on the device (docs/bdpt.md), for pathtrace.comp's PT_BDPT variant:
// one invocation traces one pixel sample, pass.sampleIndex of its pixel, as
// host/cpu/bdpt.cpp's bdptSample does over the same headers (bdpt_vertex.h, bdpt_connect.h,
// bdpt_sample.h, bdpt_splat.h): the camera subpath, the light subpath, then every strategy (s, t)
// with its shadow ray and MIS weight. Everything it adds to the film goes into exact sums by
// 64-bit atomics (exact_sum_atomic.glsl), its own pixel's sample and the light-tracing splats
// (t = 1) that land on any pixel alike, so the film's bits do not depend on the order the
// invocations add in, and equal the CPU reference's sums of the same floats. The host folds the
// sums into its film (host/vulkan/bdpt.cpp). What the host defines: PT_BDPT_MAX_VERTICES (the
// subpaths' arrays) and PT_BDPT_SPLAT_SCALE (bdpt_splat.h's scale); pass.reserved is ~0u, or
// the one strategy (s, t) rendered alone as s << 16 | t (a constant the shader does not take,
// so that such a render compiles no variant of its own).
#ifndef PT_BDPT_GLSL
#define PT_BDPT_GLSL

#ifndef PT_BDPT_SPLAT_SCALE
#define PT_BDPT_SPLAT_SCALE 1.0
#endif

layout(std430, set = 0, binding = PT_BINDING_BDPT_FILM) buffer BdptFilmBuffer {
  uint64_t bdptFilm[];  // PT_BDPT_FILM_WORDS per pixel
};
#define PT_EXACT_SUM_LIMBS bdptFilm
#include "exact_sum_atomic.glsl"

// Adds `value` to image pixel i's exact sums and `count` to its count word: 1 for its own
// sample, 0 for a splat; a NaN or infinite value is not added but counted invalid.
void bdptFilmAdd(uint i, vec3 value, uint64_t count) {
  uint base = PT_BDPT_FILM_WORDS * i;
  if (any(isnan(value)) || any(isinf(value))) {
    count = 1ul << PT_BDPT_INVALID_SHIFT;
  } else {
    for (uint c = 0u; c < 3u; ++c) exactSumAtomicAdd(base + kExactSumLimbs * c, value[c]);
  }
  if (count != 0ul) atomicAdd(bdptFilm[base + PT_BDPT_COUNT_WORD], count);
}

// The closest hit along a ray (tMax 1 and any hit: whether the segment is blocked), the exact
// test taken again where the fast one gave up: one call site of the traversal for both.
bool bdptTrace(vec3 origin, vec3 direction, float tMax, bool anyHit, out HitData hit) {
  bool found = false;
  for (uint exact = 0u; exact < 2u; ++exact) {
    bool inexact;
    found = traceRayWith(exact == 1u, origin, direction, tMax, anyHit, hit, inexact);
    if (!inexact) break;
  }
  return found;
}

// The random walk of the camera subpath (radiance) or the light subpath from its first vertex,
// until it has maxVertices vertices (host/cpu/bdpt.cpp's bdptRandomWalk, its steps
// bdptWalkStep's).
void bdptRandomWalk(bool radiance, BdptWalk walk, uint maxVertices, uvec2 pixel, uint sampleIndex) {
  bool sobol = PT_SOBOL;
  uint seed = params.seed;
  BdptVertex prev = radiance ? cameraPath.v[0] : lightPath.v[0];
  for (uint k = 1u; k < maxVertices; ++k) {
    gLoopIterations++;
    VertexKey key = VertexKey(pixel, sampleIndex, radiance ? bdptCameraDim(k) : bdptLightDim(k));
    gRays++;
    if (kAlphaCutouts) gAlphaU = pathAlphaRandom(pixel, sampleIndex, key.dim, seed);
    HitData hit;
    if (!bdptTrace(walk.origin, walk.direction, 1.0 / 0.0, /*anyHit=*/false, hit)) {
      if (radiance && params.environmentEmitter != kNoEmitter) {
        cameraPath.v[k] =
            bdptEnvironmentVertex(walk.origin, walk.direction, walk.beta, walk.pdf, key);
        cameraPath.count = k + 1u;
      }
      break;
    }
    Triangle tri = loadTriangle(hit.triangle);
    SurfacePoint s =
        surfacePointAt(hit.triangle, tri, hitBarycentrics(walk.origin, walk.direction, tri),
                       -walk.direction, noRayDifferential());
    vec2 uRoulette = random2(sobol, pixel, sampleIndex, key.dim + kDimRoulette, seed);
    vec2 uBsdf = random2(sobol, pixel, sampleIndex, key.dim + kDimBsdf, seed);
    BdptVertex v;
    bool more = bdptWalkStep(s, tri.emitter, key, k + 1u >= maxVertices, uRoulette.y, uBsdf,
                             radiance, walk, prev, v);
    if (radiance) {
      cameraPath.v[k - 1u].pdfRev = prev.pdfRev;
      cameraPath.v[k] = v;
      cameraPath.count = k + 1u;
    } else {
      lightPath.v[k - 1u].pdfRev = prev.pdfRev;
      lightPath.v[k] = v;
      lightPath.count = k + 1u;
    }
    if (!more) break;
    prev = v;
  }
}

void bdptMain() {
  params = paramsBuffer;
  uvec2 pixel = gl_GlobalInvocationID.xy;
  if (pixel.x >= params.camera.width || pixel.y >= params.camera.height) return;
  if (pass.sampleCount == 0u) return;  // the warm-up dispatch, which compiles the pipeline
  uint index = pixel.y * params.camera.width + pixel.x;
  uvec2 filmPixel = pixel + uvec2(params.camera.cropX, params.camera.cropY);
  uint sampleIndex = pass.sampleIndex;
  bool sobol = PT_SOBOL;
  uint seed = params.seed;
  uint maxDepth = min(params.maxDepth, kBdptMaxDepth);
  gTruncated = false;

  // The subpaths' first vertices, the camera's and a light's emission, and their random walks,
  // the camera's then the light's, from one call site.
  BdptStarts starts = bdptStarts(sobol, filmPixel, sampleIndex, seed);
  BdptLightStart start = starts.light;
  cameraPath.v[0] = starts.cameraVertex;
  cameraPath.count = 1u;
  lightPath.v[0] = start.vertex;
  lightPath.count = start.found ? 1u : 0u;
  for (uint side = 0u; side < 2u && (side == 0u || start.found); ++side) {
    bool radiance = side == 0u;
    bdptRandomWalk(radiance, radiance ? starts.cameraWalk : bdptLightWalk(start),
                   radiance ? maxDepth + 2u : maxDepth + 1u, filmPixel, sampleIndex);
  }
  if (start.found && bdptIsInfiniteLight(start.vertex)) {
    BdptVertex first = lightPath.v[0];
    BdptVertex second = lightPath.v[1];
    bdptCorrectInfiniteStart(first, second, lightPath.count, start.pdfPos);
    lightPath.v[0].pdfFwd = first.pdfFwd;
    lightPath.v[1].pdfFwd = second.pdfFwd;
  }

  // Every strategy: the camera's into the pixel's own sample, light tracing's splats into the
  // pixels they land on.
  vec3 L = vec3(0.0);
  bool weighed = pass.reserved == ~0u;
  int strategyS = weighed ? -1 : int(pass.reserved >> 16u);
  int strategyT = weighed ? -1 : int(pass.reserved & 0xFFFFu);
  for (uint t = 1u; t <= cameraPath.count; ++t) {
    for (uint s = 0u; s <= lightPath.count; ++s) {
      gLoopIterations++;
      if (!bdptTakesStrategy(s, t, maxDepth, strategyS, strategyT)) continue;
      BdptStrategyRandom u =
          bdptStrategyRandom(sobol, filmPixel, sampleIndex, seed, params.camera.lensRadius, s, t);
      BdptConnection c = bdptConnect(s, t, u.uChoose, u.uLight);
      if (!c.found) continue;
      if (c.visibility) {
        gRays++;
        if (kAlphaCutouts) gAlphaU = shadowAlphaRandom(u.uLight);
        HitData blocker;
        if (bdptTrace(c.from, c.to - c.from, 1.0, /*anyHit=*/true, blocker)) continue;
      }
      vec3 value = bdptStrategyL(c, t, starts.camera.weight) * bdptStrategyWeight(c, s, t, weighed);
      if (t != 1u) {
        L += value;
        continue;
      }
      BdptSplatPixels footprint = bdptSplatPixels(params.camera, c.filmPoint);
      for (int y = footprint.low.y; y <= footprint.high.y; ++y) {
        for (int x = footprint.low.x; x <= footprint.high.x; ++x) {
          gLoopIterations++;
          ivec2 at = ivec2(x, y) - ivec2(params.camera.cropX, params.camera.cropY);
          if (any(lessThan(at, ivec2(0))) || at.x >= int(params.camera.width) ||
              at.y >= int(params.camera.height)) {
            continue;
          }
          float w = bdptSplatWeight(params.camera, PT_BDPT_SPLAT_SCALE, c.filmPoint, x, y);
          if (w != 0.0) bdptFilmAdd(uint(at.y) * params.camera.width + uint(at.x), value * w, 0ul);
        }
      }
    }
  }

  // Lavapipe's loop cap (see pathtrace.comp's main): a sample cut short is counted, and the
  // host gives the render up, since its splats may be in the sums already.
  uint canary = 0u;
  for (uint bound = min(pass.sampleCount, 1u) + 1u; canary < bound;) canary++;
  if (canary < 2u) gTruncated = true;
  if (gTruncated) {
    atomicAdd(counters.truncated, 1u);
  } else {
    bdptFilmAdd(index, L, 1ul);
  }
  atomicMax(counters.maxLoopIterations, gLoopIterations);
  uint before = atomicAdd(counters.raysLow, gRays);
  if (before + gRays < before) atomicAdd(counters.raysHigh, 1u);  // carry into the high word
}

#endif  // PT_BDPT_GLSL
