// The sheen lobe of glTF's KHR_materials_sheen, written once for the CPU reference, the shader
// and the tool that tabulates its albedo (tools/sheen-albedo.cpp): Estevez and Kulla's "Charlie"
// distribution ("Production Friendly Microfacet Sheen BRDF", SIGGRAPH 2017 course) with their
// fitted masking-shadowing, as the extension's specification defines the lobe:
//
//   f = sheenColor D(h) V(wo, wi),   D = (2 + 1 / alpha) sin(theta_h)^(1 / alpha) / (2 pi)
//   V = min(1 / ((1 + Lambda(wo.z) + Lambda(wi.z)) 4 wo.z wi.z), 1)
//
// with alpha = sheenRoughness^2 (at least kSheenMinAlpha) and Lambda the paper's fit, whose five
// coefficients are interpolated between its r = 0 and r = 1 values by (1 - alpha)^2. V is capped
// at 1 as the Khronos sample viewer caps it: the fit keeps Lambda finite at grazing angles, so
// that without the cap V grows as 1 / wo.z there and the lobe's albedo without bound (8.3 at
// wo.z = 1e-6 for roughness 0, 1.5 for roughness 1). f excludes the cosine and the colour; wo
// and wi in the local frame, above the surface.
#ifndef PT_SHEEN_H
#define PT_SHEEN_H

#include "sampling.h"
#include "shared_types.h"

#ifdef __cplusplus
namespace pt {
#endif

// The smallest alpha: below it the distribution's exponent 1 / alpha overflows float's range
// of sin^(1 / alpha) long before it changes the image.
PT_CONST float kSheenMinAlpha = 1e-3f;

PT_INLINE float sheenAlpha(float roughness) {
  return max(roughness * roughness, kSheenMinAlpha);
}

PT_INLINE float charlieD(float alpha, float cosThetaH) {
  float sin2 = max(1.0f - cosThetaH * cosThetaH, 0.0f);
  float invAlpha = 1.0f / alpha;
  return (2.0f + invAlpha) * pow(sin2, 0.5f * invAlpha) * (0.5f * kInvPi);
}

// The paper's L(x) = a / (1 + b x^c) + d x + e.
PT_INLINE float charlieL(float alpha, float x) {
  float t = (1.0f - alpha) * (1.0f - alpha);
  float a = mix(21.5473f, 25.3245f, t);
  float b = mix(3.82987f, 3.32435f, t);
  float c = mix(0.19823f, 0.16801f, t);
  float d = mix(-1.97760f, -1.27393f, t);
  float e = mix(-4.32054f, -4.85967f, t);
  return a / (1.0f + b * pow(x, c)) + d * x + e;
}
PT_INLINE float charlieLambda(float alpha, float cosTheta) {
  cosTheta = clamp(cosTheta, 0.0f, 1.0f);  // a sampled direction's z may round above 1
  if (cosTheta < 0.5f) return exp(charlieL(alpha, cosTheta));
  return exp(2.0f * charlieL(alpha, 0.5f) - charlieL(alpha, 1.0f - cosTheta));
}

// The lobe without its colour, for wo and wi above the surface (0 elsewhere).
PT_INLINE float sheenLobe(float alpha, vec3 wo, vec3 wi) {
  if (wo.z <= 0.0f || wi.z <= 0.0f) return 0.0f;
  vec3 wm = wo + wi;
  float len2 = dot(wm, wm);
  if (!(len2 > 0.0f)) return 0.0f;
  float cosThetaH = wm.z / sqrt(len2);
  float g = 1.0f / (1.0f + charlieLambda(alpha, wo.z) + charlieLambda(alpha, wi.z));
  return charlieD(alpha, cosThetaH) * min(g / (4.0f * wo.z * wi.z), 1.0f);
}

#ifdef __cplusplus
}  // namespace pt
#endif

#endif  // PT_SHEEN_H
