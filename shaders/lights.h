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

// The cone a sphere of `radius` about `center` subtends from p (pbrt-v4's Sphere::Sample and
// PDF): sin^2 of its half-angle and 1 - its cosine, the latter from sin^2 / 2 where the cone is
// so narrow (below 1.5 degrees) that 1 - cos would cancel. False where p is inside.
struct SphereCone {
  bool outside;
  float sin2ThetaMax;
  float oneMinusCosThetaMax;
};
PT_INLINE SphereCone sphereCone(vec3 center, float radius, vec3 p) {
  SphereCone cone;
  vec3 toCenter = center - p;
  float dc2 = dot(toCenter, toCenter);
  cone.outside = dc2 > radius * radius;
  cone.sin2ThetaMax = cone.outside ? radius * radius / dc2 : 1.0f;
  float cosThetaMax = sqrt(max(0.0f, 1.0f - cone.sin2ThetaMax));
  cone.oneMinusCosThetaMax =
      cone.sin2ThetaMax < 0.00068523f ? 0.5f * cone.sin2ThetaMax : 1.0f - cosThetaMax;
  return cone;
}

// The density of light sampling's directions towards a sphere light seen from p: uniform over
// its cone, 1 / (2 pi (1 - cos thetaMax)); 0 from inside (no sample is drawn there).
PT_INLINE float sphereLightPdf(Light light, vec3 p) {
  SphereCone cone = sphereCone(light.position, light.radius, p);
  return cone.outside ? 1.0f / (2.0f * kPi * cone.oneMinusCosThetaMax) : 0.0f;
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
  if (light.type == kLightSphere) {
    // A direction uniform in the cone the sphere subtends, and where it meets the sphere
    // (pbrt-v4's Sphere::Sample: the angle alpha at the centre between the axis and that
    // point, from theta by the law of sines).
    s.delta = false;
    SphereCone cone = sphereCone(light.position, light.radius, p);
    vec3 toCenter = light.position - p;
    float dc = sqrt(dot(toCenter, toCenter));
    float sinThetaMax = sqrt(cone.sin2ThetaMax);
    float cosTheta = 1.0f - cone.oneMinusCosThetaMax * u.x;
    float sin2Theta = 1.0f - cosTheta * cosTheta;
    if (cone.sin2ThetaMax < 0.00068523f) {
      sin2Theta = cone.sin2ThetaMax * u.x;
      cosTheta = sqrt(1.0f - sin2Theta);
    }
    float cosAlpha = sin2Theta / sinThetaMax +
                     cosTheta * sqrt(max(0.0f, 1.0f - sin2Theta / (sinThetaMax * sinThetaMax)));
    float sinAlpha = sqrt(max(0.0f, 1.0f - cosAlpha * cosAlpha));
    vec2 cs = cosSinTwoPi(u.y);
    vec3 n = -localToWorld(vec3(sinAlpha * cs.x, sinAlpha * cs.y, cosAlpha), toCenter / dc);
    vec3 q = light.position + light.radius * n;
    vec3 toPoint = q - p;
    s.wi = toPoint / sqrt(dot(toPoint, toPoint));
    // The shadow ray ends just outside the sphere (the ray offset's distance, as at a
    // triangle light): the triangles that stand for it lie inside, up to a hair's breadth
    // from q near their edges.
    vec3 aq = abs(q);
    s.target = offsetRayOrigin(q, n, max(aq.x, max(aq.y, aq.z)));
    s.pdf = 1.0f / (2.0f * kPi * cone.oneMinusCosThetaMax);
    // From inside, or where rounding leaves no cone: no sample.
    s.Li = (cone.outside && cone.oneMinusCosThetaMax > 0.0f) ? light.radiance : vec3(0.0f);
    return s;
  }
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
