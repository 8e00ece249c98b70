// The lights that are not triangles (struct Light, shared_types.h), sampled from a receiving
// point as pbrt-v4 samples its PointLight, SpotLight, DistantLight and UniformInfiniteLight
// (SampleLi). Shared by the CPU reference and the shader, so that both take the same
// directions and radiances; the integrators pick the light (alias table), trace the shadow ray
// and weigh the sample.
#ifndef PT_LIGHTS_H
#define PT_LIGHTS_H

#include "sampling.h"
#include "shared_types.h"

#ifdef __cplusplus
namespace pt {
#endif

// pbrt-v4's SmoothStep: 0 below a, 1 above b, the cubic 3t^2 - 2t^3 between.
PT_INLINE float lightSmoothStep(float x, float a, float b) {
  if (a == b) return x < a ? 0.0f : 1.0f;
  float t = clamp((x - a) / (b - a), 0.0f, 1.0f);
  return t * t * (3.0f - 2.0f * t);
}

// Uniformly distributed unit direction (pdf 1 / (4 pi)).
PT_INLINE vec3 sampleUniformSphere(vec2 u) {
  float z = 1.0f - 2.0f * u.x;
  float r = sqrt(max(0.0f, 1.0f - z * z));
  vec2 cs = cosSinTwoPi(u.y);
  return vec3(r * cs.x, r * cs.y, z);
}

// A light sample seen from a receiving point.
struct AnalyticLightSample {
  vec3 wi;      // unit direction from the receiving point towards the light
  vec3 Li;      // radiance arriving along wi; for a delta light the delta's weight (I / r^2, L)
  vec3 target;  // where the shadow ray ends: the light's position, or a point beyond the scene
  float pdf;    // solid-angle density of wi given the light; 1 for delta lights
  bool delta;   // a point, spot or distant light: no BSDF-sampled ray can find it
};

// Samples `light` from point p with u (only the infinite light uses it). The scene lies within
// sceneRadius of any point of it times two (pbrt-v4's 2 * sceneRadius), where the shadow
// rays of distant and infinite lights end.
PT_INLINE AnalyticLightSample sampleAnalyticLight(Light light, vec3 p, vec2 u, float sceneRadius) {
  AnalyticLightSample s;
  s.delta = light.type != kLightInfinite;
  s.pdf = 1.0f;
  if (light.type == kLightPoint || light.type == kLightSpot) {
    vec3 toLight = light.position - p;
    float dist2 = dot(toLight, toLight);
    s.wi = toLight / sqrt(dist2);
    s.Li = light.radiance / dist2;
    if (light.type == kLightSpot) {
      s.Li *=
          lightSmoothStep(-dot(s.wi, light.direction), light.cosFalloffEnd, light.cosFalloffStart);
    }
    s.target = light.position;
  } else {
    // Distant: the light's one direction; infinite: a uniform direction of the sphere (pbrt-v4
    // asks its uniform light for none where MIS compensation allows: we keep the complete
    // density, so that light sampling alone still sees the whole environment).
    s.wi = light.type == kLightDistant ? light.direction : sampleUniformSphere(u);
    if (light.type == kLightInfinite) s.pdf = kInv4Pi;
    s.Li = light.radiance;
    s.target = p + s.wi * (2.0f * sceneRadius);
  }
  return s;
}

// The density with which light sampling, choosing the infinite light with probability pmf,
// produces any one direction (BSDF-sampled rays that leave the scene are weighed by it).
PT_INLINE float environmentLightPdf(float pmf) {
  return pmf * kInv4Pi;
}

#ifdef __cplusplus
}  // namespace pt
#endif

#endif  // PT_LIGHTS_H
