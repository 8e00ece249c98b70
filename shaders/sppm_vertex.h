// Stochastic progressive photon mapping (Hachisuka and Jensen 2009; pbrt-v4's SPPMIntegrator)
// at one vertex, written once for the CPU reference and the shader (sppm.glsl): where a camera
// path takes its visible point, which photons count there and what one adds to its pixel, a
// photon's Russian roulette, the random numbers of a photon, and the per-pixel update of the
// photon count, search radius and flux, and the pixel's radiance estimate. The camera path's
// steps up to the visible point are path_vertex.h's (emission found, light sampling, BSDF
// sampling); a photon's emission and scattering are bdpt_vertex.h's (sampleBdptLightStart,
// bdptScatter for importance), the grid's cells sppm_grid_cell.h's. Tracing rays, building the
// hash grid of visible points and how passes are scheduled are each backend's
// (host/cpu/sppm.cpp, host/vulkan/sppm.cpp).
#ifndef PT_SPPM_VERTEX_H
#define PT_SPPM_VERTEX_H

#include "bdpt_vertex.h"
#include "bsdf.h"
#include "path_vertex.h"
#include "sampling.h"
#include "shared_types.h"

#ifdef __cplusplus
namespace pt {
#endif

// The share of the new photons each iteration keeps (the paper's alpha, pbrt-v4's gamma).
PT_CONST float kSppmGamma = 2.0f / 3.0f;

// A photon's random numbers are drawn as a pixel sample's: the "pixel" (photon index,
// kSppmPhotonRow), a row no film reaches; the sample index is the iteration; vertex j's
// dimensions are bdpt_vertex.h's light subpath dimensions kDimLightSubpath + kDimsPerBounce * j.
PT_CONST uint kSppmPhotonRow = 0xFFFFFFFFu;

PT_INLINE VertexKey sppmPhotonKey(uint photon, uint iteration, uint vertex) {
  VertexKey key;
  key.pixel = uvec2(photon, kSppmPhotonRow);
  key.sampleIndex = iteration;
  key.dim = kDimLightSubpath + kDimsPerBounce * vertex;
  return key;
}

// The point a camera path keeps for the photons of one iteration (pbrt-v4's VisiblePoint): the
// shading point (its BSDF, position and wo), its random streams' key, and the camera path's
// throughput up to it, the camera sample's weight included.
struct SppmVisiblePoint {
  SurfacePoint s;
  VertexKey key;
  vec3 beta;
};

// Whether a photon at its surface hit `hit` (0: the first after the light) adds to the visible
// points near it (the same for all of them, so asked once a hit): not at its first hit (direct
// light, which the camera paths' light samples count), and at most maxDepth - 1 hits after it,
// whatever the camera path's depth (pbrt-v4's definition). Where the camera sees a visible point
// through glass or water, the paths so gathered have up to maxDepth + (camera scattering events
// before the point) - 1 events: more than the path tracer of the same maxdepth takes, as in
// pbrt-v4.
PT_INLINE bool sppmPhotonCounts(uint hit, uint maxDepth) {
  return hit > 0u && hit < maxDepth;
}

// Whether the BSDF of shading point s has a diffuse lobe (pbrt-v4's IsDiffuse of its flags):
// Lambertian, diffuse transmission, the coated diffuse's base, a glTF surface's base where it
// is not wholly metal nor wholly transmissive (KHR_materials_transmission, its factor in
// transmittance.x: 0 without the extension).
PT_INLINE bool sppmHasDiffuseLobe(PT_IN(SurfacePoint) s) {
  if (s.scatter == kScatterLambertian) return true;
  if (s.scatter != kScatterBsdf) return false;
  uint type = s.material.type;
  if (type == kMaterialDiffuse || type == kMaterialDiffuseTransmission ||
      type == kMaterialCoatedDiffuse) {
    return true;
  }
  return type == kMaterialGltf && s.material.thickness < 1.0f && s.material.transmittance.x < 1.0f;
}

// Whether the camera path keeps its visible point at shading point s, after `depth` scattering
// events counting the one at s (pbrt-v4: a diffuse BSDF, or a glossy one where the path may
// scatter no further).
PT_INLINE bool sppmTakesVisiblePoint(PT_IN(SurfacePoint) s, uint depth, uint maxDepth) {
  if (sppmHasDiffuseLobe(s)) return true;
  if (s.scatter != kScatterBsdf) return false;
  return depth == maxDepth && bsdfHasNonSpecular(s.material);
}

// What a photon of throughput photonBeta that arrives at a point near visible point vp, along
// -wi (wi: towards where it came from), adds to the visible point's pixel: the camera path's
// throughput times the BSDF at the visible point from its wo to wi times the photon's flux
// (pbrt-v4's Phi_i).
PT_INLINE vec3 sppmPhotonFlux(PT_SCENE_PARAM PT_IN(SppmVisiblePoint) vp, vec3 photonBeta, vec3 wi) {
  vec3 f = surfaceBsdfF(PT_SCENE_ARG vp.s, vp.key, vp.s.wo, wi, true);
  return vp.beta * (photonBeta * f);
}

// A photon's Russian roulette after its BSDF sample took its throughput from beta to betaNew,
// with uniform number u (pbrt-v4): it continues with probability min(1, max(betaNew) /
// max(beta)), its throughput divided by that. False: the photon ends.
PT_INLINE bool sppmPhotonSurvives(PT_INOUT(vec3) beta, vec3 betaNew, float u) {
  float q = max(0.0f, 1.0f - maxComponent(betaNew) / maxComponent(beta));
  if (u < q) return false;
  beta = betaNew / (1.0f - q);
  return true;
}

// A pixel's progressive state (pbrt-v4's SPPMPixel less its visible point): the search radius,
// the photon count N it stands for, and tau, the flux gathered within the radius, scaled to it.
struct SppmPixelState {
  float radius;
  float n;
  vec3 tau;
};

PT_INLINE SppmPixelState sppmStartPixel(float radius) {
  SppmPixelState p;
  p.radius = radius;
  p.n = 0.0f;
  p.tau = vec3(0.0f);
  return p;
}

// The update after an iteration whose photons brought m photons and the flux phi within the
// pixel's radius (Hachisuka and Jensen 2009, as pbrt-v4): N' = N + gamma M, r' = r sqrt(N' / (N +
// M)), tau' = (tau + phi) r'^2 / r^2. Nothing changes where no photon came.
PT_INLINE SppmPixelState sppmUpdatePixel(SppmPixelState p, vec3 phi, uint m) {
  if (m == 0u) return p;
  float nNew = p.n + kSppmGamma * float(m);
  float rNew = p.radius * sqrt(nNew / (p.n + float(m)));
  p.tau = (p.tau + phi) * (rNew * rNew) / (p.radius * p.radius);
  p.n = nNew;
  p.radius = rNew;
  return p;
}

// The pixel's radiance after `iterations` iterations of `photons` photons each: the direct
// light's mean (ldSum: the camera paths' emission found and light samples, summed) plus the
// density estimate tau / (iterations photons pi r^2).
PT_INLINE vec3 sppmPixelRadiance(vec3 ldSum, PT_IN(SppmPixelState) p, float iterations,
                                 float photons) {
  return ldSum / iterations + p.tau / (iterations * photons * kPi * p.radius * p.radius);
}

#ifdef __cplusplus
}  // namespace pt
#endif

#endif  // PT_SPPM_VERTEX_H
