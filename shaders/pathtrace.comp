// The GPU path tracer: one invocation traces a pass's samples of one pixel (as many as the
// host chose for the dispatch) and adds them to the accumulation buffer's sums. The same
// integrator as host/cpu/integrator.cpp (NEE + BSDF sampling with MIS, Russian roulette,
// Lambertian and mirror, and bsdf.h's materials), written separately in GLSL; the layouts
// (shared_types.h), random numbers (sampling.h) and the BSDFs beyond the two (bsdf.h) are
// shared.
#version 460
#extension GL_GOOGLE_include_directive : require
#ifdef PT_DEBUG_PRINTF
#extension GL_EXT_debug_printf : enable
#endif

#include "sampling.h"
#include "shared_types.h"

layout(local_size_x = kWorkgroupSize, local_size_y = kWorkgroupSize) in;

// The effect set: what the scene does not use is compiled out (see host/render/prepare.h).
layout(constant_id = PT_SPEC_DIFFUSE) const bool kDiffuse = true;
layout(constant_id = PT_SPEC_MIRROR) const bool kMirror = true;
layout(constant_id = PT_SPEC_NEE) const bool kNee = true;
layout(constant_id = PT_SPEC_BSDF_EMISSION) const bool kBsdfEmission = true;
layout(constant_id = PT_SPEC_MIS) const bool kMis = true;
layout(constant_id = PT_SPEC_RR) const bool kRussianRoulette = true;
layout(constant_id = PT_SPEC_INTERSECTION) const uint kIntersection = kSpecAtRunTime;
layout(constant_id = PT_SPEC_SAMPLER) const uint kSampler = kSpecAtRunTime;
#ifdef PT_NO_BSDF_MATERIALS
// The variant for scenes of diffuse and mirror surfaces without vertex normals (the host picks
// it): nothing of bsdf.h is compiled in, which lavapipe's compiler takes a second over even
// where specialization constants switch it off.
const bool kConductor = false;
const bool kDielectric = false;
const bool kThinDielectric = false;
const bool kDiffuseTransmission = false;
const bool kCoatedDiffuse = false;
const bool kShadingNormals = false;
const bool kDeltaLights = false;
const bool kEnvironment = false;
const bool kTwoSidedEmitters = false;
const bool kSphereLights = false;
const bool kTextures = false;
const bool kAlphaCutouts = false;
const bool kBumpMaps = false;
const bool kEnvironmentImage = false;
#else
layout(constant_id = PT_SPEC_CONDUCTOR) const bool kConductor = true;
layout(constant_id = PT_SPEC_DIELECTRIC) const bool kDielectric = true;
layout(constant_id = PT_SPEC_THIN_DIELECTRIC) const bool kThinDielectric = true;
layout(constant_id = PT_SPEC_DIFFUSE_TRANSMISSION) const bool kDiffuseTransmission = true;
layout(constant_id = PT_SPEC_COATED_DIFFUSE) const bool kCoatedDiffuse = true;
layout(constant_id = PT_SPEC_SHADING_NORMALS) const bool kShadingNormals = true;
layout(constant_id = PT_SPEC_DELTA_LIGHTS) const bool kDeltaLights = true;
layout(constant_id = PT_SPEC_ENVIRONMENT) const bool kEnvironment = true;
layout(constant_id = PT_SPEC_TWO_SIDED_EMITTERS) const bool kTwoSidedEmitters = true;
layout(constant_id = PT_SPEC_SPHERE_LIGHTS) const bool kSphereLights = true;
layout(constant_id = PT_SPEC_TEXTURES) const bool kTextures = true;
layout(constant_id = PT_SPEC_ALPHA) const bool kAlphaCutouts = true;
layout(constant_id = PT_SPEC_BUMP) const bool kBumpMaps = true;
layout(constant_id = PT_SPEC_TEXTURE_FEATURES) const uint kTextureFeatures = kTextureUsesAll;
layout(constant_id = PT_SPEC_ENVIRONMENT_IMAGE) const bool kEnvironmentImage = true;
#endif
// Some emitter is one of lights.h's (not a triangle).
const bool kAnalyticLights = kDeltaLights || kEnvironment || kSphereLights;
// Some surface has one of bsdf.h's materials; bsdf.h's switch sees only the types in use.
const bool kBsdfMaterials =
    kConductor || kDielectric || kThinDielectric || kDiffuseTransmission || kCoatedDiffuse;

layout(std430, set = 0, binding = PT_BINDING_PARAMS) readonly buffer ParamsBuffer {
  RenderParams paramsBuffer;
};
// The parameters, copied from their buffer once at the start of main and read from here. On
// lavapipe a buffer load inside a loop or branch runs lane by lane, in a loop of its own (only
// at the top of main does it read once for all lanes): the path loop had 28 such loops, 5 % of
// the render.
RenderParams params;
// The scene's arrays, as texels (see PT_BINDING_NODES); loadNode, loadTriangle, loadMaterial
// and loadEmitter read their structs.
layout(set = 0, binding = PT_BINDING_NODES) uniform usamplerBuffer nodeTexels;
layout(set = 0, binding = PT_BINDING_TRIANGLES) uniform usamplerBuffer triangleTexels;
layout(set = 0, binding = PT_BINDING_MATERIALS) uniform usamplerBuffer materialTexels;
layout(set = 0, binding = PT_BINDING_EMITTERS) uniform usamplerBuffer emitterTexels;
layout(set = 0, binding = PT_BINDING_NORMALS) uniform usamplerBuffer normalTexels;
layout(set = 0, binding = PT_BINDING_LIGHTS) uniform usamplerBuffer lightTexels;
layout(set = 0, binding = PT_BINDING_UVS) uniform usamplerBuffer uvTexels;
layout(set = 0, binding = PT_BINDING_TEXTURES) uniform usamplerBuffer textureTexels;
layout(set = 0, binding = PT_BINDING_IMAGES) uniform usamplerBuffer imageTexels;
layout(set = 0,
       binding = PT_BINDING_MATERIAL_TEXTURES) uniform usamplerBuffer materialTextureTexels;
#ifndef PT_NO_BSDF_MATERIALS
layout(set = 0, binding = PT_BINDING_ENVIRONMENT) uniform usamplerBuffer environmentTexels;
#endif
layout(std430, set = 0, binding = PT_BINDING_ACCUM) buffer AccumBuffer {
  AccumPixel accum[];
};
layout(std430, set = 0, binding = PT_BINDING_COUNTERS) buffer CounterBuffer {
  DeviceCounters counters;
};

layout(push_constant) uniform Pass {
  PassConstants pass;
};

// Lavapipe (Mesa 22.3) silently ends every loop once an invocation has run 65,535 loop
// iterations (counted per SIMD group, so a lane's own count can be lower). Each loop here
// notes how it ended, where the compiler cannot fold the note away, and main checks after
// every sample that the cap had not been reached; a sample cut short sets gTruncated.
bool gTruncated = false;
uint gLoopIterations = 0u;  // this invocation's count, for the statistics
uint gRays = 0u;
bool gDebug = false;  // this invocation prints its path (--debug-pixel)

#ifndef PT_NO_BSDF_MATERIALS
// bsdf.h, for the material types in use, its loops counted.
#define PT_HAS_CONDUCTOR kConductor
#define PT_HAS_DIELECTRIC kDielectric
#define PT_HAS_THIN_DIELECTRIC kThinDielectric
#define PT_HAS_DIFFUSE_TRANSMISSION kDiffuseTransmission
#define PT_HAS_COATED_DIFFUSE kCoatedDiffuse
#define PT_LOOP_TICK() gLoopIterations++
#include "bsdf.h"
#include "lights.h"

// What texture.h reads (see there), from the texture bindings.
TextureNode textureNodeAt(uint i) {
  int at = int(kTextureNodeTexels * i);
  uvec4 a = texelFetch(textureTexels, at);
  uvec4 b = texelFetch(textureTexels, at + 1);
  uvec4 c = texelFetch(textureTexels, at + 2);
  uvec4 d = texelFetch(textureTexels, at + 3);
  return TextureNode(uintBitsToFloat(a.xyz), a.w, uintBitsToFloat(b), c.x, c.y, c.z, c.w, d.x, d.y,
                     d.z, d.w);
}
uint imageWordAt(uint i) {
  return texelFetch(imageTexels, int(i >> 2u))[i & 3u];
}
MaterialTextures materialTexturesAt(uint i) {
  int at = int(kMaterialTextureTexels * i);
  uvec4 a = texelFetch(materialTextureTexels, at);
  uvec4 b = texelFetch(materialTextureTexels, at + 1);
  uvec4 c = texelFetch(materialTextureTexels, at + 2);
  return MaterialTextures(a.x, a.y, a.z, a.w, b.x, b.y, b.z, b.w, c.x, uintBitsToFloat(c.y), c.z,
                          c.w);
}
TriangleUVs uvsAt(uint primitive) {
  int at = int(2u * primitive);
  vec4 a = uintBitsToFloat(texelFetch(uvTexels, at));
  vec4 b = uintBitsToFloat(texelFetch(uvTexels, at + 1));
  return TriangleUVs(a.xy, a.zw, b.xy, b.zw);
}
#define PT_TEXTURE_LOOP_TICK() gLoopIterations++
#define PT_TEXTURE_FEATURES kTextureFeatures
#include "texture.h"
// Alpha cut-outs in the traversal (bvh.glsl): a hit where the surface is cut away is passed by.
// gAlphaU is the ray's number (texture.h): set before each ray is traced (the path's ray at the
// start of extendPath, a shadow ray by the light sample that casts it; a ray traced again in main
// keeps the number of the ray that asked, the last one set).
float gAlphaU = 0.0;
#define PT_HIT_FILTER(tri, hit, r)                   \
  (!kAlphaCutouts || params.texturesPresent == 0u || \
   alphaKeepsHit(tri.material, tri.primitive, hit.barycentrics, gAlphaU))
// The environment image (environment.h reads its texels through environmentTexel).
vec4 environmentTexel(uint i) {
  return uintBitsToFloat(texelFetch(environmentTexels, int(i)));
}
#define PT_ENVIRONMENT_LOOP_TICK() gLoopIterations++
#include "environment.h"
#endif

// Watertight unless switched off by specialization or, unspecialized, by the parameters.
#define PT_WATERTIGHT \
  (kIntersection == kSpecAtRunTime ? params.fastIntersection == 0u : kIntersection == 0u)
// The sampler, likewise: Owen-scrambled Sobol points or independent hashes.
#define PT_SOBOL \
  (kSampler == kSpecAtRunTime ? params.samplerType == kSamplerSobol : kSampler == kSamplerSobol)
#include "bvh.glsl"
// The camera's samples (pixel filter, thin lens), the bisection loops counted.
#define PT_FILTER_LOOP_TICK() gLoopIterations++
#ifdef PT_NO_BSDF_MATERIALS
#define PT_FILTER_BOX_PINHOLE
#endif
#include "filter.h"

// The rows beyond the first two only where a scene has bsdf.h's materials.
Material loadMaterial(uint i) {
  int at = int(kMaterialTexels * i);
  uvec4 a = texelFetch(materialTexels, at);
  uvec4 b = texelFetch(materialTexels, at + 1);
  uvec4 c = uvec4(0u), d = uvec4(0u), e = uvec4(0u), f = uvec4(0u);
  if (kBsdfMaterials) {
    c = texelFetch(materialTexels, at + 2);
    d = texelFetch(materialTexels, at + 3);
    e = texelFetch(materialTexels, at + 4);
    f = texelFetch(materialTexels, at + 5);
  }
  return Material(uintBitsToFloat(a.xyz), a.w, uintBitsToFloat(b.xyz), b.w, uintBitsToFloat(c.xyz),
                  uintBitsToFloat(c.w), uintBitsToFloat(d.xyz), uintBitsToFloat(d.w),
                  uintBitsToFloat(e.xyz), uintBitsToFloat(e.w), uintBitsToFloat(f.x), f.y, f.z,
                  f.w);
}

#ifndef PT_NO_BSDF_MATERIALS
TriangleNormals loadNormals(uint primitive) {
  int at = int(3u * primitive);
  vec4 a = uintBitsToFloat(texelFetch(normalTexels, at));
  vec4 b = uintBitsToFloat(texelFetch(normalTexels, at + 1));
  vec4 c = uintBitsToFloat(texelFetch(normalTexels, at + 2));
  return TriangleNormals(a.xyz, a.w, b.xyz, b.w, c.xyz, c.w);
}
#endif

Emitter loadEmitter(uint i) {
  uvec4 a = texelFetch(emitterTexels, int(i));
  return Emitter(a.x, uintBitsToFloat(a.y), uintBitsToFloat(a.z), a.w);
}

#ifndef PT_NO_BSDF_MATERIALS
EnvironmentMap environmentMap() {
  return EnvironmentMap(params.environmentX, params.environmentY, params.environmentZ,
                        params.environmentWidth, params.environmentHeight,
                        params.environmentMapping);
}

Light loadLight(uint i) {
  int at = int(kLightTexels * i);
  uvec4 a = texelFetch(lightTexels, at);
  uvec4 b = texelFetch(lightTexels, at + 1);
  uvec4 c = texelFetch(lightTexels, at + 2);
  uvec4 d = texelFetch(lightTexels, at + 3);
  return Light(uintBitsToFloat(a.xyz), a.w, uintBitsToFloat(b.xyz), uintBitsToFloat(b.w),
               uintBitsToFloat(c.xyz), uintBitsToFloat(c.w), uintBitsToFloat(d.x), d.y, d.z, d.w);
}
#endif

// A ray whose first traversal gave up at an edge function of exactly zero (traceRayWith in
// bvh.glsl), traced again with the exact test once the bounce is done (main): a shadow ray,
// whose light sample then adds `contribution` to the path's radiance unless occluded, or the
// path's next ray, whose hit the next bounce takes. The bounce does without the answer: it
// adds nothing for the shadow ray (the contribution comes after every other addition of the
// bounce, as it would have come after the light sample), or it stops before the hit is used.
// One exact traversal per bounce, for either kind, rather than one after each traversal:
// lavapipe runs a loop's body at least once whether a lane needs it or not.
struct Retrace {
  bool pending;
  bool shadow;
  vec3 origin;
  vec3 direction;
  vec3 contribution;
};

// A uniform point on an emitter chosen from the alias table with uChoose (uLight: the point).
struct LightPoint {
  vec3 point;
  vec3 normal;  // the emitter's unit geometric normal (it emits on this side)
  float area;
  float magnitude;  // for the ray offset at the light
  float pmf;        // probability of choosing this emitter
  vec3 Le;
  uint triangle;
  uint primitive;
  bool twoSided;  // emits on both sides
};

// The emitter the alias table gives for uChoose.
Emitter pickEmitter(vec2 uChoose) {
  uint slot = aliasTableSlot(uChoose.x, params.emitterCount);
  return loadEmitter(aliasTablePick(slot, loadEmitter(slot), uChoose.y));
}

LightPoint pointOnEmitter(Emitter emitter, vec2 uLight) {
  Triangle light = loadTriangle(emitter.triangle);
  vec2 b = sampleTriangleBarycentrics(uLight);
  vec3 lightCross = cross(light.v1 - light.v0, light.v2 - light.v0);
  Material lightMaterial = loadMaterial(light.material);
  return LightPoint((1.0 - b.x - b.y) * light.v0 + b.x * light.v1 + b.y * light.v2,
                    normalize(lightCross), 0.5 * length(lightCross),
                    triangleMagnitude(light.v0, light.v1, light.v2), emitter.pmf,
                    lightMaterial.emission, emitter.triangle, light.primitive,
                    kTwoSidedEmitters && lightMaterial.twoSided != 0u);
}

// A two-sided light seen from its back (cosLight < 0): the side the receiver sees is the
// emitting one, its normal turned towards the receiver (for the cosine and the shadow ray's
// offset).
void faceTwoSided(inout LightPoint light, inout float cosLight) {
  if (light.twoSided && cosLight < 0.0) {
    cosLight = -cosLight;
    light.normal = -light.normal;
  }
}

// Traces the shadow ray of a light sample from `from` (offset) to the light point (offset),
// `direction` spanning it with t in [0, 1): kShadowOccluded, kShadowClear, or kShadowRetrace
// when the traversal gave up (see Retrace), the ray then to be traced again later.
const uint kShadowOccluded = 0u;
const uint kShadowClear = 1u;
const uint kShadowRetrace = 2u;
uint traceShadowRayTo(vec3 from, vec3 to, out vec3 direction) {
  direction = to - from;
  gRays++;
  HitData blocker;
  bool inexact;
  bool occluded =
      traceRayWith(/*exact=*/false, from, direction, 1.0, /*anyHit=*/true, blocker, inexact);
  if (inexact) return kShadowRetrace;
  return occluded ? kShadowOccluded : kShadowClear;
}
uint traceShadowRay(vec3 from, LightPoint light, out vec3 direction) {
  return traceShadowRayTo(from, offsetRayOrigin(light.point, light.normal, light.magnitude),
                          direction);
}

// A clear shadow ray's contribution, or zero with `retrace` set to add it once the ray has been
// traced again.
vec3 addOrDefer(uint shadow, vec3 from, vec3 direction, vec3 contribution, inout Retrace retrace) {
  if (shadow != kShadowRetrace) return contribution;
  retrace = Retrace(true, true, from, direction, contribution);
  return vec3(0.0);
}

void debugLightSample(uint depth, LightPoint light, float lightPdf, float weight) {
#ifdef PT_DEBUG_PRINTF
  if (gDebug) {
    debugPrintfEXT("gpu depth %u: light sample on triangle %u (primitive %u) pdf=%g weight=%g",
                   depth, light.triangle, light.primitive, lightPdf, weight);
  }
#endif
}

#ifndef PT_NO_BSDF_MATERIALS
// A light sample of one of lights.h's lights (chosen with probability pmf), given the BSDF's
// f * |cos| towards it (fCos) and its density (bsdfDensity, read only for MIS): traces the
// shadow ray from `from` and returns the contribution, weighed by the power heuristic unless
// the light is a delta (which BSDF sampling never finds).
vec3 analyticLightContribution(AnalyticLightSample ls, float pmf, vec3 from, vec3 beta, vec3 fCos,
                               float bsdfDensity, bool misOn, uint depth, inout Retrace retrace) {
  vec3 direction;
  uint shadow = traceShadowRayTo(from, ls.target, direction);
  if (shadow == kShadowOccluded) return vec3(0.0);
  float lightPdf = pmf * ls.pdf;
  float weight = (misOn && !ls.delta) ? powerHeuristic(lightPdf, bsdfDensity) : 1.0;
#ifdef PT_DEBUG_PRINTF
  if (gDebug) {
    debugPrintfEXT("gpu depth %u: light sample on analytic light pdf=%g weight=%g", depth, lightPdf,
                   weight);
  }
#endif
  vec3 contribution = beta * fCos * ls.Li * (weight / lightPdf);
  return addOrDefer(shadow, from, direction, contribution, retrace);
}

// A sample of the analytic light an emitter names, from p: the environment image's for an
// infinite light that has one (integrator.cpp's sampleLight).
AnalyticLightSample sampleLight(Emitter emitter, vec3 p, vec2 u) {
  Light light = loadLight(emitter.triangle & ~kEmitterLight);
  if (kEnvironmentImage && light.type == kLightInfinite && params.environmentWidth != 0u) {
    return sampleEnvironmentLight(environmentMap(), p, u, params.sceneRadius);
  }
  return sampleAnalyticLight(light, p, u, params.sceneRadius);
}
#endif

// Samples direct illumination at diffuse vertex p with shading normal n (next-event
// estimation, pbrt's SampleLd): picks an emitter from the alias table with uChoose, a uniform
// point on its triangle with uLight, and traces a shadow ray to it. Returns the light's
// contribution to L, beta * f * Le * cos / pdf, weighted by the power heuristic against BSDF
// sampling when misOn; zero when the point faces away or is occluded, and zero with `retrace`
// set when the shadow ray is to be traced again. The shadow ray leaves along n, or with
// shading normals (n then interpolated) on the side of the geometric normal ng the light is on.
vec3 sampleDirectLight(vec3 p, vec3 n, vec3 ng, bool shadingNormals, float magnitude, vec3 beta,
                       vec3 f, vec2 uChoose, vec2 uLight, bool misOn, uint depth,
                       inout Retrace retrace) {
#ifndef PT_NO_BSDF_MATERIALS
  if (kAlphaCutouts) gAlphaU = shadowAlphaRandom(uLight);
#endif
  // Pick an emitter from the alias table, then a uniform point on its triangle (or a sample of
  // an analytic light).
  Emitter emitter = pickEmitter(uChoose);
#ifndef PT_NO_BSDF_MATERIALS
  if (kAnalyticLights && (emitter.triangle & kEmitterLight) != 0u) {
    AnalyticLightSample ls = sampleLight(emitter, p, uLight);
    float cosWi = dot(n, ls.wi);
    if (!(cosWi > 0.0) || !(maxComponent(ls.Li) > 0.0)) return vec3(0.0);
    vec3 from =
        offsetRayOrigin(p, shadingNormals ? (dot(ng, ls.wi) > 0.0 ? ng : -ng) : n, magnitude);
    return analyticLightContribution(ls, emitter.pmf, from, beta, f * cosWi, cosWi * kInvPi, misOn,
                                     depth, retrace);
  }
#endif
  LightPoint light = pointOnEmitter(emitter, uLight);

  vec3 toLight = light.point - p;
  float dist2 = dot(toLight, toLight);
  vec3 wl = toLight / sqrt(dist2);
  float cosLight = -dot(light.normal, wl);  // > 0: we see the emitting side
  if (kTwoSidedEmitters) faceTwoSided(light, cosLight);
  float cosSurface = dot(n, wl);
  if (!(cosLight > 0.0 && cosSurface > 0.0)) return vec3(0.0);

  // Shadow ray between the two offset points; t in [0, 1) spans the segment.
  vec3 from = offsetRayOrigin(p, shadingNormals ? (dot(ng, wl) > 0.0 ? ng : -ng) : n, magnitude);
  vec3 direction;
  uint shadow = traceShadowRay(from, light, direction);
  if (shadow == kShadowOccluded) return vec3(0.0);

  float lightPdf = light.pmf * dist2 / (cosLight * light.area);
  float weight = misOn ? powerHeuristic(lightPdf, cosSurface * kInvPi) : 1.0;
  debugLightSample(depth, light, lightPdf, weight);
  vec3 contribution = beta * f * light.Le * (cosSurface * weight / lightPdf);
  return addOrDefer(shadow, from, direction, contribution, retrace);
}

#ifndef PT_NO_BSDF_MATERIALS
// sampleDirectLight at a vertex with one of bsdf.h's BSDFs (integrator.cpp's
// sampleDirectLightBsdf): the BSDF's value and density in the local shading frame; the shadow
// ray leaves from the side of the geometric normal ng the light is on.
vec3 sampleDirectLightBsdf(vec3 p, vec3 ng, ShadingFrame frame, Material material, vec3 wo,
                           float magnitude, vec3 beta, vec2 uChoose, vec2 uLight,
                           RandomStream evalStream, RandomStream pdfStream, bool misOn, uint depth,
                           inout Retrace retrace) {
  if (kAlphaCutouts) gAlphaU = shadowAlphaRandom(uLight);
  Emitter emitter = pickEmitter(uChoose);
  if (kAnalyticLights && (emitter.triangle & kEmitterLight) != 0u) {
    AnalyticLightSample ls = sampleLight(emitter, p, uLight);
    if (!(maxComponent(ls.Li) > 0.0)) return vec3(0.0);
    vec3 wiLocal = toLocal(frame, ls.wi);
    vec3 fCos = bsdfF(material, wo, wiLocal, evalStream) * absCosTheta(wiLocal);
    if (!(maxComponent(fCos) > 0.0)) return vec3(0.0);
    float density = (misOn && !ls.delta) ? bsdfPdf(material, wo, wiLocal, pdfStream) : 0.0;
    vec3 from = offsetRayOrigin(p, dot(ng, ls.wi) > 0.0 ? ng : -ng, magnitude);
    return analyticLightContribution(ls, emitter.pmf, from, beta, fCos, density, misOn, depth,
                                     retrace);
  }
  LightPoint light = pointOnEmitter(emitter, uLight);
  vec3 toLight = light.point - p;
  float dist2 = dot(toLight, toLight);
  vec3 wl = toLight / sqrt(dist2);
  float cosLight = -dot(light.normal, wl);  // > 0: we see the emitting side
  if (kTwoSidedEmitters) faceTwoSided(light, cosLight);
  if (!(cosLight > 0.0)) return vec3(0.0);
  vec3 wi = toLocal(frame, wl);
  vec3 f = bsdfF(material, wo, wi, evalStream) * absCosTheta(wi);
  if (!(maxComponent(f) > 0.0)) return vec3(0.0);

  vec3 from = offsetRayOrigin(p, dot(ng, wl) > 0.0 ? ng : -ng, magnitude);
  vec3 direction;
  uint shadow = traceShadowRay(from, light, direction);
  if (shadow == kShadowOccluded) return vec3(0.0);

  float lightPdf = light.pmf * dist2 / (cosLight * light.area);
  float weight = misOn ? powerHeuristic(lightPdf, bsdfPdf(material, wo, wi, pdfStream)) : 1.0;
  debugLightSample(depth, light, lightPdf, weight);
  vec3 contribution = beta * f * light.Le * (weight / lightPdf);
  return addOrDefer(shadow, from, direction, contribution, retrace);
}
#endif

// What sampleRadiance (host/cpu/integrator.cpp) keeps across its loop: one sample's path,
// between two bounces.
struct Path {
  uint sampleIndex;
  uint depth;   // scattering events so far
  vec3 origin;  // the ray to trace next
  vec3 direction;
  vec3 L;               // radiance gathered so far
  vec3 beta;            // path throughput
  bool specularBounce;  // the ray leaves a specular bounce (or the camera)
  float weight;         // the camera sample's weight (filter.h): multiplies L at the end
  float bsdfPdf;        // solid-angle pdf of the BSDF sample that produced the ray
  float etaScale;       // product of the squared relative indices refracted through
  bool hitReady;        // the ray's closest hit is hitFound and hit already (see Retrace)
  bool hitFound;
  HitData hit;
};

// The effects in use. Those switched off by a specialization constant fold away here; the
// run-time half of each test keeps the unspecialized shader (every constant true) correct for
// any scene.
bool neeOn() {
  return kNee && params.emitterCount > 0u && params.strategy != kStrategyBsdf;
}
bool misOn() {
  return kMis && params.strategy == kStrategyMis;
}
bool bsdfEmissionOn() {
  return kBsdfEmission && params.strategy != kStrategyNee;
}
bool rouletteOn() {
  return kRussianRoulette && params.russianRoulette != 0u;
}

// sampleRadiance's start: the camera ray through a point of the pixel's filter (and of the
// lens), radiance 0, throughput 1. `pixel` is the film's (the image's plus the crop's corner).
Path startPath(uvec2 pixel, uint sampleIndex) {
  Path path;
  path.sampleIndex = sampleIndex;
  path.depth = 0u;
  // The lens's numbers only for a thin lens: a pinhole draws what it drew before lenses.
  vec2 uLens = params.camera.lensRadius > 0.0
                   ? random2(PT_SOBOL, pixel, sampleIndex, kDimLens, params.seed)
                   : vec2(0.0);
  CameraSample camera = generateCameraRay(
      params.camera, pixel, random2(PT_SOBOL, pixel, sampleIndex, kDimPixel, params.seed), uLens);
  path.origin = camera.origin;
  path.direction = camera.direction;
  path.weight = camera.weight;
  path.L = vec3(0.0);
  path.beta = vec3(1.0);
  // The camera ray counts as specular: emission it finds is taken at full weight.
  path.specularBounce = true;
  path.bsdfPdf = 0.0;
  path.etaScale = 1.0;
  path.hitReady = false;
  path.hitFound = false;
  path.hit = HitData(0.0, 0u);
  return path;
}

// One iteration of sampleRadiance's loop: traces the path's ray, adds the emission it finds,
// scatters. Returns true when the path has ended, its radiance then being path.L once
// `retrace` is done (main).
bool extendPath(inout Path path, uvec2 pixel, inout Retrace retrace) {
  uint seed = params.seed;
  bool sobol = PT_SOBOL;  // else independent random numbers
  uint sampleIndex = path.sampleIndex;
  // Find the closest surface along the ray; the background is black.
  HitData hit = path.hit;
  bool found = path.hitFound;
  if (!path.hitReady) {
    gRays++;
#ifndef PT_NO_BSDF_MATERIALS
    if (kAlphaCutouts) gAlphaU = pathAlphaRandom(pixel, sampleIndex, path.depth, seed);
#endif
    bool inexact;
    found = traceRayWith(/*exact=*/false, path.origin, path.direction, 1.0 / 0.0,
                         /*anyHit=*/false, hit, inexact);
    if (inexact) {
      retrace = Retrace(true, false, path.origin, path.direction, vec3(0.0));
      return false;
    }
  }
  path.hitReady = false;
  if (!found) {
#ifndef PT_NO_BSDF_MATERIALS
    // The ray leaves the scene: the infinite light's radiance, weighed as an emitter's.
    if (kEnvironment && params.environmentEmitter != kNoEmitter) {
      vec3 Le = params.environment;
      float lightPdf = params.environmentPdf;
      if (kEnvironmentImage && params.environmentWidth != 0u) {
        // The image: the direction's texel, and its density times the light's pmf.
        EnvironmentLookup e = environmentLookup(environmentMap(), path.direction);
        Le = e.Le;
        lightPdf = params.environmentPdf * e.pdf;
      }
      if (path.specularBounce) {
        path.L += path.beta * Le;
      } else if (bsdfEmissionOn()) {
        float weight = 1.0;
        if (misOn()) {
          weight = powerHeuristic(path.bsdfPdf, lightPdf);
        }
        path.L += path.beta * weight * Le;
      }
    }
#endif
    return true;
  }
  Triangle tri = loadTriangle(hit.triangle);
  Material material = loadMaterial(tri.material);
  // Hit point from barycentrics (more accurate than origin + t * direction).
  vec3 b = hitBarycentrics(path.origin, path.direction, tri);
#ifndef PT_NO_BSDF_MATERIALS
  // The parameters that textures give, at the hit's texture coordinates.
  vec2 uv = vec2(0.0);
  MaterialTextures textures;
  if ((kTextures || kBumpMaps) && params.texturesPresent != 0u) {
    uv = interpolatedUV(uvsAt(tri.primitive), b);
    textures = materialTexturesAt(tri.material);
    if (kTextures) material = resolveMaterial(material, textures, uv);
  }
#endif
  vec3 p = b.x * tri.v0 + b.y * tri.v1 + b.z * tri.v2;
  vec3 edgeCross = cross(tri.v1 - tri.v0, tri.v2 - tri.v0);
  vec3 ng = normalize(edgeCross);
  vec3 wo = -path.direction;
  float cosOut = dot(ng, wo);
  // Coordinates' scale at this vertex, for the ray offsets.
  float magnitude = triangleMagnitude(tri.v0, tri.v1, tri.v2);
#ifdef PT_DEBUG_PRINTF
  if (gDebug) {
    debugPrintfEXT(
        "gpu depth %u: hit triangle %u (primitive %u) t=%g p=(%g, %g, %g) beta=(%g, %g, %g)",
        path.depth, hit.triangle, tri.primitive, hit.t, p.x, p.y, p.z, path.beta.x, path.beta.y,
        path.beta.z);
  }
#endif

  // Add emitted light found by this ray: on the geometric normal's side, or on both.
  float cosEmit = (kTwoSidedEmitters && material.twoSided != 0u) ? abs(cosOut) : cosOut;
  if (tri.emitter != kNoEmitter && cosEmit > 0.0) {
    vec3 Le = material.emission;
    if (path.specularBounce) {
      path.L += path.beta * Le;
    } else if (bsdfEmissionOn()) {
      // Weigh against the chance that light sampling had produced this point.
      float weight = 1.0;
      if (misOn()) {
        float area = 0.5 * length(edgeCross);
        Emitter emitter = loadEmitter(tri.emitter);
        float lightPdf = emitter.pmf * hit.t * hit.t / (cosEmit * area);
#ifndef PT_NO_BSDF_MATERIALS
        // A sphere light's triangle: light sampling draws its cone (seen from the ray's origin).
        if (kSphereLights && (emitter.triangle & kEmitterLight) != 0u) {
          lightPdf = emitter.pmf *
                     sphereLightPdf(loadLight(emitter.triangle & ~kEmitterLight), path.origin);
        }
#endif
        weight = powerHeuristic(path.bsdfPdf, lightPdf);
      }
      path.L += path.beta * weight * Le;
    }
  }

  // Stop after maxDepth scattering events.
  if (path.depth == params.maxDepth) return true;
  uint dim = kDimFirstBounce + kDimsPerBounce * path.depth;
  ++path.depth;

  // Diffuse and mirror surfaces are two-sided: shaded with the normal facing the ray.
  vec3 n = cosOut >= 0.0 ? ng : -ng;
  // With vertex normals, shaded about the interpolated normal (integrator.cpp says more).
  vec3 ns = ng;
  bool shaded = kShadingNormals && params.normalsPresent != 0u;  // ns may differ from ng
#ifndef PT_NO_BSDF_MATERIALS
  TriangleNormals normals;
  if (shaded) {
    normals = loadNormals(tri.primitive);
    ns = interpolatedNormal(normals, b, ng);
    n = dot(ns, wo) >= 0.0 ? ns : -ns;
  }
  // A bump map moves the shading normal (texture.h).
  if (kBumpMaps && params.texturesPresent != 0u && textures.displacement != kNoTexture) {
    vec3 bumped =
        bumpedNormal(textures.displacement, tri, uvsAt(tri.primitive), uv, ng, ns, shaded, normals);
    if (bumped != ns) {
      ns = bumped;
      shaded = true;
      n = dot(ns, wo) >= 0.0 ? ns : -ns;
    }
  }
#endif
  vec3 wi;
  if (kMirror && ((!kDiffuse && !kBsdfMaterials) || material.type == kMaterialMirror)) {
    // Ideal reflection: the BSDF is a delta, f * cos / pdf = reflectance.
    wi = path.direction - 2.0 * dot(path.direction, n) * n;
    path.beta *= material.reflectance;
    path.specularBounce = true;
#ifndef PT_NO_BSDF_MATERIALS
  } else if (kBsdfMaterials && (!kDiffuse || material.type != kMaterialDiffuse)) {
    // One of bsdf.h's BSDFs, in the shading frame about the shading normal (not turned
    // towards the ray: a dielectric tells inside from outside by it).
    ShadingFrame frame = makeShadingFrame(ns, tri.v1 - tri.v0);
    vec3 woLocal = toLocal(frame, wo);
    // Sample direct illumination from an emitter, unless the BSDF has only delta lobes.
    if (neeOn() && bsdfHasNonSpecular(material)) {
      path.L +=
          sampleDirectLightBsdf(p, ng, frame, material, woLocal, magnitude, path.beta,
                                random2(sobol, pixel, sampleIndex, dim + kDimLightChoose, seed),
                                random2(sobol, pixel, sampleIndex, dim + kDimLightPoint, seed),
                                makeRandomStream(pixel, sampleIndex, dim, seed, kStreamEval),
                                makeRandomStream(pixel, sampleIndex, dim, seed, kStreamLightPdf),
                                misOn(), path.depth, retrace);
    }
    // Sample the BSDF; the lobe choice takes the roulette dimension's second number.
    BsdfSample bs = bsdfSample(material, woLocal,
                               random2(sobol, pixel, sampleIndex, dim + kDimRoulette, seed).y,
                               random2(sobol, pixel, sampleIndex, dim + kDimBsdf, seed),
                               makeRandomStream(pixel, sampleIndex, dim, seed, kStreamSample));
    if (bs.flags == 0u) return true;
    wi = fromLocal(frame, bs.wi);
    path.beta *= bs.f * (absCosTheta(bs.wi) / bs.pdf);
    path.specularBounce = (bs.flags & kBsdfSpecular) != 0u;
    path.bsdfPdf = bs.pdfIsProportional
                       ? bsdfPdf(material, woLocal, bs.wi,
                                 makeRandomStream(pixel, sampleIndex, dim, seed, kStreamSamplePdf))
                       : bs.pdf;
    if ((bs.flags & kBsdfTransmission) != 0u) path.etaScale *= bs.eta * bs.eta;
    // The new ray leaves from the side it goes to.
    n = dot(ng, wi) > 0.0 ? ng : -ng;
#endif
  } else {
    vec3 f = material.reflectance * kInvPi;
    // Sample direct illumination from an emitter (next-event estimation).
    if (neeOn() && material.reflectance != vec3(0.0)) {
      path.L += sampleDirectLight(p, n, ng, shaded, magnitude, path.beta, f,
                                  random2(sobol, pixel, sampleIndex, dim + kDimLightChoose, seed),
                                  random2(sobol, pixel, sampleIndex, dim + kDimLightPoint, seed),
                                  misOn(), path.depth, retrace);
    }
    // Sample the BSDF: cosine-weighted, so f * cos / pdf = reflectance.
    wi = localToWorld(
        sampleCosineHemisphere(random2(sobol, pixel, sampleIndex, dim + kDimBsdf, seed)), n);
    path.bsdfPdf = dot(wi, n) * kInvPi;
    // A direction in the tangent plane: zero contribution.
    if (!(path.bsdfPdf > 0.0)) return true;
    path.beta *= material.reflectance;
    path.specularBounce = false;
  }
  if (maxComponent(path.beta) <= 0.0) return true;

  // Possibly terminate the path with Russian roulette (unbiased: survivors are scaled).
  if (rouletteOn() && path.depth >= params.rrStartDepth) {
    float q = max(0.0, 1.0 - maxComponent(kBsdfMaterials ? path.beta * path.etaScale : path.beta));
    if (random1(sobol, pixel, sampleIndex, dim + kDimRoulette, seed) < q) return true;
    path.beta /= 1.0 - q;
  }

  // Leave the surface on the side of the new direction.
  if (shaded) n = dot(ng, wi) > 0.0 ? ng : -ng;
  path.origin = offsetRayOrigin(p, n, magnitude);
  path.direction = wi;
  return false;
}

void main() {
  params = paramsBuffer;
  uvec2 pixel = gl_GlobalInvocationID.xy;
  if (pixel.x >= params.camera.width || pixel.y >= params.camera.height) return;
  uint index = pixel.y * params.camera.width + pixel.x;
  gDebug = index == pass.debugPixel;
  // The film's pixel, which the random numbers and the camera ray are of: a crop renders its
  // pixels of the whole film's image.
  uvec2 filmPixel = pixel + uvec2(params.camera.cropX, params.camera.cropY);

  // This dispatch's samples of the pixel, added in float to the batch's sum one by one, in
  // the order of their indices: how a batch's samples are split into dispatches does not
  // change a bit of it (the host folds it into the film's exact sums after every batch, a few
  // dozen samples at most). One loop runs them all, a bounce per iteration, and a path that
  // ends makes way for the next sample's at once (path regeneration): the invocations of a
  // SIMD group (lavapipe's vector lanes, a GPU's warp) each go on with a ray of their own,
  // rather than wait for the group's longest path of the same sample. Every sample is still
  // its own path with its own random numbers.
  vec3 sum = accum[index].sum;
  uint invalid = 0u;
  uint truncated = 0u;
  uint done = 0u;
  bool finished = pass.sampleCount == 0u;
  Path path = startPath(filmPixel, pass.sampleIndex);
  gTruncated = false;
  while (!finished) {
    gLoopIterations++;
    Retrace retrace = Retrace(false, false, vec3(0.0), vec3(0.0), vec3(0.0));
    bool ended = extendPath(path, filmPixel, retrace);
    // The rare ray to trace again with the exact test (see Retrace).
    if (retrace.pending) {
      HitData exactHit;
      bool inexact;
      bool found =
          traceRayWith(/*exact=*/true, retrace.origin, retrace.direction,
                       retrace.shadow ? 1.0 : 1.0 / 0.0, retrace.shadow, exactHit, inexact);
      if (retrace.shadow) {
        if (!found) path.L += retrace.contribution;
      } else {
        path.hitReady = true;
        path.hitFound = found;
        path.hit = exactHit;
      }
    }
    if (!ended) continue;
    // The camera sample's weight: 1 but for the negative lobes of some filters (filter.h).
    vec3 L = path.L * path.weight;
#ifdef PT_DEBUG_PRINTF
    if (gDebug) {
      debugPrintfEXT("gpu sample %u: L=(%g, %g, %g)", path.sampleIndex, L.x, L.y, L.z);
    }
#endif
    // Lavapipe's cap, once reached, ends every loop after its first iteration. A loop that
    // must run twice, to a bound the compiler cannot know, tells whether it was reached by
    // now: a flag set on every way out of a loop cannot, as the compiler folds it to true.
    uint canary = 0u;
    for (uint bound = min(pass.sampleCount, 1u) + 1u; canary < bound;) canary++;
    if (canary < 2u) gTruncated = true;
    // A path given up at the loop budget is reported, never added as if complete.
    if (gTruncated) {
      truncated++;
      invalid++;
    } else if (any(isnan(L)) || any(isinf(L))) {
      invalid++;  // counted, never silently dropped
    } else {
      sum += L;
    }
    done++;
    finished = done == pass.sampleCount;
    // The next sample's path.
    path = startPath(filmPixel, pass.sampleIndex + done);
    gTruncated = false;
  }
  // The loop itself can be cut short by lavapipe's cap: the samples it never finished.
  truncated += pass.sampleCount - done;
  invalid += pass.sampleCount - done;

  accum[index].sum = sum;
  accum[index].invalid += invalid;
  if (truncated > 0u) atomicAdd(counters.truncated, truncated);
  atomicMax(counters.maxLoopIterations, gLoopIterations);
  uint before = atomicAdd(counters.raysLow, gRays);
  if (before + gRays < before) atomicAdd(counters.raysHigh, 1u);  // carry into the high word
}
