// Stochastic progressive photon mapping's two passes on the device (docs/sppm.md), for
// pathtrace.comp: PT_SPPM_CAMERA is the path tracer's own main and path loop, which end a path
// one ray past its visible point and write the point here (sppmKeepVisiblePoint, called by
// extendPath); the accumulation holds the path's direct light. PT_SPPM_PHOTONS replaces main:
// one invocation traces one photon from the lights (sampleBdptLightStart, bdptScatter, as
// host/cpu/sppm.cpp's sppmTracePhoton) and adds its flux at the visible points of the host's
// hash grid within their radius, summed exactly by 64-bit atomics (exact_sum_atomic.glsl). The
// steps at a vertex are sppm_vertex.h's, the grid's cells sppm_grid_cell.h's; the host builds
// the grid and updates the pixels between passes (host/vulkan/sppm.cpp).
#ifndef PT_SPPM_GLSL
#define PT_SPPM_GLSL

#include "sppm_grid_cell.h"

layout(std430, set = 0, binding = PT_BINDING_SPPM_POINTS) buffer SppmPointBuffer {
  SppmVisiblePoint sppmPoints[];
};
layout(std430, set = 0, binding = PT_BINDING_SPPM_FOUND) buffer SppmFoundBuffer {
  vec4 sppmFound[];
};

#ifdef PT_SPPM_CAMERA
uint gSppmPixel = 0u;  // the image's pixel index of this invocation (main sets it)

// The camera path's visible point test at shading point s after `depth` scattering events
// (sampleRadianceUntil's PathEnd in host/cpu/sppm.cpp): where it takes the point, the record
// and its position are written and the path is to end one ray later.
bool sppmKeepVisiblePoint(SurfacePoint s, VertexKey key, uint depth, vec3 beta) {
  if (!sppmTakesVisiblePoint(s, depth, params.maxDepth)) return false;
  SppmVisiblePoint vp;
  vp.s = s;
  vp.key = key;
  vp.beta = beta;
  sppmPoints[gSppmPixel] = vp;
  // (Only a point that carries light to its pixel goes into the grid.)
  sppmFound[gSppmPixel] = vec4(s.p, beta != vec3(0.0) ? 1.0 : 0.0);
  return true;
}
#endif

#ifdef PT_SPPM_PHOTONS
layout(std430, set = 0, binding = PT_BINDING_SPPM_GRID) readonly buffer SppmGridBuffer {
  SppmGridShape sppmGridShape;
  uint sppmGridWords[];  // the buckets' starts (buckets + 1 of them), then the entries
};
layout(std430, set = 0, binding = PT_BINDING_SPPM_GRID_POINTS) readonly buffer SppmGridPoints {
  vec4 sppmGridPoints[];  // each pixel's visible point and search radius
};
layout(std430, set = 0, binding = PT_BINDING_SPPM_FLUX) buffer SppmFluxBuffer {
  uint64_t sppmFlux[];  // PT_SPPM_FLUX_WORDS per pixel
};
#define PT_EXACT_SUM_LIMBS sppmFlux
#include "exact_sum_atomic.glsl"

// A photon's flux at pixel i's visible point: each channel into its exact sum, and one photon
// counted (with an invalid one, whose flux is NaN or infinite, counted apart as well).
void sppmAddPhoton(uint i, vec3 flux) {
  uint base = PT_SPPM_FLUX_WORDS * i;
  bool valid = !any(isnan(flux)) && !any(isinf(flux));
  if (valid) {
    exactSumAtomicAdd(base, flux.x);
    exactSumAtomicAdd(base + kExactSumLimbs, flux.y);
    exactSumAtomicAdd(base + 2u * kExactSumLimbs, flux.z);
  }
  atomicAdd(sppmFlux[base + PT_SPPM_COUNT_WORD],
            valid ? 1ul : 1ul + (1ul << PT_SPPM_INVALID_SHIFT));
}

// The photon at shading point p, with throughput beta, arrived along -wi: adds its flux to every
// visible point within its radius listed in the bucket of p's cell (SppmGrid::forWithin).
void sppmGather(SppmGridShape grid, vec3 p, vec3 beta, vec3 wi) {
  ivec3 cell;
  if (grid.entries == 0u || !sppmGridCell(grid, p, cell)) return;
  uint h = sppmGridBucket(grid, cell);
  uint end = sppmGridWords[h + 1u];
  for (uint k = sppmGridWords[h]; k < end; ++k) {
    gLoopIterations++;
    uint i = sppmGridWords[grid.buckets + 1u + k];
    vec4 point = sppmGridPoints[i];
    vec3 d = point.xyz - p;
    if (dot(d, d) <= point.w * point.w) {
      sppmAddPhoton(i, sppmPhotonFlux(sppmPoints[i], beta, wi));
    }
  }
}

// Photon pass.sampleCount of the dispatch's photons, from photon pass.reserved on, of
// iteration pass.sampleIndex: one per invocation. pass.debugPixel: ~0u, or the one hit whose
// visible points the photons take (a pass split by hits, the photon ending there; see
// host/vulkan/sppm.cpp).
void sppmTracePhotons() {
  params = paramsBuffer;
  SppmGridShape grid = sppmGridShape;
  uint width = gl_NumWorkGroups.x * kWorkgroupSize;
  uint local = gl_GlobalInvocationID.y * width + gl_GlobalInvocationID.x;
  if (local >= pass.sampleCount) return;
  uint photon = pass.reserved + local;
  uint iteration = pass.sampleIndex;
  uint seed = params.seed;
  bool sobol = PT_SOBOL;
  gTruncated = false;

  VertexKey start = sppmPhotonKey(photon, iteration, 0u);
  BdptLightStart light = sampleBdptLightStart(
      random2(sobol, start.pixel, iteration, start.dim + kDimLightChoose, seed),
      random2(sobol, start.pixel, iteration, start.dim + kDimLightPoint, seed),
      random2(sobol, start.pixel, iteration, start.dim + kDimBsdf, seed), start);
  if (light.found) {
    vec3 beta = light.beta;
    vec3 origin = light.origin;
    vec3 direction = light.direction;
    BdptVertex prev = light.vertex;
    for (uint depth = 0u; depth < params.maxDepth; ++depth) {
      gLoopIterations++;
      VertexKey key = sppmPhotonKey(photon, iteration, depth + 1u);
      gRays++;
      if (kAlphaCutouts) gAlphaU = pathAlphaRandom(key.pixel, iteration, key.dim, seed);
      HitData hit;
      bool inexact;
      bool found = traceRayWith(/*exact=*/false, origin, direction, 1.0 / 0.0,
                                /*anyHit=*/false, hit, inexact);
      if (inexact) {
        found = traceRayWith(/*exact=*/true, origin, direction, 1.0 / 0.0, /*anyHit=*/false, hit,
                             inexact);
      }
      if (!found) break;
      Triangle tri = loadTriangle(hit.triangle);
      SurfacePoint s = surfacePointAt(hit.triangle, tri, hitBarycentrics(origin, direction, tri),
                                      -direction, noRayDifferential());
      if (sppmPhotonCounts(depth, params.maxDepth) &&
          (pass.debugPixel == ~0u || depth == pass.debugPixel)) {
        sppmGather(grid, s.p, beta, -direction);
      }
      if (depth == pass.debugPixel) break;
      BdptVertex v = bdptSurfaceVertex(s, tri.emitter, key, beta, 0.0, prev);
      vec2 uRoulette = random2(sobol, key.pixel, iteration, key.dim + kDimRoulette, seed);
      vec3 betaNew = beta;
      float pdf;
      vec3 wi;
      if (!bdptScatter(v, prev, uRoulette.y,
                       random2(sobol, key.pixel, iteration, key.dim + kDimBsdf, seed),
                       /*radiance=*/false, betaNew, pdf, wi)) {
        break;
      }
      if (!sppmPhotonSurvives(beta, betaNew, uRoulette.x)) break;
      prev = v;
      origin = nextRayOrigin(s, wi);
      direction = wi;
    }
  }
  // Lavapipe's loop cap (see main): a photon cut short is counted, its pixels' sums then
  // incomplete.
  uint canary = 0u;
  for (uint bound = min(pass.sampleCount, 1u) + 1u; canary < bound;) canary++;
  if (canary < 2u) gTruncated = true;
  if (gTruncated) atomicAdd(counters.truncated, 1u);
  atomicMax(counters.maxLoopIterations, gLoopIterations);
  uint before = atomicAdd(counters.raysLow, gRays);
  if (before + gRays < before) atomicAdd(counters.raysHigh, 1u);  // carry into the high word
}
#endif

#endif  // PT_SPPM_GLSL
