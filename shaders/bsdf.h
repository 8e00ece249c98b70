// The BSDFs of the material types beyond diffuse and mirror, written once for the CPU
// reference and the shader (C++ through GLM, GLSL through #include). Each follows pbrt-v4's
// definition of the BxDF of the same name (Pharr, Jakob and Humphreys, "Physically Based
// Rendering", 4th edition, chapters 9 and 14; its bxdfs.h), in RGB instead of sampled
// wavelengths. Everything works in the local shading frame, z along the shading normal, with
// the book's names: wo (towards the viewer), wi (towards the light), wm (microfacet normal).
// f and the pdf are per unit solid angle; f excludes the cosine.
//
// A delta lobe (a smooth interface) is returned only by sampling, flagged kBsdfSpecular,
// with f and pdf carrying the same delta (their ratio is what counts); bsdfF and bsdfPdf leave
// delta lobes out, as pbrt-v4's do.
#ifndef PT_BSDF_H
#define PT_BSDF_H

#include "gltf_material_fields.h"
#include "sampling.h"
#include "shared_types.h"
#include "sheen.h"
#include "sheen_albedo.h"

#ifdef __cplusplus
namespace pt {
#endif

// Which material types the code is compiled for. The shader defines these as the constants
// it is compiled with for the scene, so that types it does not use fold away; C++ has them all.
#ifndef PT_HAS_CONDUCTOR
#define PT_HAS_CONDUCTOR true
#define PT_HAS_DIELECTRIC true
#define PT_HAS_THIN_DIELECTRIC true
#define PT_HAS_DIFFUSE_TRANSMISSION true
#define PT_HAS_COATED_DIFFUSE true
#define PT_HAS_GLTF true
#endif
// glTF's material extensions (transmission, volume, clearcoat, specular: gltfLayered*), which
// the shader compiles in only for scenes with a material that uses one.
#ifndef PT_HAS_GLTF_LAYERS
#define PT_HAS_GLTF_LAYERS true
#endif
// Of those, KHR_materials_sheen, and a clear coat with a normal of its own (kGltfCoatNormal):
// compiled in only for scenes that have them.
#ifndef PT_HAS_GLTF_SHEEN
#define PT_HAS_GLTF_SHEEN true
#endif
#ifndef PT_HAS_GLTF_COAT_NORMAL
#define PT_HAS_GLTF_COAT_NORMAL true
#endif

// Counts an iteration of the layered BSDF's loops where the shader keeps count of its loops
// (lavapipe caps them; see pathtrace.comp); nothing in C++.
#ifndef PT_LOOP_TICK
#define PT_LOOP_TICK()
#endif

// ---- Sample records and flags ------------------------------------------------------------

PT_CONST uint kBsdfReflection = 1u;    // wi on wo's side of the surface
PT_CONST uint kBsdfTransmission = 2u;  // wi on the other side
PT_CONST uint kBsdfSpecular = 4u;      // a delta lobe: no light sampling can find wi
// Restricting a sampler to one kind of scattering (pbrt-v4's BxDFReflTransFlags), as the
// layered BSDF's random walk asks of its interfaces.
PT_CONST uint kSampleReflection = 1u;
PT_CONST uint kSampleTransmission = 2u;
PT_CONST uint kSampleAll = 3u;

// One sampled direction. flags == 0: no sample (the path ends). pdfIsProportional: pdf is
// only proportional to the density of wi (the layered BSDF's random walk), so that f / pdf is
// right but MIS must ask bsdfPdf for the density (an estimate of it).
struct BsdfSample {
  vec3 f;                  // BSDF value (a delta's weight for a specular sample)
  float pdf;               // solid-angle density (or a discrete probability, if specular)
  vec3 wi;                 // sampled direction, local frame
  uint flags;              // kBsdf* bits, 0 when sampling failed
  float eta;               // relative index of refraction crossed by a transmission, else 1
  bool pdfIsProportional;  // see above
};

PT_INLINE BsdfSample noBsdfSample() {
  return BsdfSample(vec3(0.0f), 0.0f, vec3(0.0f, 0.0f, 1.0f), 0u, 1.0f, false);
}

// ---- Local-frame trigonometry -------------------------------------------------------------

PT_INLINE float absCosTheta(vec3 w) {
  return abs(w.z);
}
PT_INLINE bool sameHemisphere(vec3 a, vec3 b) {
  return a.z * b.z > 0.0f;
}
PT_INLINE float sqr(float x) {
  return x * x;
}
PT_INLINE float safeSqrt(float x) {
  return sqrt(max(0.0f, x));
}
PT_INLINE vec3 reflectAbout(vec3 wo, vec3 n) {
  return -wo + (2.0f * dot(wo, n)) * n;
}
// Refraction of wi through a surface of normal n (either side) and relative index eta
// (inside over outside, n pointing outside). False on total internal reflection. etap: the
// relative index the ray actually crossed (eta, or 1 / eta coming from inside).
PT_INLINE bool refractAbout(vec3 wi, vec3 n, float eta, PT_OUT(float) etap, PT_OUT(vec3) wt) {
  float cosThetaI = dot(n, wi);
  etap = eta;
  if (cosThetaI < 0.0f) {
    etap = 1.0f / eta;
    cosThetaI = -cosThetaI;
    n = -n;
  }
  float sin2ThetaI = max(0.0f, 1.0f - cosThetaI * cosThetaI);
  float sin2ThetaT = sin2ThetaI / (etap * etap);
  wt = vec3(0.0f);
  if (sin2ThetaT >= 1.0f) return false;
  float cosThetaT = safeSqrt(1.0f - sin2ThetaT);
  wt = -wi / etap + (cosThetaI / etap - cosThetaT) * n;
  return true;
}

// ---- Fresnel equations -------------------------------------------------------------------

// Unpolarized Fresnel reflectance of a dielectric interface (pbrt-v4's FrDielectric): eta is
// the index inside over outside; a negative cosine means the ray arrives from inside.
PT_INLINE float frDielectric(float cosThetaI, float eta) {
  cosThetaI = clamp(cosThetaI, -1.0f, 1.0f);
  if (cosThetaI < 0.0f) {
    eta = 1.0f / eta;
    cosThetaI = -cosThetaI;
  }
  float sin2ThetaI = 1.0f - cosThetaI * cosThetaI;
  float sin2ThetaT = sin2ThetaI / (eta * eta);
  if (sin2ThetaT >= 1.0f) return 1.0f;  // total internal reflection
  float cosThetaT = safeSqrt(1.0f - sin2ThetaT);
  float rParallel = (eta * cosThetaI - cosThetaT) / (eta * cosThetaI + cosThetaT);
  float rPerpendicular = (cosThetaI - eta * cosThetaT) / (cosThetaI + eta * cosThetaT);
  return (rParallel * rParallel + rPerpendicular * rPerpendicular) * 0.5f;
}

// Complex numbers as vec2 (real, imaginary), for the conductor's Fresnel term.
PT_INLINE vec2 complexMul(vec2 a, vec2 b) {
  return vec2(a.x * b.x - a.y * b.y, a.x * b.y + a.y * b.x);
}
PT_INLINE vec2 complexDiv(vec2 a, vec2 b) {
  float scale = 1.0f / (b.x * b.x + b.y * b.y);
  return vec2(scale * (a.x * b.x + a.y * b.y), scale * (a.y * b.x - a.x * b.y));
}
PT_INLINE float complexNorm(vec2 a) {
  return a.x * a.x + a.y * a.y;
}
// The principal square root, as pbrt-v4's pstd::sqrt for complex numbers.
PT_INLINE vec2 complexSqrt(vec2 z) {
  float n = sqrt(z.x * z.x + z.y * z.y);
  if (n == 0.0f) return vec2(0.0f);
  float t1 = sqrt(0.5f * (n + abs(z.x)));
  float t2 = 0.5f * z.y / t1;
  if (z.x >= 0.0f) return vec2(t1, t2);
  return vec2(abs(t2), z.y >= 0.0f ? t1 : -t1);
}

// Fresnel reflectance of a conductor of complex index eta + i k, one channel (pbrt-v4's
// FrComplex).
PT_INLINE float frComplex1(float cosThetaI, float etaRe, float etaIm) {
  cosThetaI = clamp(cosThetaI, 0.0f, 1.0f);
  vec2 eta = vec2(etaRe, etaIm);
  float sin2ThetaI = 1.0f - cosThetaI * cosThetaI;
  vec2 sin2ThetaT = complexDiv(vec2(sin2ThetaI, 0.0f), complexMul(eta, eta));
  vec2 cosThetaT = complexSqrt(vec2(1.0f, 0.0f) - sin2ThetaT);
  vec2 etaCosI = eta * cosThetaI;
  vec2 rParallel = complexDiv(etaCosI - cosThetaT, etaCosI + cosThetaT);
  vec2 etaCosT = complexMul(eta, cosThetaT);
  vec2 rPerpendicular =
      complexDiv(vec2(cosThetaI, 0.0f) - etaCosT, vec2(cosThetaI, 0.0f) + etaCosT);
  return (complexNorm(rParallel) + complexNorm(rPerpendicular)) * 0.5f;
}
PT_INLINE vec3 frComplex(float cosThetaI, vec3 eta, vec3 k) {
  return vec3(frComplex1(cosThetaI, eta.x, k.x), frComplex1(cosThetaI, eta.y, k.y),
              frComplex1(cosThetaI, eta.z, k.z));
}

// ---- Trowbridge-Reitz (GGX) microfacet distribution -----------------------------------------
// Anisotropic, alpha per tangent axis; visible normals sampled as in Heitz 2018 ("Sampling the
// GGX Distribution of Visible Normals", JCGT), pbrt-v4's Sample_wm.

struct TrowbridgeReitz {
  float alphaX;
  float alphaY;
};

// Below this alpha the surface is treated as perfectly smooth (pbrt-v4's EffectivelySmooth).
PT_CONST float kSmoothAlpha = 1e-3f;
PT_INLINE bool effectivelySmooth(TrowbridgeReitz d) {
  return max(d.alphaX, d.alphaY) < kSmoothAlpha;
}

// pbrt-v4's RoughnessToAlpha, applied by the host when "remaproughness" is true.
PT_INLINE float roughnessToAlpha(float roughness) {
  return sqrt(roughness);
}

PT_INLINE float trD(TrowbridgeReitz d, vec3 wm) {
  float cos2Theta = wm.z * wm.z;
  float cos4Theta = cos2Theta * cos2Theta;
  if (cos4Theta < 1e-16f) return 0.0f;
  // tan^2(theta) (cos^2(phi) / ax^2 + sin^2(phi) / ay^2), from the components directly: pbrt-v4
  // takes tan^2 from 1 - cos^2, which cancels near the pole, where a nearly smooth lobe lives
  // (D was 23 % off at alpha 0.0015).
  float e = (sqr(wm.x / d.alphaX) + sqr(wm.y / d.alphaY)) / cos2Theta;
  return 1.0f / (kPi * d.alphaX * d.alphaY * cos4Theta * sqr(1.0f + e));
}

PT_INLINE float trLambda(TrowbridgeReitz d, vec3 w) {
  float cos2Theta = w.z * w.z;
  if (cos2Theta == 0.0f) return 0.0f;  // pbrt-v4: an infinite tan^2 gives 0
  // alpha^2(phi) tan^2(theta), from the components as in trD.
  float alpha2Tan2 = (sqr(w.x * d.alphaX) + sqr(w.y * d.alphaY)) / cos2Theta;
  return (sqrt(1.0f + alpha2Tan2) - 1.0f) * 0.5f;
}

PT_INLINE float trG1(TrowbridgeReitz d, vec3 w) {
  return 1.0f / (1.0f + trLambda(d, w));
}

// Height-correlated masking-shadowing.
PT_INLINE float trG(TrowbridgeReitz d, vec3 wo, vec3 wi) {
  return 1.0f / (1.0f + trLambda(d, wo) + trLambda(d, wi));
}

// Density of the normals visible from w: G1(w) / |cos w| * D(wm) * |w . wm|.
PT_INLINE float trPdf(TrowbridgeReitz d, vec3 w, vec3 wm) {
  return trG1(d, w) / absCosTheta(w) * trD(d, wm) * abs(dot(w, wm));
}

PT_INLINE vec3 trSampleWm(TrowbridgeReitz d, vec3 w, vec2 u) {
  // Transform w to the hemispherical configuration (alpha = 1).
  vec3 wh = normalize(vec3(d.alphaX * w.x, d.alphaY * w.y, w.z));
  if (wh.z < 0.0f) wh = -wh;
  // An orthonormal basis about wh.
  vec3 t1 = wh.z < 0.99999f ? normalize(cross(vec3(0.0f, 0.0f, 1.0f), wh)) : vec3(1.0f, 0.0f, 0.0f);
  vec3 t2 = cross(wh, t1);
  // A uniform point on the unit disk, warped to the projection of the visible hemisphere.
  float r = sqrt(u.x);
  vec2 cs = cosSinTwoPi(u.y);
  vec2 p = r * cs;
  float h = sqrt(1.0f - p.x * p.x);
  float s = (1.0f + wh.z) * 0.5f;
  p.y = (1.0f - s) * h + s * p.y;
  // Reproject onto the hemisphere and back to the ellipsoid configuration.
  float pz = sqrt(max(0.0f, 1.0f - dot(p, p)));
  vec3 nh = p.x * t1 + p.y * t2 + pz * wh;
  return normalize(vec3(d.alphaX * nh.x, d.alphaY * nh.y, max(1e-6f, nh.z)));
}

// ---- Diffuse reflection (the coated material's base) ------------------------------------

PT_INLINE vec3 diffuseF(vec3 r, vec3 wo, vec3 wi) {
  return sameHemisphere(wo, wi) ? r * kInvPi : vec3(0.0f);
}
PT_INLINE float diffusePdf(vec3 wo, vec3 wi, uint sampleFlags) {
  if ((sampleFlags & kSampleReflection) == 0u || !sameHemisphere(wo, wi)) return 0.0f;
  return absCosTheta(wi) * kInvPi;
}
PT_INLINE BsdfSample diffuseSample(vec3 r, vec3 wo, vec2 u, uint sampleFlags) {
  if ((sampleFlags & kSampleReflection) == 0u) return noBsdfSample();
  vec3 wi = sampleCosineHemisphere(u);
  if (wo.z < 0.0f) wi.z = -wi.z;
  float pdf = absCosTheta(wi) * kInvPi;
  if (!(pdf > 0.0f)) return noBsdfSample();
  return BsdfSample(r * kInvPi, pdf, wi, kBsdfReflection, 1.0f, false);
}

// ---- Conductor -----------------------------------------------------------------------------
// pbrt-v4's ConductorBxDF: specular reflection scaled by the complex Fresnel term when
// effectively smooth, else the Torrance-Sparrow model over Trowbridge-Reitz. Two-sided.

PT_INLINE vec3 conductorF(TrowbridgeReitz d, vec3 eta, vec3 k, vec3 wo, vec3 wi) {
  if (!sameHemisphere(wo, wi) || effectivelySmooth(d)) return vec3(0.0f);
  float cosThetaO = absCosTheta(wo);
  float cosThetaI = absCosTheta(wi);
  if (cosThetaI == 0.0f || cosThetaO == 0.0f) return vec3(0.0f);
  vec3 wm = wi + wo;
  if (dot(wm, wm) == 0.0f) return vec3(0.0f);
  wm = normalize(wm);
  vec3 F = frComplex(abs(dot(wo, wm)), eta, k);
  return trD(d, wm) * F * trG(d, wo, wi) / (4.0f * cosThetaI * cosThetaO);
}

PT_INLINE float conductorPdf(TrowbridgeReitz d, vec3 wo, vec3 wi) {
  if (!sameHemisphere(wo, wi) || effectivelySmooth(d)) return 0.0f;
  vec3 wm = wo + wi;
  if (dot(wm, wm) == 0.0f) return 0.0f;
  wm = normalize(wm);
  if (wm.z < 0.0f) wm = -wm;
  return trPdf(d, wo, wm) / (4.0f * abs(dot(wo, wm)));
}

PT_INLINE BsdfSample conductorSample(TrowbridgeReitz d, vec3 eta, vec3 k, vec3 wo, vec2 u) {
  if (effectivelySmooth(d)) {
    // Specular reflection.
    vec3 wi = vec3(-wo.x, -wo.y, wo.z);
    float cosThetaI = absCosTheta(wi);
    if (cosThetaI == 0.0f) return noBsdfSample();
    return BsdfSample(frComplex(cosThetaI, eta, k) / cosThetaI, 1.0f, wi,
                      kBsdfReflection | kBsdfSpecular, 1.0f, false);
  }
  // Sample a visible microfacet normal and reflect about it.
  if (wo.z == 0.0f) return noBsdfSample();
  vec3 wm = trSampleWm(d, wo, u);
  vec3 wi = reflectAbout(wo, wm);
  if (!sameHemisphere(wo, wi)) return noBsdfSample();
  float pdf = trPdf(d, wo, wm) / (4.0f * abs(dot(wo, wm)));
  float cosThetaO = absCosTheta(wo);
  float cosThetaI = absCosTheta(wi);
  if (cosThetaI == 0.0f || cosThetaO == 0.0f || !(pdf > 0.0f)) return noBsdfSample();
  vec3 F = frComplex(abs(dot(wo, wm)), eta, k);
  vec3 f = trD(d, wm) * F * trG(d, wo, wi) / (4.0f * cosThetaI * cosThetaO);
  return BsdfSample(f, pdf, wi, kBsdfReflection, 1.0f, false);
}

// ---- Dielectric ------------------------------------------------------------------------------
// pbrt-v4's DielectricBxDF: eta is the index of the side the normal points away from (inside)
// over the other. Smooth (specular reflection or refraction, chosen in proportion to the
// Fresnel reflectance) when eta is 1 or the distribution effectively smooth, else rough
// (Walter et al. 2007 over Trowbridge-Reitz). `radiance`: the path carries radiance from a
// camera, and refraction scales it by 1 / eta^2 (pbrt-v4's TransportMode::Radiance); false for
// importance, as the layered BSDF's paths from the light side need.

PT_INLINE bool dielectricIsSmooth(TrowbridgeReitz d, float eta) {
  return eta == 1.0f || effectivelySmooth(d);
}

// The generalized half vector of wo and wi facing +z, or false where there is none or the
// microfacet faces away from either direction.
PT_INLINE bool dielectricHalfVector(float eta, vec3 wo, vec3 wi, PT_OUT(vec3) wm,
                                    PT_OUT(float) etap) {
  float cosThetaO = wo.z;
  float cosThetaI = wi.z;
  bool reflect = cosThetaI * cosThetaO > 0.0f;
  etap = 1.0f;
  if (!reflect) etap = cosThetaO > 0.0f ? eta : 1.0f / eta;
  wm = wi * etap + wo;
  if (cosThetaI == 0.0f || cosThetaO == 0.0f || dot(wm, wm) == 0.0f) return false;
  wm = normalize(wm);
  if (wm.z < 0.0f) wm = -wm;
  // Discard back-facing microfacets.
  return !(dot(wm, wi) * cosThetaI < 0.0f || dot(wm, wo) * cosThetaO < 0.0f);
}

PT_INLINE vec3 dielectricF(TrowbridgeReitz d, float eta, vec3 wo, vec3 wi, bool radiance) {
  if (dielectricIsSmooth(d, eta)) return vec3(0.0f);
  vec3 wm;
  float etap;
  if (!dielectricHalfVector(eta, wo, wi, wm, etap)) return vec3(0.0f);
  float F = frDielectric(dot(wo, wm), eta);
  if (wi.z * wo.z > 0.0f) {
    return vec3(trD(d, wm) * trG(d, wo, wi) * F / abs(4.0f * wi.z * wo.z));
  }
  float denom = sqr(dot(wi, wm) + dot(wo, wm) / etap) * wi.z * wo.z;
  float ft = trD(d, wm) * (1.0f - F) * trG(d, wo, wi) * abs(dot(wi, wm) * dot(wo, wm) / denom);
  if (radiance) ft /= sqr(etap);
  return vec3(ft);
}

PT_INLINE float dielectricPdf(TrowbridgeReitz d, float eta, vec3 wo, vec3 wi, uint sampleFlags) {
  if (dielectricIsSmooth(d, eta)) return 0.0f;
  vec3 wm;
  float etap;
  if (!dielectricHalfVector(eta, wo, wi, wm, etap)) return 0.0f;
  // The probabilities of reflection and transmission.
  float R = frDielectric(dot(wo, wm), eta);
  float T = 1.0f - R;
  float pr = (sampleFlags & kSampleReflection) != 0u ? R : 0.0f;
  float pt = (sampleFlags & kSampleTransmission) != 0u ? T : 0.0f;
  if (pr == 0.0f && pt == 0.0f) return 0.0f;
  if (wi.z * wo.z > 0.0f) return trPdf(d, wo, wm) / (4.0f * abs(dot(wo, wm))) * pr / (pr + pt);
  float denom = sqr(dot(wi, wm) + dot(wo, wm) / etap);
  float dwmDwi = abs(dot(wi, wm)) / denom;
  return trPdf(d, wo, wm) * dwmDwi * pt / (pr + pt);
}

PT_INLINE BsdfSample dielectricSample(TrowbridgeReitz d, float eta, vec3 wo, float uc, vec2 u,
                                      bool radiance, uint sampleFlags) {
  if (dielectricIsSmooth(d, eta)) {
    // Specular reflection or transmission, in proportion to the Fresnel terms.
    float R = frDielectric(wo.z, eta);
    float T = 1.0f - R;
    float pr = (sampleFlags & kSampleReflection) != 0u ? R : 0.0f;
    float pt = (sampleFlags & kSampleTransmission) != 0u ? T : 0.0f;
    if (pr == 0.0f && pt == 0.0f) return noBsdfSample();
    if (uc < pr / (pr + pt)) {
      vec3 wi = vec3(-wo.x, -wo.y, wo.z);
      if (wi.z == 0.0f) return noBsdfSample();
      return BsdfSample(vec3(R / absCosTheta(wi)), pr / (pr + pt), wi,
                        kBsdfReflection | kBsdfSpecular, 1.0f, false);
    }
    vec3 wi;
    float etap;
    if (!refractAbout(wo, vec3(0.0f, 0.0f, 1.0f), eta, etap, wi) || wi.z == 0.0f) {
      return noBsdfSample();
    }
    float ft = T / absCosTheta(wi);
    if (radiance) ft /= sqr(etap);
    return BsdfSample(vec3(ft), pt / (pr + pt), wi, kBsdfTransmission | kBsdfSpecular, etap, false);
  }
  // Rough: sample a visible microfacet normal, then reflect or refract about it.
  if (wo.z == 0.0f) return noBsdfSample();
  vec3 wm = trSampleWm(d, wo, u);
  float R = frDielectric(dot(wo, wm), eta);
  float T = 1.0f - R;
  float pr = (sampleFlags & kSampleReflection) != 0u ? R : 0.0f;
  float pt = (sampleFlags & kSampleTransmission) != 0u ? T : 0.0f;
  if (pr == 0.0f && pt == 0.0f) return noBsdfSample();
  if (uc < pr / (pr + pt)) {
    vec3 wi = reflectAbout(wo, wm);
    if (!sameHemisphere(wo, wi)) return noBsdfSample();
    float pdf = trPdf(d, wo, wm) / (4.0f * abs(dot(wo, wm))) * pr / (pr + pt);
    vec3 f = vec3(trD(d, wm) * trG(d, wo, wi) * R / (4.0f * wi.z * wo.z));
    if (!(pdf > 0.0f)) return noBsdfSample();
    return BsdfSample(f, pdf, wi, kBsdfReflection, 1.0f, false);
  }
  vec3 wi;
  float etap;
  bool tir = !refractAbout(wo, wm, eta, etap, wi);
  if (sameHemisphere(wo, wi) || wi.z == 0.0f || tir) return noBsdfSample();
  float denom = sqr(dot(wi, wm) + dot(wo, wm) / etap);
  float dwmDwi = abs(dot(wi, wm)) / denom;
  float pdf = trPdf(d, wo, wm) * dwmDwi * pt / (pr + pt);
  float ft =
      T * trD(d, wm) * trG(d, wo, wi) * abs(dot(wi, wm) * dot(wo, wm) / (wi.z * wo.z * denom));
  if (radiance) ft /= sqr(etap);
  if (!(pdf > 0.0f)) return noBsdfSample();
  return BsdfSample(vec3(ft), pdf, wi, kBsdfTransmission, etap, false);
}

// ---- Thin dielectric ---------------------------------------------------------------------
// pbrt-v4's ThinDielectricBxDF: a pane whose two parallel interfaces reflect back and forth;
// the reflectance sums the geometric series R + T^2 R / (1 - R^2). Transmission passes
// straight through. Only delta lobes.

PT_INLINE BsdfSample thinDielectricSample(float eta, vec3 wo, float uc) {
  float R = frDielectric(absCosTheta(wo), eta);
  float T = 1.0f - R;
  if (R < 1.0f) {
    R += sqr(T) * R / (1.0f - sqr(R));
    T = 1.0f - R;
  }
  if (R == 0.0f && T == 0.0f) return noBsdfSample();
  if (wo.z == 0.0f) return noBsdfSample();
  if (uc < R / (R + T)) {
    vec3 wi = vec3(-wo.x, -wo.y, wo.z);
    return BsdfSample(vec3(R / absCosTheta(wi)), R / (R + T), wi, kBsdfReflection | kBsdfSpecular,
                      1.0f, false);
  }
  vec3 wi = -wo;
  return BsdfSample(vec3(T / absCosTheta(wi)), T / (R + T), wi, kBsdfTransmission | kBsdfSpecular,
                    1.0f, false);
}

// ---- Diffuse transmission ------------------------------------------------------------------
// pbrt-v4's DiffuseTransmissionBxDF: Lambertian reflection r / pi on wo's side, Lambertian
// transmission t / pi on the other; each side sampled cosine-weighted, chosen in proportion
// to the largest channel of r and t.

PT_INLINE vec3 diffuseTransmissionF(vec3 r, vec3 t, vec3 wo, vec3 wi) {
  return sameHemisphere(wo, wi) ? r * kInvPi : t * kInvPi;
}
PT_INLINE float diffuseTransmissionPdf(vec3 r, vec3 t, vec3 wo, vec3 wi) {
  float pr = maxComponent(r);
  float pt = maxComponent(t);
  if (pr == 0.0f && pt == 0.0f) return 0.0f;
  float p = absCosTheta(wi) * kInvPi;
  return sameHemisphere(wo, wi) ? p * pr / (pr + pt) : p * pt / (pr + pt);
}
PT_INLINE BsdfSample diffuseTransmissionSample(vec3 r, vec3 t, vec3 wo, float uc, vec2 u) {
  float pr = maxComponent(r);
  float pt = maxComponent(t);
  if (pr == 0.0f && pt == 0.0f) return noBsdfSample();
  vec3 wi = sampleCosineHemisphere(u);
  float p = absCosTheta(wi) * kInvPi;
  if (!(p > 0.0f)) return noBsdfSample();
  if (uc < pr / (pr + pt)) {
    if (wo.z < 0.0f) wi.z = -wi.z;
    return BsdfSample(r * kInvPi, p * pr / (pr + pt), wi, kBsdfReflection, 1.0f, false);
  }
  if (wo.z > 0.0f) wi.z = -wi.z;
  return BsdfSample(t * kInvPi, p * pt / (pr + pt), wi, kBsdfTransmission, 1.0f, false);
}

// ---- Random numbers of the layered BSDF's random walks -----------------------------------
// pbrt-v4 seeds a generator from a hash of the directions. Here the stream is a function of the
// path's own random-number coordinates (pixel, sample, dimension, seed) and of what it is for
// (kStream*), so that the CPU reference and the shader take the same walks even where their
// directions differ in the last bits.

struct RandomStream {
  uvec4 key;  // .w advances by one per number drawn
};
PT_CONST uint kStreamSample = 1u;     // sampling a direction
PT_CONST uint kStreamEval = 2u;       // bsdfF at a light sample
PT_CONST uint kStreamLightPdf = 3u;   // bsdfPdf at a light sample
PT_CONST uint kStreamSamplePdf = 4u;  // bsdfPdf of a sampled direction (pdfIsProportional)

PT_INLINE RandomStream makeRandomStream(uvec2 pixel, uint sampleIndex, uint dimension, uint seed,
                                        uint purpose) {
  uvec4 h = pcg4d(uvec4(pixel.x, pixel.y, sampleIndex, dimension + seed * 0x9E3779B9u));
  return RandomStream(uvec4(h.x, h.y, h.z ^ purpose * 0x85EBCA6Bu, h.w));
}

// A uniform number in [0, 1), 24 bits (exact in float on both sides).
PT_INLINE float nextRandom(PT_INOUT(RandomStream) s) {
  uvec4 h = pcg4d(s.key);
  s.key.w += 1u;
  return float(h.x >> 8u) * (1.0f / 16777216.0f);
}
// Two numbers, drawn in order. (Never vec2(nextRandom(s), nextRandom(s)): C++ leaves the
// order of a call's arguments open, and GCC draws the second first, GLSL the first.)
PT_INLINE vec2 nextRandom2(PT_INOUT(RandomStream) s) {
  float a = nextRandom(s);
  float b = nextRandom(s);
  return vec2(a, b);
}

// ---- Henyey-Greenstein phase function (the coat's medium) ----------------------------------
// pbrt-v4's conventions: wo and wi both point away from the scattering point, so forward
// scattering (g > 0) sends wi near -wo.

PT_INLINE float henyeyGreenstein(float cosTheta, float g) {
  g = clamp(g, -0.99f, 0.99f);
  float denom = 1.0f + g * g + 2.0f * g * cosTheta;
  return kInv4Pi * (1.0f - g * g) / (denom * safeSqrt(denom));
}

// Samples wi for wo; pdf = p = henyeyGreenstein(dot(wo, wi), g).
PT_INLINE vec3 sampleHenyeyGreenstein(vec3 wo, float g, vec2 u, PT_OUT(float) pdf) {
  g = clamp(g, -0.99f, 0.99f);
  float cosTheta;
  if (abs(g) < 1e-3f) {
    cosTheta = 1.0f - 2.0f * u.x;
  } else {
    cosTheta =
        -1.0f / (2.0f * g) * (1.0f + g * g - sqr((1.0f - g * g) / (1.0f + g - 2.0f * g * u.x)));
  }
  float sinTheta = safeSqrt(1.0f - cosTheta * cosTheta);
  vec2 cs = cosSinTwoPi(u.y);
  pdf = henyeyGreenstein(cosTheta, g);
  return localToWorld(vec3(sinTheta * cs.x, sinTheta * cs.y, cosTheta), wo);
}

// ---- Coated diffuse: pbrt-v4's LayeredBxDF<DielectricBxDF, DiffuseBxDF, twoSided = true> ----
// A dielectric coat (eta, roughness) over a Lambertian base (reflectance), with a medium of
// the given thickness, albedo and g between them. f and sampling are stochastic estimates
// by random walks between the two interfaces (unbiased; maxDepth bounds a walk, with Russian
// roulette after four steps); the pdf is an estimate mixed with the uniform density, good
// for MIS only (pbrt-v4's choice). Interfaces are named by z: the coat at z = thickness, the
// base at z = 0. Two-sided: a wo below the surface is mirrored above it.

struct CoatedDiffuse {
  TrowbridgeReitz coat;
  float eta;
  vec3 reflectance;
  vec3 albedo;
  float thickness;
  float g;
  uint maxDepth;
  uint nSamples;
};

PT_INLINE CoatedDiffuse coatedDiffuseOf(Material m) {
  return CoatedDiffuse(TrowbridgeReitz(m.alphaX, m.alphaY), m.eta.x, m.reflectance, m.transmittance,
                       max(m.thickness, 1.17549435e-38f), m.g, m.maxDepth, m.nSamples);
}

// The medium's transmittance over depth dz along w (unit extinction).
PT_INLINE float layerTransmittance(float dz, vec3 w) {
  if (abs(dz) <= 1.17549435e-38f) return 1.0f;
  return exp(-abs(dz / w.z));
}

// The two interfaces seen from the walk: the coat (top) or the base (bottom).
PT_INLINE vec3 coatedInterfaceF(CoatedDiffuse c, bool top, vec3 wo, vec3 wi, bool radiance) {
  return top ? dielectricF(c.coat, c.eta, wo, wi, radiance) : diffuseF(c.reflectance, wo, wi);
}
PT_INLINE float coatedInterfacePdf(CoatedDiffuse c, bool top, vec3 wo, vec3 wi, uint flags) {
  return top ? dielectricPdf(c.coat, c.eta, wo, wi, flags) : diffusePdf(wo, wi, flags);
}
PT_INLINE BsdfSample coatedInterfaceSample(CoatedDiffuse c, bool top, vec3 wo, float uc, vec2 u,
                                           bool radiance, uint flags) {
  return top ? dielectricSample(c.coat, c.eta, wo, uc, u, radiance, flags)
             : diffuseSample(c.reflectance, wo, u, flags);
}
PT_INLINE bool sampleUsable(BsdfSample s) {
  return s.flags != 0u && maxComponent(s.f) > 0.0f && s.pdf > 0.0f && s.wi.z != 0.0f;
}

PT_INLINE vec3 coatedDiffuseF(CoatedDiffuse c, vec3 wo, vec3 wi, bool radiance, RandomStream rng) {
  if (wo.z < 0.0f) {
    wo = -wo;
    wi = -wi;
  }
  // Entered through the coat (two-sided); reflection leaves through it too, transmission
  // (none here: the base is opaque) would leave through the base.
  bool exitTop = sameHemisphere(wo, wi);
  float exitZ = exitTop ? c.thickness : 0.0f;
  bool coatSmooth = dielectricIsSmooth(c.coat, c.eta);
  bool exitSpecular = exitTop ? coatSmooth : false;
  bool nonExitSpecular = exitTop ? false : coatSmooth;
  float n = float(c.nSamples);
  // Reflection at the entrance interface.
  vec3 f = vec3(0.0f);
  if (exitTop) f = n * dielectricF(c.coat, c.eta, wo, wi, radiance);

  for (uint s = 0u; s < c.nSamples; ++s) {
    PT_LOOP_TICK();
    // Sample the transmission through the entrance interface, and a virtual light path from
    // wi through the exit interface (pbrt-v4's wos and wis).
    float uc = nextRandom(rng);
    vec2 u = nextRandom2(rng);
    BsdfSample wos = dielectricSample(c.coat, c.eta, wo, uc, u, radiance, kSampleTransmission);
    if (!sampleUsable(wos)) continue;
    uc = nextRandom(rng);
    u = nextRandom2(rng);
    BsdfSample wis = coatedInterfaceSample(c, exitTop, wi, uc, u, !radiance, kSampleTransmission);
    if (!sampleUsable(wis)) continue;

    vec3 beta = wos.f * absCosTheta(wos.wi) / wos.pdf;
    float z = c.thickness;
    vec3 w = wos.wi;
    for (uint depth = 0u; depth < c.maxDepth; ++depth) {
      PT_LOOP_TICK();
      // Possibly end the walk with Russian roulette.
      if (depth > 3u && maxComponent(beta) < 0.25f) {
        float q = max(0.0f, 1.0f - maxComponent(beta));
        if (nextRandom(rng) < q) break;
        beta /= 1.0f - q;
      }
      if (maxComponent(c.albedo) == 0.0f) {
        // No scattering medium: advance to the other interface.
        z = z == c.thickness ? 0.0f : c.thickness;
        beta *= layerTransmittance(c.thickness, w);
      } else {
        // Sample a scattering event in the medium.
        float dz = -log(1.0f - nextRandom(rng)) * abs(w.z);
        float zp = w.z > 0.0f ? z + dz : z - dz;
        if (zp == z) continue;
        if (0.0f < zp && zp < c.thickness) {
          // Scattering in the medium: towards wis's direction (NEE), then a new direction.
          float wt = 1.0f;
          if (!exitSpecular) {
            wt = powerHeuristic(wis.pdf, henyeyGreenstein(dot(-w, -wis.wi), c.g));
          }
          f += beta * c.albedo * henyeyGreenstein(dot(-w, -wis.wi), c.g) * wt *
               layerTransmittance(zp - exitZ, wis.wi) * wis.f / wis.pdf;
          float phasePdf;
          vec3 wNew = sampleHenyeyGreenstein(-w, c.g, nextRandom2(rng), phasePdf);
          if (!(phasePdf > 0.0f) || wNew.z == 0.0f) continue;
          // The phase function's value equals its pdf: beta *= albedo.
          beta *= c.albedo;
          w = wNew;
          z = zp;
          // Possibly leave through the exit interface towards wi.
          if (((z < exitZ && w.z > 0.0f) || (z > exitZ && w.z < 0.0f)) && !exitSpecular) {
            vec3 fExit = coatedInterfaceF(c, exitTop, -w, wi, radiance);
            if (maxComponent(fExit) > 0.0f) {
              // The other strategy, wis, samples the internal direction -w from wi: its
              // density over -w (pbrt-v4 takes the density over wi here, another measure, and
              // so its weights do not sum to one: f came out up to 8 % too bright).
              float exitPdf = coatedInterfacePdf(c, exitTop, wi, -w, kSampleTransmission);
              float wt2 = powerHeuristic(phasePdf, exitPdf);
              f += beta * layerTransmittance(zp - exitZ, wNew) * fExit * wt2;
            }
          }
          continue;
        }
        z = clamp(zp, 0.0f, c.thickness);
      }
      if (z == exitZ) {
        // Reflection at the exit interface back into the layer.
        float uc2 = nextRandom(rng);
        vec2 u2 = nextRandom2(rng);
        BsdfSample bs = coatedInterfaceSample(c, exitTop, -w, uc2, u2, radiance, kSampleReflection);
        if (!sampleUsable(bs)) break;
        beta *= bs.f * absCosTheta(bs.wi) / bs.pdf;
        w = bs.wi;
      } else {
        // Scattering at the other interface: first towards wis (NEE).
        if (!nonExitSpecular) {
          float wt = 1.0f;
          if (!exitSpecular) {
            wt = powerHeuristic(wis.pdf, coatedInterfacePdf(c, !exitTop, -w, -wis.wi, kSampleAll));
          }
          f += beta * coatedInterfaceF(c, !exitTop, -w, -wis.wi, radiance) * absCosTheta(wis.wi) *
               wt * layerTransmittance(c.thickness, wis.wi) * wis.f / wis.pdf;
        }
        // Then a new direction from that interface's BSDF.
        float uc2 = nextRandom(rng);
        vec2 u2 = nextRandom2(rng);
        BsdfSample bs =
            coatedInterfaceSample(c, !exitTop, -w, uc2, u2, radiance, kSampleReflection);
        if (!sampleUsable(bs)) break;
        beta *= bs.f * absCosTheta(bs.wi) / bs.pdf;
        w = bs.wi;
        if (!exitSpecular) {
          // Towards wi through the exit interface along the new direction (NEE by BSDF).
          vec3 fExit = coatedInterfaceF(c, exitTop, -w, wi, radiance);
          if (maxComponent(fExit) > 0.0f) {
            float wt = 1.0f;
            if (!nonExitSpecular) {
              // wis's density over the internal direction -w (see above).
              float exitPdf = coatedInterfacePdf(c, exitTop, wi, -w, kSampleTransmission);
              wt = powerHeuristic(bs.pdf, exitPdf);
            }
            f += beta * layerTransmittance(c.thickness, bs.wi) * fExit * wt;
          }
        }
      }
    }
  }
  return f / n;
}

PT_INLINE BsdfSample coatedDiffuseSample(CoatedDiffuse c, vec3 wo, float uc, vec2 u, bool radiance,
                                         RandomStream rng) {
  bool flipWi = false;
  if (wo.z < 0.0f) {
    wo = -wo;
    flipWi = true;
  }
  // Sample the coat to get the first direction.
  BsdfSample bs = dielectricSample(c.coat, c.eta, wo, uc, u, radiance, kSampleAll);
  if (!sampleUsable(bs)) return noBsdfSample();
  if ((bs.flags & kBsdfReflection) != 0u) {
    if (flipWi) bs.wi = -bs.wi;
    bs.pdfIsProportional = true;
    return bs;
  }
  vec3 w = bs.wi;
  bool specularPath = (bs.flags & kBsdfSpecular) != 0u;
  vec3 f = bs.f * absCosTheta(bs.wi);
  float pdf = bs.pdf;
  float z = c.thickness;
  for (uint depth = 0u; depth < c.maxDepth; ++depth) {
    PT_LOOP_TICK();
    // Possibly end the walk with Russian roulette.
    float rrBeta = maxComponent(f) / pdf;
    if (depth > 3u && rrBeta < 0.25f) {
      float q = max(0.0f, 1.0f - rrBeta);
      if (nextRandom(rng) < q) return noBsdfSample();
      pdf *= 1.0f - q;
    }
    if (w.z == 0.0f) return noBsdfSample();
    if (maxComponent(c.albedo) > 0.0f) {
      // Possibly scatter in the medium.
      float dz = -log(1.0f - nextRandom(rng)) * absCosTheta(w);
      float zp = w.z > 0.0f ? z + dz : z - dz;
      if (zp == z) return noBsdfSample();
      if (0.0f < zp && zp < c.thickness) {
        float phasePdf;
        vec3 wNew = sampleHenyeyGreenstein(-w, c.g, nextRandom2(rng), phasePdf);
        if (!(phasePdf > 0.0f) || wNew.z == 0.0f) return noBsdfSample();
        f *= c.albedo * phasePdf;
        pdf *= phasePdf;
        specularPath = false;
        w = wNew;
        z = zp;
        continue;
      }
      z = clamp(zp, 0.0f, c.thickness);
    } else {
      // Advance to the other interface.
      z = z == c.thickness ? 0.0f : c.thickness;
      f *= layerTransmittance(c.thickness, w);
    }
    // Scatter at the interface reached.
    bool top = z != 0.0f;
    float uc2 = nextRandom(rng);
    vec2 u2 = nextRandom2(rng);
    BsdfSample is = coatedInterfaceSample(c, top, -w, uc2, u2, radiance, kSampleAll);
    if (!sampleUsable(is)) return noBsdfSample();
    f *= is.f;
    pdf *= is.pdf;
    specularPath = specularPath && (is.flags & kBsdfSpecular) != 0u;
    w = is.wi;
    if ((is.flags & kBsdfTransmission) != 0u) {
      // The walk has left the layers.
      uint flags = sameHemisphere(wo, w) ? kBsdfReflection : kBsdfTransmission;
      if (specularPath) flags |= kBsdfSpecular;
      if (flipWi) w = -w;
      // A long walk can take f and pdf down to 0 together (float underflow): no sample, as
      // pbrt-v4's BSDF::Sample_f drops a pdf of 0, rather than 0 / 0.
      if (!(pdf > 0.0f) || !(maxComponent(f) > 0.0f)) return noBsdfSample();
      return BsdfSample(f, pdf, w, flags, 1.0f, true);
    }
    f *= absCosTheta(is.wi);
  }
  return noBsdfSample();
}

PT_INLINE float coatedDiffusePdf(CoatedDiffuse c, vec3 wo, vec3 wi, RandomStream rng) {
  if (wo.z < 0.0f) {
    wo = -wo;
    wi = -wi;
  }
  // Nothing leaves through the opaque base: only reflection has a density.
  if (!sameHemisphere(wo, wi)) return 0.0f;
  float n = float(c.nSamples);
  // Reflection at the coat.
  float pdfSum = n * dielectricPdf(c.coat, c.eta, wo, wi, kSampleReflection);
  bool coatSmooth = dielectricIsSmooth(c.coat, c.eta);
  for (uint s = 0u; s < c.nSamples; ++s) {
    PT_LOOP_TICK();
    // Transmission, reflection at the base, transmission (TRT).
    float uc = nextRandom(rng);
    vec2 u = nextRandom2(rng);
    BsdfSample wos = dielectricSample(c.coat, c.eta, wo, uc, u, true, kSampleTransmission);
    uc = nextRandom(rng);
    u = nextRandom2(rng);
    BsdfSample wis = dielectricSample(c.coat, c.eta, wi, uc, u, false, kSampleTransmission);
    if (wos.flags == 0u || !(maxComponent(wos.f) > 0.0f) || !(wos.pdf > 0.0f) || wis.flags == 0u ||
        !(maxComponent(wis.f) > 0.0f) || !(wis.pdf > 0.0f)) {
      continue;
    }
    if (coatSmooth) {
      pdfSum += diffusePdf(-wos.wi, -wis.wi, kSampleAll);
    } else {
      // The base is diffuse (non-specular): estimate the product by MIS.
      nextRandom(rng);  // the lobe choice, which a diffuse base does not need
      vec2 u2 = nextRandom2(rng);
      BsdfSample rs = diffuseSample(c.reflectance, -wos.wi, u2, kSampleAll);
      if (rs.flags != 0u && maxComponent(rs.f) > 0.0f && rs.pdf > 0.0f) {
        float rPdf = diffusePdf(-wos.wi, -wis.wi, kSampleAll);
        pdfSum += powerHeuristic(wis.pdf, rPdf) * rPdf;
        float tPdf = dielectricPdf(c.coat, c.eta, -rs.wi, wi, kSampleAll);
        pdfSum += powerHeuristic(rs.pdf, tPdf) * tPdf;
      }
    }
  }
  // Mix with the uniform density, as pbrt-v4 does, so the estimate is never 0 where f is not.
  return 0.1f * kInv4Pi + 0.9f * (pdfSum / n);
}

// ---- Shading frame ------------------------------------------------------------------------
// z along the normal n (unit); x along `tangent` made orthogonal to n, as pbrt-v4's frame from
// dpdu (a triangle without UVs takes pbrt-v4's default UVs, whose dpdu is v1 - v0); any
// orthonormal pair where the tangent is parallel to n.

struct ShadingFrame {
  vec3 x;
  vec3 y;
  vec3 z;
};

PT_INLINE ShadingFrame makeShadingFrame(vec3 n, vec3 tangent) {
  vec3 t = tangent - dot(n, tangent) * n;
  float len2 = dot(t, t);
  if (!(len2 > 1e-20f)) {
    t = localToWorld(vec3(1.0f, 0.0f, 0.0f), n);
  } else {
    t = t / sqrt(len2);
  }
  return ShadingFrame(t, cross(n, t), n);
}
// The shading normal at barycentrics b (weights of v0, v1, v2): the vertex normals
// interpolated and normalized; ng where they cancel.
PT_INLINE vec3 interpolatedNormal(TriangleNormals t, vec3 b, vec3 ng) {
  vec3 n = b.x * t.n0 + b.y * t.n1 + b.z * t.n2;
  float len2 = dot(n, n);
  return len2 > 0.0f ? n / sqrt(len2) : ng;
}

PT_INLINE vec3 toLocal(ShadingFrame f, vec3 w) {
  return vec3(dot(w, f.x), dot(w, f.y), dot(w, f.z));
}
PT_INLINE vec3 fromLocal(ShadingFrame f, vec3 w) {
  return w.x * f.x + w.y * f.y + w.z * f.z;
}

// ---- glTF metallic-roughness ---------------------------------------------------------------
// The glTF 2.0 specification's material (its appendix B): mix(dielectric_brdf, metal_brdf,
// metallic), where metal_brdf is the Trowbridge-Reitz specular lobe (alpha = roughness^2)
// times Schlick's Fresnel term of f0 = baseColor, and dielectric_brdf is fresnel_mix(ior,
// Lambertian base of baseColor, the same specular lobe) with Schlick's term of
// f0 = ((ior - 1) / (ior + 1))^2. The specular lobe is appendix B's D * G / (4 |N.L| |N.V|)
// with the separable Smith masking-shadowing G = G1(L) G1(V). One difference: appendix B weighs
// the dielectric's two layers by the Fresnel term of each microfacet (V.H); this takes the
// term of the macro surface (N.V), so that the base receives what the layer does not reflect
// and no parameter set reflects more than it receives (with V.H a white base of roughness 0.3
// reflects 1.22 times the light it receives at 80 degrees: docs/gltf.md). Both are the same
// for a smooth surface's specular reflection. Two-sided, reflection only. Material fields:
// reflectance the base colour, eta.x the ior, alphaX = alphaY, thickness the metallic factor.

struct GltfSurface {
  vec3 baseColor;
  float metallic;
  float f0;  // the dielectric's reflectance at normal incidence
  TrowbridgeReitz d;
};

PT_INLINE GltfSurface gltfSurfaceOf(Material m) {
  float r = (m.eta.x - 1.0f) / (m.eta.x + 1.0f);
  return GltfSurface(m.reflectance, m.thickness, r * r, TrowbridgeReitz(m.alphaX, m.alphaY));
}

PT_INLINE float schlickWeight(float cosTheta) {
  float x = clamp(1.0f - cosTheta, 0.0f, 1.0f);
  float x2 = x * x;
  return x2 * x2 * x;
}

// How the specular lobe is weighed: the dielectric's share (1 - metallic) F(N.V) and the
// metal's metallic F(V.H) per channel; the base's (1 - metallic) (1 - F(N.V)).
PT_INLINE float gltfDielectricFresnel(GltfSurface s, float cosThetaO) {
  return s.f0 + (1.0f - s.f0) * schlickWeight(cosThetaO);
}
PT_INLINE vec3 gltfSpecularWeight(GltfSurface s, float cosThetaO, float cosThetaH) {
  vec3 metal = s.baseColor + (vec3(1.0f) - s.baseColor) * schlickWeight(cosThetaH);
  return (1.0f - s.metallic) * gltfDielectricFresnel(s, cosThetaO) + s.metallic * metal;
}
PT_INLINE vec3 gltfDiffuseWeight(GltfSurface s, float cosThetaO) {
  return (1.0f - s.metallic) * (1.0f - gltfDielectricFresnel(s, cosThetaO)) * s.baseColor;
}

// The probability of sampling the diffuse lobe for wo: its weight's largest channel against the
// specular lobe's at normal incidence of the microfacet (a function of wo alone).
PT_INLINE float gltfDiffuseProbability(GltfSurface s, float cosThetaO) {
  float diffuse = maxComponent(gltfDiffuseWeight(s, cosThetaO));
  float specular = maxComponent(gltfSpecularWeight(s, cosThetaO, cosThetaO));
  float sum = diffuse + specular;
  return sum > 0.0f ? diffuse / sum : 0.0f;
}

PT_INLINE vec3 gltfF(GltfSurface s, vec3 wo, vec3 wi) {
  if (!sameHemisphere(wo, wi)) return vec3(0.0f);
  float cosThetaO = absCosTheta(wo);
  float cosThetaI = absCosTheta(wi);
  if (cosThetaI == 0.0f || cosThetaO == 0.0f) return vec3(0.0f);
  vec3 f = gltfDiffuseWeight(s, cosThetaO) * kInvPi;
  if (effectivelySmooth(s.d)) return f;
  vec3 wm = wi + wo;
  if (dot(wm, wm) == 0.0f) return f;
  wm = normalize(wm);
  vec3 specular = gltfSpecularWeight(s, cosThetaO, abs(dot(wo, wm)));
  // Appendix B's separable Smith masking-shadowing, G1(wo) G1(wi).
  float g = trG1(s.d, wo) * trG1(s.d, wi);
  return f + specular * (trD(s.d, wm) * g / (4.0f * cosThetaI * cosThetaO));
}

PT_INLINE float gltfPdf(GltfSurface s, vec3 wo, vec3 wi) {
  if (!sameHemisphere(wo, wi)) return 0.0f;
  float pd = gltfDiffuseProbability(s, absCosTheta(wo));
  float pdf = pd * absCosTheta(wi) * kInvPi;
  if (effectivelySmooth(s.d)) return pdf;
  vec3 wm = wo + wi;
  if (dot(wm, wm) == 0.0f) return pdf;
  wm = normalize(wm);
  if (wm.z < 0.0f) wm = -wm;
  return pdf + (1.0f - pd) * trPdf(s.d, wo, wm) / (4.0f * abs(dot(wo, wm)));
}

PT_INLINE BsdfSample gltfSample(GltfSurface s, vec3 wo, float uc, vec2 u) {
  float cosThetaO = absCosTheta(wo);
  if (cosThetaO == 0.0f) return noBsdfSample();
  float pd = gltfDiffuseProbability(s, cosThetaO);
  vec3 wi;
  if (uc < pd) {
    wi = sampleCosineHemisphere(u);
    if (wo.z < 0.0f) wi.z = -wi.z;
  } else if (effectivelySmooth(s.d)) {
    // Specular reflection, chosen with probability 1 - pd.
    wi = vec3(-wo.x, -wo.y, wo.z);
    return BsdfSample(gltfSpecularWeight(s, cosThetaO, cosThetaO) / cosThetaO, 1.0f - pd, wi,
                      kBsdfReflection | kBsdfSpecular, 1.0f, false);
  } else {
    vec3 w = wo.z < 0.0f ? -wo : wo;
    vec3 wm = trSampleWm(s.d, w, u);
    wi = reflectAbout(wo, wo.z < 0.0f ? -wm : wm);
  }
  float pdf = gltfPdf(s, wo, wi);
  vec3 f = gltfF(s, wo, wi);
  if (!(pdf > 0.0f) || !sameHemisphere(wo, wi)) return noBsdfSample();
  return BsdfSample(f, pdf, wi, kBsdfReflection, 1.0f, false);
}

// ---- glTF's material extensions -------------------------------------------------------------
// KHR_materials_transmission, _volume, _clearcoat and _specular on top of the material above,
// layered as the extensions' specifications layer them:
//
//   coated   = mix(sheened, clearcoat_brdf, clearcoat Fc(Nc.V)),  Fc Schlick's of f0 0.04
//   sheened  = sheenColor sheen_brdf / s + min(1 - S E(N.V), 1 - S E(N.L)) material
//   material = mix(dielectric, metal_brdf, metallic)
//   dielectric = fresnel_mix(F(N.V), base = mix(diffuse, specular_btdf baseColor, transmission),
//                            layer = specular_brdf)
//   F = f0 + (f90 - f0)(1 - cos)^5, f0 = min(((ior - 1) / (ior + 1))^2 specularColor, 1)
//       specular, f90 = specular (KHR_materials_specular)
//
// with the macro surface's N.V in every Fresnel weight of a layer, as the material above takes
// it, so that each layer passes on exactly what it does not reflect. specular_btdf is thin-walled
// (the reflection lobe mirrored through the surface, KHR_materials_transmission's thin wall)
// unless the material bounds a volume (KHR_materials_volume's thicknessFactor > 0): then the
// transmitted share is a rough dielectric interface of the material's ior (Walter et al. 2007,
// dielectricF above, exact Fresnel per microfacet, total internal reflection from inside) whose
// refracted part is tinted by the base colour, in place of the layer's Fresnel mix. Material
// fields (kMaterialGltf with nSamples != 0): nSamples the kGltf* flags, transmittance (the
// transmission factor, the clearcoat factor, the clearcoat's alpha), k the specular colour, eta.y
// the specular factor; the sheen and the coat's normal where gltf_material_fields.h says; the rest
// as the material above.
//
// The sheen (KHR_materials_sheen) is sheen.h's lobe with the albedo scaling of the extension's
// specification: the layers below lose S E, S = max(sheenColor), E the lobe's directional albedo
// (sheen_albedo.h), the smaller of the scalings of wo and wi, so that f stays reciprocal. Where
// E exceeds 1 (low sheen roughness at grazing angles: the Charlie lobe is not normalized) the
// lobe is divided by s = max(1, E(N.V), E(N.L)) and its share taken as min(E, 1), so that no
// parameter set gains energy. It is sampled cosine-weighted. Nc, the coat's own normal
// (kGltfCoatNormal: its clearcoatNormalTexture at the hit, in the base's local frame), turns
// the coat's lobe (f about Nc times Nc.L / N.L, so that the integrators' N.L weighs it by its own
// cosine) and its Fresnel weight, which then takes Nc.V; the layers below keep N.

struct GltfLayers {
  GltfSurface s;
  vec3 f0;             // the dielectric's reflectance at normal incidence (KHR_materials_specular)
  float f90;           // its reflectance at grazing incidence
  float transmission;  // the share of the dielectric's base that is transmitted
  bool refracts;       // the transmission refracts into a volume (else thin-walled)
  float eta;           // the index of refraction
  float clearcoat;
  TrowbridgeReitz coat;
  bool sheen;  // KHR_materials_sheen
  vec3 sheenColour;
  float sheenRoughness;
  float sheenAlpha;
  bool coatNormal;         // the coat has its own normal: coatFrame's z
  ShadingFrame coatFrame;  // in the base's local frame
  float coatCosThetaO;     // with coatNormal: Nc.wo (wo turned above the base), set per wo
};

PT_INLINE GltfLayers gltfLayersOf(Material m) {
  GltfSurface s = gltfSurfaceOf(m);
  vec3 f0 = min(vec3(s.f0) * m.k, vec3(1.0f)) * m.eta.y;
  bool refracts = (m.nSamples & kGltfVolume) != 0u;
  bool sheen = PT_HAS_GLTF_SHEEN && (m.nSamples & kGltfSheen) != 0u;
  float sheenRoughness = sheen ? gltfSheenRoughness(m) : 0.0f;
  bool coatNormal = PT_HAS_GLTF_COAT_NORMAL && (m.nSamples & kGltfCoatNormal) != 0u;
  ShadingFrame coatFrame =
      ShadingFrame(vec3(1.0f, 0.0f, 0.0f), vec3(0.0f, 1.0f, 0.0f), vec3(0.0f, 0.0f, 1.0f));
  if (coatNormal) coatFrame = makeShadingFrame(gltfCoatNormal(m), vec3(1.0f, 0.0f, 0.0f));
  return GltfLayers(s, f0, m.eta.y, m.transmittance.x, refracts, m.eta.x, m.transmittance.y,
                    TrowbridgeReitz(m.transmittance.z, m.transmittance.z), sheen,
                    sheen ? gltfSheenColour(m) : vec3(0.0f), sheenRoughness,
                    sheenAlpha(sheenRoughness), coatNormal, coatFrame, 0.0f);
}
// l for wo turned above the base (o): the coat's cosine where it has its own normal.
PT_INLINE GltfLayers gltfLayersFacing(GltfLayers l, vec3 o) {
  if (PT_HAS_GLTF_COAT_NORMAL && l.coatNormal) l.coatCosThetaO = dot(o, l.coatFrame.z);
  return l;
}

// What each lobe is weighed by for wo (cosThetaO = |wo.z|), before its own Fresnel term where it
// has one: the clear coat's Fc (scalar; of Nc.V where the coat has its own normal, 1 where wo is
// behind it), the base's 1 - clearcoat Fc (the rest is below).
PT_INLINE float gltfCoatWeight(GltfLayers l, float cosThetaO) {
  float c = PT_HAS_GLTF_COAT_NORMAL && l.coatNormal ? l.coatCosThetaO : cosThetaO;
  return l.clearcoat * (0.04f + 0.96f * schlickWeight(c));
}
// The sheen's directional albedo for a cosine, at most 1 (see above), and the scaling it leaves
// the layers below (1 - S E).
PT_INLINE float gltfSheenAlbedo(GltfLayers l, float cosTheta) {
  return min(sheenAlbedo(cosTheta, l.sheenRoughness), 1.0f);
}
PT_INLINE float gltfSheenScaling(GltfLayers l, float cosTheta) {
  return 1.0f - maxComponent(l.sheenColour) * gltfSheenAlbedo(l, cosTheta);
}
// f of the layers below the sheen (delta lobes' weights too) for wo and wi (their cosines),
// scaled by the sheen.
PT_INLINE vec3 gltfBelowSheen(GltfLayers l, vec3 f, float cosThetaO, float cosThetaI) {
  if (!(PT_HAS_GLTF_SHEEN && l.sheen)) return f;
  return f * min(gltfSheenScaling(l, cosThetaO), gltfSheenScaling(l, cosThetaI));
}
// The sheen lobe's f for o and i above the base, its coat's share included.
PT_INLINE vec3 gltfSheenF(GltfLayers l, float coatWeight, vec3 o, vec3 i) {
  float e = max(max(sheenAlbedo(o.z, l.sheenRoughness), sheenAlbedo(i.z, l.sheenRoughness)), 1.0f);
  return (1.0f - coatWeight) * l.sheenColour * (sheenLobe(l.sheenAlpha, o, i) / e);
}
PT_INLINE vec3 gltfLayerFresnel(GltfLayers l, float cosThetaO) {
  return l.f0 + (vec3(l.f90) - l.f0) * schlickWeight(cosThetaO);
}
// The specular reflection lobe: the dielectric layer's F(N.V) (of the opaque share alone where
// the transmitted share refracts: the interface has its own reflection) and the metal's
// Schlick term at V.H.
PT_INLINE vec3 gltfLayeredSpecularWeight(GltfLayers l, float cosThetaO, float cosThetaH) {
  float opaque = l.refracts ? 1.0f - l.transmission : 1.0f;
  vec3 metal = l.s.baseColor + (vec3(1.0f) - l.s.baseColor) * schlickWeight(cosThetaH);
  vec3 w = (1.0f - l.s.metallic) * opaque * gltfLayerFresnel(l, cosThetaO) + l.s.metallic * metal;
  return (1.0f - gltfCoatWeight(l, cosThetaO)) * w;
}
PT_INLINE vec3 gltfLayeredDiffuseWeight(GltfLayers l, float cosThetaO) {
  return (1.0f - gltfCoatWeight(l, cosThetaO)) * (1.0f - l.s.metallic) * (1.0f - l.transmission) *
         (vec3(1.0f) - gltfLayerFresnel(l, cosThetaO)) * l.s.baseColor;
}
// The transmitted share: thin-walled, (1 - F(N.V)) baseColor; refracting, the interface's whole
// weight (its refracted part tinted apart).
PT_INLINE vec3 gltfTransmissionWeight(GltfLayers l, float cosThetaO) {
  float w = (1.0f - gltfCoatWeight(l, cosThetaO)) * (1.0f - l.s.metallic) * l.transmission;
  if (l.refracts) return vec3(w);
  return w * (vec3(1.0f) - gltfLayerFresnel(l, cosThetaO)) * l.s.baseColor;
}

// The probabilities of sampling the coat, the specular lobe, the diffuse lobe and the
// transmission for wo (x, y, z, w), and the sheen (pSheen): their weights' largest channels,
// normalized (those below the sheen scaled by it).
PT_INLINE vec4 gltfLobeProbabilities(GltfLayers l, float cosThetaO, PT_OUT(float) pSheen) {
  vec4 p = vec4(gltfCoatWeight(l, cosThetaO),
                maxComponent(gltfLayeredSpecularWeight(l, cosThetaO, cosThetaO)),
                maxComponent(gltfLayeredDiffuseWeight(l, cosThetaO)),
                maxComponent(gltfTransmissionWeight(l, cosThetaO)));
  pSheen = 0.0f;
  if (PT_HAS_GLTF_SHEEN && l.sheen) {
    float e = gltfSheenAlbedo(l, cosThetaO);
    float scaling = 1.0f - maxComponent(l.sheenColour) * e;
    p = vec4(p.x, p.y * scaling, p.z * scaling, p.w * scaling);
    pSheen = (1.0f - p.x) * maxComponent(l.sheenColour) * e;
  }
  float sum = p.x + p.y + p.z + p.w + pSheen;
  pSheen = sum > 0.0f ? pSheen / sum : 0.0f;
  return sum > 0.0f ? p / sum : vec4(0.0f);
}

// A microfacet reflection lobe without its Fresnel term, appendix B's D G1(L) G1(V) /
// (4 |N.L| |N.V|), for wo and wi above the surface; and the density of sampling it by visible
// normals.
PT_INLINE float gltfMicrofacet(TrowbridgeReitz d, vec3 wo, vec3 wi) {
  vec3 wm = wi + wo;
  if (dot(wm, wm) == 0.0f || wo.z <= 0.0f || wi.z <= 0.0f) return 0.0f;
  wm = normalize(wm);
  return trD(d, wm) * trG1(d, wo) * trG1(d, wi) / (4.0f * wi.z * wo.z);
}
PT_INLINE float gltfMicrofacetPdf(TrowbridgeReitz d, vec3 wo, vec3 wi) {
  vec3 wm = wi + wo;
  if (dot(wm, wm) == 0.0f || wo.z <= 0.0f || wi.z <= 0.0f) return 0.0f;
  wm = normalize(wm);
  return trPdf(d, wo, wm) / (4.0f * abs(dot(wo, wm)));
}
PT_INLINE vec3 gltfMirrored(vec3 w) {
  return vec3(w.x, w.y, -w.z);
}

// The refracting interface's f or its pdf (in wo's own orientation), its refracted part tinted.
PT_INLINE vec3 gltfRefractionF(GltfLayers l, vec3 wo, vec3 wi, bool radiance) {
  vec3 f = dielectricF(l.s.d, l.eta, wo, wi, radiance);
  return sameHemisphere(wo, wi) ? f : f * l.s.baseColor;
}

// o and i (above the base's surface) in the coat's frame, where the coat has its own normal.
PT_INLINE vec3 gltfInCoatFrame(GltfLayers l, vec3 w) {
  return PT_HAS_GLTF_COAT_NORMAL && l.coatNormal ? toLocal(l.coatFrame, w) : w;
}

PT_INLINE vec3 gltfLayeredF(GltfLayers l, vec3 wo, vec3 wi, bool radiance) {
  float cosThetaO = absCosTheta(wo);
  if (cosThetaO == 0.0f || wi.z == 0.0f) return vec3(0.0f);
  // The other lobes are two-sided: wo turned above the surface, wi with it.
  vec3 o = wo.z < 0.0f ? -wo : wo;
  vec3 i = wo.z < 0.0f ? -wi : wi;
  l = gltfLayersFacing(l, o);
  vec3 f = vec3(0.0f);
  if (l.refracts && l.transmission > 0.0f) {
    f += gltfTransmissionWeight(l, cosThetaO) * gltfRefractionF(l, wo, wi, radiance);
  }
  bool baseSmooth = effectivelySmooth(l.s.d);
  if (i.z > 0.0f) {
    f += gltfLayeredDiffuseWeight(l, cosThetaO) * kInvPi;
    if (!baseSmooth) {
      vec3 wm = normalize(o + i);
      f += gltfLayeredSpecularWeight(l, cosThetaO, abs(dot(o, wm))) * gltfMicrofacet(l.s.d, o, i);
    }
  } else if (!l.refracts && !baseSmooth) {
    f += gltfTransmissionWeight(l, cosThetaO) * gltfMicrofacet(l.s.d, o, gltfMirrored(i));
  }
  // The sheen over the layers so far, scaled by what it takes from them.
  float coatWeight = gltfCoatWeight(l, cosThetaO);
  if (PT_HAS_GLTF_SHEEN && l.sheen) {
    f = gltfBelowSheen(l, f, cosThetaO, abs(i.z));
    if (i.z > 0.0f) f += gltfSheenF(l, coatWeight, o, i);
  }
  if (i.z > 0.0f && l.clearcoat > 0.0f && !effectivelySmooth(l.coat)) {
    if (PT_HAS_GLTF_COAT_NORMAL && l.coatNormal) {
      // The coat's lobe is f about Nc, whose cosine is Nc.L: in the base's frame, where the
      // integrators weigh f by N.L, it is f Nc.L / N.L.
      vec3 ic = toLocal(l.coatFrame, i);
      f += vec3(coatWeight * gltfMicrofacet(l.coat, toLocal(l.coatFrame, o), ic) * (ic.z / i.z));
    } else {
      f += vec3(coatWeight * gltfMicrofacet(l.coat, o, i));
    }
  }
  return f;
}

PT_INLINE float gltfLayeredPdf(GltfLayers l, vec3 wo, vec3 wi) {
  float cosThetaO = absCosTheta(wo);
  if (cosThetaO == 0.0f || wi.z == 0.0f) return 0.0f;
  vec3 o = wo.z < 0.0f ? -wo : wo;
  vec3 i = wo.z < 0.0f ? -wi : wi;
  l = gltfLayersFacing(l, o);
  float pSheen;
  vec4 p = gltfLobeProbabilities(l, cosThetaO, pSheen);
  float pdf = 0.0f;
  if (l.refracts && p.w > 0.0f) pdf += p.w * dielectricPdf(l.s.d, l.eta, wo, wi, kSampleAll);
  bool baseSmooth = effectivelySmooth(l.s.d);
  if (i.z > 0.0f) {
    pdf += p.z * i.z * kInvPi;
    if (!baseSmooth) pdf += p.y * gltfMicrofacetPdf(l.s.d, o, i);
    if (p.x > 0.0f && !effectivelySmooth(l.coat)) {
      pdf += p.x * gltfMicrofacetPdf(l.coat, gltfInCoatFrame(l, o), gltfInCoatFrame(l, i));
    }
    if (PT_HAS_GLTF_SHEEN && l.sheen) pdf += pSheen * i.z * kInvPi;
  } else if (!l.refracts && !baseSmooth) {
    pdf += p.w * gltfMicrofacetPdf(l.s.d, o, gltfMirrored(i));
  }
  return pdf;
}

PT_INLINE BsdfSample gltfLayeredSample(GltfLayers l, vec3 wo, float uc, vec2 u, bool radiance) {
  float cosThetaO = absCosTheta(wo);
  if (cosThetaO == 0.0f) return noBsdfSample();
  vec3 o = wo.z < 0.0f ? -wo : wo;
  l = gltfLayersFacing(l, o);
  float pSheen;
  vec4 p = gltfLobeProbabilities(l, cosThetaO, pSheen);
  vec3 i;
  float etap = 1.0f;
  bool baseSmooth = effectivelySmooth(l.s.d);
  if (uc < p.x) {
    // The clear coat.
    if (PT_HAS_GLTF_COAT_NORMAL && l.coatNormal) {
      // About its own normal: nothing where wo is behind it or wi falls below the base.
      vec3 oc = toLocal(l.coatFrame, o);
      if (oc.z <= 0.0f) return noBsdfSample();
      bool coatSmooth = effectivelySmooth(l.coat);
      i = fromLocal(l.coatFrame, coatSmooth ? vec3(-oc.x, -oc.y, oc.z)
                                            : reflectAbout(oc, trSampleWm(l.coat, oc, u)));
      if (coatSmooth) {
        if (i.z <= 0.0f) return noBsdfSample();
        return BsdfSample(vec3(gltfCoatWeight(l, cosThetaO) / i.z), p.x, wo.z < 0.0f ? -i : i,
                          kBsdfReflection | kBsdfSpecular, 1.0f, false);
      }
    } else if (effectivelySmooth(l.coat)) {
      return BsdfSample(vec3(gltfCoatWeight(l, cosThetaO) / cosThetaO), p.x,
                        vec3(-wo.x, -wo.y, wo.z), kBsdfReflection | kBsdfSpecular, 1.0f, false);
    } else {
      i = reflectAbout(o, trSampleWm(l.coat, o, u));
    }
  } else if (uc < p.x + p.y) {
    if (baseSmooth) {
      vec3 w = gltfLayeredSpecularWeight(l, cosThetaO, cosThetaO) / cosThetaO;
      return BsdfSample(gltfBelowSheen(l, w, cosThetaO, cosThetaO), p.y, vec3(-wo.x, -wo.y, wo.z),
                        kBsdfReflection | kBsdfSpecular, 1.0f, false);
    }
    i = reflectAbout(o, trSampleWm(l.s.d, o, u));
  } else if (uc < p.x + p.y + p.z) {
    i = sampleCosineHemisphere(u);
  } else if (PT_HAS_GLTF_SHEEN && l.sheen && uc < p.x + p.y + p.z + pSheen) {
    i = sampleCosineHemisphere(u);  // the sheen
  } else if (!(p.w > 0.0f)) {
    return noBsdfSample();  // uc beyond the probabilities' sum, rounded below 1
  } else if (l.refracts) {
    // The interface, in wo's own orientation; uc rescaled to its share for its own choice.
    float ur = min((uc - (p.x + p.y + p.z + pSheen)) / max(p.w, 1e-30f), 0.99999994f);
    BsdfSample bs = dielectricSample(l.s.d, l.eta, wo, ur, u, radiance, kSampleAll);
    if (bs.flags == 0u) return noBsdfSample();
    if ((bs.flags & kBsdfSpecular) != 0u) {
      vec3 tint = (bs.flags & kBsdfTransmission) != 0u ? l.s.baseColor : vec3(1.0f);
      vec3 w = gltfTransmissionWeight(l, cosThetaO) * tint * bs.f;
      return BsdfSample(gltfBelowSheen(l, w, cosThetaO, absCosTheta(bs.wi)), p.w * bs.pdf, bs.wi,
                        bs.flags, bs.eta, false);
    }
    i = wo.z < 0.0f ? -bs.wi : bs.wi;
    etap = bs.eta;
  } else if (baseSmooth) {
    // Thin-walled: straight through.
    vec3 w = gltfTransmissionWeight(l, cosThetaO) / cosThetaO;
    return BsdfSample(gltfBelowSheen(l, w, cosThetaO, cosThetaO), p.w, -wo,
                      kBsdfTransmission | kBsdfSpecular, 1.0f, false);
  } else {
    // Thin-walled: the specular lobe's direction, mirrored through the surface.
    i = reflectAbout(o, trSampleWm(l.s.d, o, u));
    if (i.z <= 0.0f) return noBsdfSample();
    i = gltfMirrored(i);
  }
  // A microfacet's reflection below the surface is no sample of its lobe (whose density counts
  // only the directions above).
  if (uc < p.x + p.y && i.z <= 0.0f) return noBsdfSample();
  vec3 wi = wo.z < 0.0f ? -i : i;
  float pdf = gltfLayeredPdf(l, wo, wi);
  vec3 f = gltfLayeredF(l, wo, wi, radiance);
  if (!(pdf > 0.0f) || wi.z == 0.0f) return noBsdfSample();
  bool reflects = sameHemisphere(wo, wi);
  return BsdfSample(f, pdf, wi, reflects ? kBsdfReflection : kBsdfTransmission,
                    reflects ? 1.0f : etap, false);
}

// Whether the layered material has a lobe light sampling can find, or a delta lobe.
PT_INLINE bool gltfLayeredHasNonSpecular(GltfLayers l) {
  return !effectivelySmooth(l.s.d) || (l.s.metallic < 1.0f && l.transmission < 1.0f) ||
         (l.clearcoat > 0.0f && !effectivelySmooth(l.coat)) || (PT_HAS_GLTF_SHEEN && l.sheen);
}
PT_INLINE bool gltfLayeredHasSpecular(GltfLayers l) {
  return effectivelySmooth(l.s.d) || (l.refracts && l.eta == 1.0f && l.transmission > 0.0f) ||
         (l.clearcoat > 0.0f && effectivelySmooth(l.coat));
}

// ---- The material switch: what the integrators call ---------------------------------------
// For types other than diffuse and mirror (those two stay in the integrators' own code).

PT_INLINE TrowbridgeReitz distributionOf(Material m) {
  return TrowbridgeReitz(m.alphaX, m.alphaY);
}

// Whether the BSDF has a lobe that light sampling can find (not only delta lobes).
PT_INLINE bool bsdfHasNonSpecular(Material m) {
  if (PT_HAS_CONDUCTOR && m.type == kMaterialConductor) {
    return !effectivelySmooth(distributionOf(m));
  }
  if (PT_HAS_DIELECTRIC && m.type == kMaterialDielectric) {
    return !dielectricIsSmooth(distributionOf(m), m.eta.x);
  }
  if (PT_HAS_THIN_DIELECTRIC && m.type == kMaterialThinDielectric) return false;
  if (PT_HAS_GLTF && m.type == kMaterialGltf) {
    if (PT_HAS_GLTF_LAYERS && m.nSamples != 0u) return gltfLayeredHasNonSpecular(gltfLayersOf(m));
    return !effectivelySmooth(distributionOf(m)) || m.thickness < 1.0f;
  }
  return true;  // diffuse transmission, coated diffuse
}

// Whether sampling the BSDF can return a delta lobe: a bounce that carries the ray's
// differentials on (pbrt-v4's SpawnRay after a specular sample).
PT_INLINE bool bsdfHasSpecular(Material m) {
  if (PT_HAS_CONDUCTOR && m.type == kMaterialConductor) {
    return effectivelySmooth(distributionOf(m));
  }
  if ((PT_HAS_DIELECTRIC && m.type == kMaterialDielectric) ||
      (PT_HAS_COATED_DIFFUSE && m.type == kMaterialCoatedDiffuse)) {
    // A coated surface's delta lobe is its coat's reflection.
    return dielectricIsSmooth(distributionOf(m), m.eta.x);
  }
  if (PT_HAS_THIN_DIELECTRIC && m.type == kMaterialThinDielectric) return true;
  if (PT_HAS_GLTF && m.type == kMaterialGltf) {
    if (PT_HAS_GLTF_LAYERS && m.nSamples != 0u) return gltfLayeredHasSpecular(gltfLayersOf(m));
    return effectivelySmooth(distributionOf(m));
  }
  return false;  // diffuse, diffuse transmission (mirror: the integrators' own)
}

// f(wo, wi) without delta lobes; `rng` feeds the coated material's estimate. `radiance`: the
// path carries radiance from the camera (pbrt-v4's TransportMode::Radiance), else importance
// from a light (bidirectional methods' light subpaths), which refraction does not scale.
PT_INLINE vec3 bsdfFTransport(Material m, vec3 wo, vec3 wi, bool radiance, RandomStream rng) {
  if (wo.z == 0.0f) return vec3(0.0f);
  if (PT_HAS_CONDUCTOR && m.type == kMaterialConductor) {
    return conductorF(distributionOf(m), m.eta, m.k, wo, wi);
  }
  if (PT_HAS_DIELECTRIC && m.type == kMaterialDielectric) {
    return dielectricF(distributionOf(m), m.eta.x, wo, wi, radiance);
  }
  if (PT_HAS_DIFFUSE_TRANSMISSION && m.type == kMaterialDiffuseTransmission) {
    return diffuseTransmissionF(m.reflectance, m.transmittance, wo, wi);
  }
  if (PT_HAS_COATED_DIFFUSE && m.type == kMaterialCoatedDiffuse) {
    return coatedDiffuseF(coatedDiffuseOf(m), wo, wi, radiance, rng);
  }
  if (PT_HAS_GLTF && m.type == kMaterialGltf) {
    if (PT_HAS_GLTF_LAYERS && m.nSamples != 0u)
      return gltfLayeredF(gltfLayersOf(m), wo, wi, radiance);
    return gltfF(gltfSurfaceOf(m), wo, wi);
  }
  return vec3(0.0f);  // thin dielectric: delta lobes only
}
PT_INLINE vec3 bsdfF(Material m, vec3 wo, vec3 wi, RandomStream rng) {
  return bsdfFTransport(m, wo, wi, true, rng);
}

// The density of sampling wi (non-delta lobes); an estimate for the coated material.
PT_INLINE float bsdfPdf(Material m, vec3 wo, vec3 wi, RandomStream rng) {
  if (wo.z == 0.0f) return 0.0f;
  if (PT_HAS_CONDUCTOR && m.type == kMaterialConductor) {
    return conductorPdf(distributionOf(m), wo, wi);
  }
  if (PT_HAS_DIELECTRIC && m.type == kMaterialDielectric) {
    return dielectricPdf(distributionOf(m), m.eta.x, wo, wi, kSampleAll);
  }
  if (PT_HAS_DIFFUSE_TRANSMISSION && m.type == kMaterialDiffuseTransmission) {
    return diffuseTransmissionPdf(m.reflectance, m.transmittance, wo, wi);
  }
  if (PT_HAS_COATED_DIFFUSE && m.type == kMaterialCoatedDiffuse) {
    return coatedDiffusePdf(coatedDiffuseOf(m), wo, wi, rng);
  }
  if (PT_HAS_GLTF && m.type == kMaterialGltf) {
    if (PT_HAS_GLTF_LAYERS && m.nSamples != 0u) return gltfLayeredPdf(gltfLayersOf(m), wo, wi);
    return gltfPdf(gltfSurfaceOf(m), wo, wi);
  }
  return 0.0f;
}

// Samples wi for wo with uc (choice of lobe) and u (direction); radiance or importance
// transport, as bsdfFTransport.
PT_INLINE BsdfSample bsdfSampleTransport(Material m, vec3 wo, float uc, vec2 u, bool radiance,
                                         RandomStream rng) {
  if (wo.z == 0.0f) return noBsdfSample();
  if (PT_HAS_CONDUCTOR && m.type == kMaterialConductor) {
    return conductorSample(distributionOf(m), m.eta, m.k, wo, u);
  }
  if (PT_HAS_DIELECTRIC && m.type == kMaterialDielectric) {
    return dielectricSample(distributionOf(m), m.eta.x, wo, uc, u, radiance, kSampleAll);
  }
  if (PT_HAS_THIN_DIELECTRIC && m.type == kMaterialThinDielectric) {
    return thinDielectricSample(m.eta.x, wo, uc);
  }
  if (PT_HAS_DIFFUSE_TRANSMISSION && m.type == kMaterialDiffuseTransmission) {
    return diffuseTransmissionSample(m.reflectance, m.transmittance, wo, uc, u);
  }
  if (PT_HAS_COATED_DIFFUSE && m.type == kMaterialCoatedDiffuse) {
    return coatedDiffuseSample(coatedDiffuseOf(m), wo, uc, u, radiance, rng);
  }
  if (PT_HAS_GLTF && m.type == kMaterialGltf) {
    if (PT_HAS_GLTF_LAYERS && m.nSamples != 0u) {
      return gltfLayeredSample(gltfLayersOf(m), wo, uc, u, radiance);
    }
    return gltfSample(gltfSurfaceOf(m), wo, uc, u);
  }
  return noBsdfSample();
}
// Radiance transport, what path tracing samples.
PT_INLINE BsdfSample bsdfSample(Material m, vec3 wo, float uc, vec2 u, RandomStream rng) {
  return bsdfSampleTransport(m, wo, uc, u, true, rng);
}

#ifdef __cplusplus
}  // namespace pt
#endif

#endif  // PT_BSDF_H
