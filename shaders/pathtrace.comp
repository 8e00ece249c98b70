// The GPU path tracer: one invocation traces a pass's samples of one pixel (as many as the
// host chose for the dispatch) and adds them to the accumulation buffer's sums. The same
// integrator as host/cpu/integrator.cpp (NEE + BSDF sampling with MIS, Russian roulette):
// its steps at a path vertex are path_vertex.h's, which the CPU calls too, as it shares the
// layouts (shared_types.h), random numbers (sampling.h), BSDFs (bsdf.h), lights and textures.
// What is this file's own: the traversal (bvh.glsl), the exact retrace of rays the fast test
// gave up on, the path regeneration loop, lavapipe's loop cap, and the accumulation. The other
// integrators' variants replace main: SPPM's passes (sppm.glsl) and bidirectional path tracing
// (PT_BDPT, bdpt.glsl).
#version 460
#extension GL_GOOGLE_include_directive : require
#ifdef PT_DEBUG_PRINTF
#extension GL_EXT_debug_printf : enable
#endif
#if defined(PT_SPPM_PHOTONS) || defined(PT_BDPT)
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#endif

#include "sampling.h"
#include "shared_types.h"

layout(local_size_x = kWorkgroupSize, local_size_y = kWorkgroupSize) in;

// The effect set: what the scene does not use is compiled out. The host compiles this shader
// for each scene with its effects as these definitions (PT_FX_SET and every PT_FX_*, see
// host/vulkan/backend.cpp and host/render/prepare.h); without them, as the build checks it,
// every effect is compiled in, and the intersection test and the sampler are read from the
// parameters (kSpecAtRunTime).
#ifndef PT_FX_SET
#define PT_FX_DIFFUSE true
#define PT_FX_MIRROR true
#define PT_FX_NEE true
#define PT_FX_BSDF_EMISSION true
#define PT_FX_MIS true
#define PT_FX_RR true
#define PT_FX_INTERSECTION kSpecAtRunTime
#define PT_FX_SAMPLER kSpecAtRunTime
#define PT_FX_LIGHT_BVH true
#define PT_FX_CONDUCTOR true
#define PT_FX_DIELECTRIC true
#define PT_FX_THIN_DIELECTRIC true
#define PT_FX_DIFFUSE_TRANSMISSION true
#define PT_FX_COATED_DIFFUSE true
#define PT_FX_GLTF true
#define PT_FX_GLTF_LAYERS true
#define PT_FX_GLTF_SHEEN true
#define PT_FX_SHADING_NORMALS true
#define PT_FX_DELTA_LIGHTS true
#define PT_FX_ENVIRONMENT true
#define PT_FX_TWO_SIDED_EMITTERS true
#define PT_FX_SPHERE_LIGHTS true
#define PT_FX_TEXTURES true
#define PT_FX_ALPHA true
#define PT_FX_BUMP true
#define PT_FX_TEXTURE_FEATURES kTextureUsesAll
#define PT_FX_MEDIUM_KINDS 0xFFFFFFFFu
#define PT_FX_ENVIRONMENT_IMAGE true
#endif
const bool kDiffuse = PT_FX_DIFFUSE;
const bool kMirror = PT_FX_MIRROR;
const bool kNee = PT_FX_NEE;
const bool kBsdfEmission = PT_FX_BSDF_EMISSION;
const bool kMis = PT_FX_MIS;
const bool kRussianRoulette = PT_FX_RR;
const uint kIntersection = PT_FX_INTERSECTION;
const uint kSampler = PT_FX_SAMPLER;
const bool kLightBvh = PT_FX_LIGHT_BVH;
#ifdef PT_NO_BSDF_MATERIALS
// The variant for scenes of diffuse and mirror surfaces without vertex normals (the host picks
// it): nothing of bsdf.h is compiled in, and no binding of the environment.
const bool kConductor = false;
const bool kDielectric = false;
const bool kThinDielectric = false;
const bool kDiffuseTransmission = false;
const bool kCoatedDiffuse = false;
const bool kGltf = false;
const bool kGltfLayers = false;
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
const bool kConductor = PT_FX_CONDUCTOR;
const bool kDielectric = PT_FX_DIELECTRIC;
const bool kThinDielectric = PT_FX_THIN_DIELECTRIC;
const bool kDiffuseTransmission = PT_FX_DIFFUSE_TRANSMISSION;
const bool kCoatedDiffuse = PT_FX_COATED_DIFFUSE;
const bool kGltf = PT_FX_GLTF;
const bool kGltfLayers = PT_FX_GLTF_LAYERS;
const bool kGltfSheens = PT_FX_GLTF_SHEEN;
const bool kShadingNormals = PT_FX_SHADING_NORMALS;
const bool kDeltaLights = PT_FX_DELTA_LIGHTS;
const bool kEnvironment = PT_FX_ENVIRONMENT;
const bool kTwoSidedEmitters = PT_FX_TWO_SIDED_EMITTERS;
const bool kSphereLights = PT_FX_SPHERE_LIGHTS;
const bool kTextures = PT_FX_TEXTURES;
const bool kAlphaCutouts = PT_FX_ALPHA;
const bool kBumpMaps = PT_FX_BUMP;
const uint kTextureFeatures = PT_FX_TEXTURE_FEATURES;
const uint kMediumKinds = PT_FX_MEDIUM_KINDS;
const bool kEnvironmentImage = PT_FX_ENVIRONMENT_IMAGE;
#endif
// Some emitter is one of lights.h's (not a triangle).
const bool kAnalyticLights = kDeltaLights || kEnvironment || kSphereLights;
// Some surface has one of bsdf.h's materials; bsdf.h's switch sees only the types in use.
const bool kBsdfMaterials =
    kConductor || kDielectric || kThinDielectric || kDiffuseTransmission || kCoatedDiffuse || kGltf;

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
layout(set = 0, binding = PT_BINDING_LIGHT_BVH) uniform usamplerBuffer lightBvhTexels;
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
#ifdef PT_VOLPATH
layout(set = 0, binding = PT_BINDING_MEDIA) uniform usamplerBuffer mediumTexels;
layout(set = 0, binding = PT_BINDING_MEDIUM_GRIDS) uniform usamplerBuffer mediumGridTexels;
layout(set = 0, binding = PT_BINDING_MEDIUM_INTERFACES) uniform usamplerBuffer interfaceTexels;
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

// The sheen's albedo table (sheen_albedo.h), uploaded after the materials where a scene has a
// sheen, from texel PT_SHEEN_ALBEDO_TEXEL on.
#ifndef PT_SHEEN_ALBEDO_TEXEL
#define PT_SHEEN_ALBEDO_TEXEL 0
#endif
float sheenAlbedoNode(int i) {
  return uintBitsToFloat(texelFetch(materialTexels, PT_SHEEN_ALBEDO_TEXEL + (i >> 2))[i & 3]);
}

#ifndef PT_NO_BSDF_MATERIALS
// bsdf.h, for the material types in use, its loops counted.
#define PT_HAS_CONDUCTOR kConductor
#define PT_HAS_DIELECTRIC kDielectric
#define PT_HAS_THIN_DIELECTRIC kThinDielectric
#define PT_HAS_DIFFUSE_TRANSMISSION kDiffuseTransmission
#define PT_HAS_COATED_DIFFUSE kCoatedDiffuse
#define PT_HAS_GLTF kGltf
#define PT_HAS_GLTF_LAYERS kGltfLayers
#define PT_HAS_GLTF_SHEEN kGltfSheens
#define PT_HAS_GLTF_COAT_NORMAL ((kTextureFeatures & kTextureUsesCoatNormal) != 0u)
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
  uvec4 e = texelFetch(textureTexels, at + 4);
  return TextureNode(uintBitsToFloat(a.xyz), a.w, uintBitsToFloat(b), c.x, c.y, c.z, c.w, d.x, d.y,
                     d.z, uintBitsToFloat(d.w), uintBitsToFloat(e.xy), e.z, e.w);
}
uint imageWordAt(uint i) {
  return texelFetch(imageTexels, int(i >> 2u))[i & 3u];
}
MaterialTextures materialTexturesAt(uint i) {
  int at = int(kMaterialTextureTexels * i);
  uvec4 a = texelFetch(materialTextureTexels, at);
  uvec4 b = texelFetch(materialTextureTexels, at + 1);
  uvec4 c = texelFetch(materialTextureTexels, at + 2);
  uvec4 d = texelFetch(materialTextureTexels, at + 3);
  // glTF's extension textures: read only in the shaders of scenes that have one.
  bool layers = (kTextureFeatures &
                 (kTextureUsesGltfLayers | kTextureUsesGltfSheen | kTextureUsesCoatNormal)) != 0u;
  uvec4 e = layers ? texelFetch(materialTextureTexels, at + 4) : uvec4(kNoTexture);
  uvec4 f = layers ? texelFetch(materialTextureTexels, at + 5) : uvec4(kNoTexture);
  return MaterialTextures(a.x, a.y, a.z, a.w, b.x, b.y, b.z, b.w, c.x, uintBitsToFloat(c.y), c.z,
                          c.w, d.x, d.y, uintBitsToFloat(d.z), uintBitsToFloat(d.w), e.x, e.y, e.z,
                          e.w, f.x, f.y, f.z, f.w);
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
// Whether PT_HIT_FILTER has anything to judge at a hit on tri: its material has an alpha
// texture (MaterialTextures::alpha, the second texel's w).
bool materialHasAlpha(uint material) {
  return texelFetch(materialTextureTexels, int(kMaterialTextureTexels * material) + 1).w !=
         kNoTexture;
}
#define PT_HIT_FILTERED(tri) \
  (kAlphaCutouts && params.texturesPresent != 0u && materialHasAlpha(tri.material))
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
  uvec4 a = texelFetch(normalTexels, at);
  uvec4 b = texelFetch(normalTexels, at + 1);
  uvec4 c = texelFetch(normalTexels, at + 2);
  return TriangleNormals(uintBitsToFloat(a.xyz), a.w, uintBitsToFloat(b.xyz), b.w,
                         uintBitsToFloat(c.xyz), c.w);
}
#endif

Emitter loadEmitter(uint i) {
  uvec4 a = texelFetch(emitterTexels, int(i));
  return Emitter(a.x, uintBitsToFloat(a.y), uintBitsToFloat(a.z), a.w);
}

// The light BVH's nodes, then its words: each Emitter's leaf, then the unbounded Emitters.
LightBvhNode loadLightBvhNode(uint i) {
  int at = int(kLightBvhTexels * i);
  uvec4 a = texelFetch(lightBvhTexels, at);
  uvec4 b = texelFetch(lightBvhTexels, at + 1);
  uvec4 c = texelFetch(lightBvhTexels, at + 2);
  uvec4 d = texelFetch(lightBvhTexels, at + 3);
  return LightBvhNode(uintBitsToFloat(a.xyz), uintBitsToFloat(a.w), uintBitsToFloat(b.xyz),
                      uintBitsToFloat(b.w), uintBitsToFloat(c.x), uintBitsToFloat(c.y),
                      uintBitsToFloat(c.z), c.w, d.x, d.y, d.z, d.w);
}
uint lightBvhWord(uint i) {
  return texelFetch(lightBvhTexels,
                    int(kLightBvhTexels * params.lightBvhNodes + (i >> 2u)))[i & 3u];
}
uint loadEmitterLeaf(uint emitter) {
  return lightBvhWord(emitter);
}
uint loadUnboundedEmitter(uint k) {
  return lightBvhWord(params.emitterCount + k);
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

// The path's vertex (path_vertex.h), over the effects in use.
#define PT_HAS_DIFFUSE kDiffuse
#define PT_HAS_MIRROR kMirror
#define PT_HAS_NEE kNee
#define PT_HAS_MIS kMis
#define PT_HAS_BSDF_EMISSION kBsdfEmission
#define PT_HAS_RUSSIAN_ROULETTE kRussianRoulette
#define PT_HAS_SHADING_NORMALS kShadingNormals
#define PT_HAS_TWO_SIDED_EMITTERS kTwoSidedEmitters
#define PT_HAS_SPHERE_LIGHTS kSphereLights
#define PT_HAS_LIGHT_BVH kLightBvh
#define PT_HAS_ANALYTIC_LIGHTS kAnalyticLights
#define PT_HAS_ENVIRONMENT kEnvironment
#define PT_HAS_ENVIRONMENT_IMAGE kEnvironmentImage
#define PT_HAS_TEXTURES kTextures
#define PT_HAS_BUMP_MAPS kBumpMaps
#ifdef PT_NO_BSDF_MATERIALS
#define PT_HAS_FOOTPRINTS false
#else
#define PT_HAS_FOOTPRINTS ((kTextureFeatures & kTextureUsesFootprints) != 0u)
#endif
#define PT_HAS_BSDF_MATERIALS kBsdfMaterials
#ifdef PT_VOLPATH
#define PT_HAS_MEDIA true
#else
#define PT_HAS_MEDIA false
#endif
#include "path_vertex.h"

#ifdef PT_VOLPATH
// What medium.h and volume_vertex.h read, from the media bindings.
Medium loadMedium(uint i) {
  int at = int(kMediumTexels * i);
  uvec4 a = texelFetch(mediumTexels, at);
  uvec4 b = texelFetch(mediumTexels, at + 1);
  uvec4 c = texelFetch(mediumTexels, at + 2);
  uvec4 d = texelFetch(mediumTexels, at + 3);
  uvec4 e = texelFetch(mediumTexels, at + 4);
  uvec4 f = texelFetch(mediumTexels, at + 5);
  return Medium(uintBitsToFloat(a.xyz), a.w, uintBitsToFloat(b.xyz), uintBitsToFloat(b.w),
                uintBitsToFloat(c.xyz), c.w, uintBitsToFloat(d.xyz), d.w, uintBitsToFloat(e.xyz),
                e.w, f.xyz, f.w, uintBitsToFloat(texelFetch(mediumTexels, at + 6)),
                uintBitsToFloat(texelFetch(mediumTexels, at + 7)),
                uintBitsToFloat(texelFetch(mediumTexels, at + 8)));
}
float mediumGridFloat(uint i) {
  return uintBitsToFloat(texelFetch(mediumGridTexels, int(i >> 2u))[i & 3u]);
}
uint mediumGridWord(uint i) {
  return texelFetch(mediumGridTexels, int(i >> 2u))[i & 3u];
}
MediumInterface loadMediumInterface(uint primitive) {
  uvec4 a = texelFetch(interfaceTexels, int(primitive >> 1u));
  return (primitive & 1u) != 0u ? MediumInterface(a.z, a.w) : MediumInterface(a.x, a.y);
}
#define PT_MEDIUM_LOOP_TICK() gLoopIterations++
#define PT_MEDIUM_KINDS kMediumKinds
#include "volume_vertex.h"
#endif
#if defined(PT_CHECK_LIGHT_PATHS) || defined(PT_SPPM)
// The headers of bidirectional path tracing and photon mapping (docs/bdpt.md, docs/sppm.md):
// SPPM's passes call them; the build also compiles them all here, every effect on.
#include "bdpt_camera.h"
#include "bdpt_connect.h"
#include "bdpt_vertex.h"
#include "sppm_vertex.h"
#endif
#ifdef PT_SPPM
#include "sppm.glsl"
#endif
#ifdef PT_BDPT
#include "bdpt_connect.h"
#include "bdpt_sample.h"
#include "bdpt_splat.h"
#include "bdpt_vertex.h"

// After the headers it calls (a block of its own, so that include sorting keeps it last).
#include "bdpt.glsl"
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

// Traces the shadow ray of a light sample (path_vertex.h) from `from` to `to`, `direction`
// spanning it with t in [0, 1): kShadowOccluded, kShadowClear, or kShadowRetrace when the
// traversal gave up (see Retrace), the ray then to be traced again later.
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
// A clear shadow ray's contribution, or zero with `retrace` set to add it once the ray has been
// traced again.
vec3 addOrDefer(uint shadow, vec3 from, vec3 direction, vec3 contribution, inout Retrace retrace) {
  if (shadow != kShadowRetrace) return contribution;
  retrace = Retrace(true, true, from, direction, contribution);
  return vec3(0.0);
}

// --debug-pixel's line about a light sample found clear (integrator.cpp prints the same).
void debugLightSample(uint depth, LightSample ls, float weight) {
#ifdef PT_DEBUG_PRINTF
  if (gDebug) {
    if ((ls.emitter & kEmitterLight) != 0u) {
      debugPrintfEXT("gpu depth %u: light sample on analytic light pdf=%g weight=%g", depth,
                     ls.lightPdf, weight);
    } else {
      debugPrintfEXT("gpu depth %u: light sample on triangle %u (primitive %u) pdf=%g weight=%g",
                     depth, ls.emitter, loadTriangle(ls.emitter).primitive, ls.lightPdf, weight);
    }
  }
#endif
}

// The radiance a path has gathered.
#ifdef PT_VOLPATH
#define PATH_RADIANCE(path) path.vol.path.L
#else
#define PATH_RADIANCE(path) path.state.L
#endif

// What sampleRadiance (host/cpu/integrator.cpp) keeps across its loop: one sample's path,
// between two bounces.
struct Path {
  uint sampleIndex;
  uint depth;   // scattering events so far
  vec3 origin;  // the ray to trace next
  vec3 direction;
#ifdef PT_VOLPATH
  VolumePath vol;  // PathState and what media add (volume_vertex.h)
  uint crossings;  // interface surfaces crossed since the last scattering event
#else
  PathState state;  // L, beta, etaScale, bsdfPdf, specularBounce (path_vertex.h)
#endif
  float weight;  // the camera sample's weight (filter.h): multiplies L at the end
#ifdef PT_SPPM_CAMERA
  bool ending;  // past SPPM's visible point: the path's last ray is under way
#endif
  bool hitReady;  // the ray's closest hit is hitFound and hit already (see Retrace)
  bool hitFound;
  HitData hit;
};

// sampleRadiance's start: the camera ray through a point of the pixel's filter (and of the
// lens), radiance 0, throughput 1. `pixel` is the film's (the image's plus the crop's corner).
Path startPath(uvec2 pixel, uint sampleIndex) {
  Path path;
  path.sampleIndex = sampleIndex;
  path.depth = 0u;
  CameraSample camera = cameraSampleOf(params.camera, PT_SOBOL, pixel, sampleIndex, params.seed);
  path.origin = camera.origin;
  path.direction = camera.direction;
  path.weight = camera.weight;
#ifdef PT_VOLPATH
  path.vol = startVolumePath(pixel, sampleIndex, camera);
  path.crossings = 0u;
#else
  path.state = cameraPathState(camera);
#endif
#ifdef PT_SPPM_CAMERA
  path.ending = false;
#endif
  path.hitReady = false;
  path.hitFound = false;
  path.hit = HitData(0.0, 0u);
  return path;
}

#ifdef PT_VOLPATH
#include "volpath.glsl"
#else
// One iteration of sampleRadiance's loop (the same steps of path_vertex.h): traces the path's
// ray, adds the emission it finds, samples a light, scatters. Returns true when the path has
// ended, its radiance then being path.state.L once `retrace` is done (main).
bool extendPath(inout Path path, uvec2 pixel, inout Retrace retrace) {
  uint seed = params.seed;
  bool sobol = PT_SOBOL;  // else independent random numbers
  uint sampleIndex = path.sampleIndex;
  // Find the closest surface along the ray.
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
    // The ray leaves the scene: the infinite light's radiance, weighed as an emitter's.
    addEnvironmentFound(path.state, path.direction);
    return true;
  }
  // The shading point: material (textures resolved), hit point from the barycentrics (more
  // accurate than origin + t * direction), normals, how it scatters.
  Triangle tri = loadTriangle(hit.triangle);
  SurfacePoint s =
      surfacePointAt(hit.triangle, tri, hitBarycentrics(path.origin, path.direction, tri),
                     -path.direction, path.state.rd);
#ifdef PT_DEBUG_PRINTF
  if (gDebug) {
    debugPrintfEXT(
        "gpu depth %u: hit triangle %u (primitive %u) t=%g p=(%g, %g, %g) beta=(%g, %g, %g)",
        path.depth, hit.triangle, tri.primitive, hit.t, s.p.x, s.p.y, s.p.z, path.state.beta.x,
        path.state.beta.y, path.state.beta.z);
  }
#endif

  // Add emitted light found by this ray, weighed against light sampling (MIS).
  addEmissionFound(path.state, tri, s, hit.t, path.origin);

  // Stop after maxDepth scattering events (or one ray past SPPM's visible point).
  if (path.depth == params.maxDepth) return true;
#ifdef PT_SPPM_CAMERA
  if (path.ending) return true;
#endif
  VertexKey key = VertexKey(pixel, sampleIndex, kDimFirstBounce + kDimsPerBounce * path.depth);
  ++path.depth;
#ifdef PT_SPPM_CAMERA
  path.ending = sppmKeepVisiblePoint(s, key, path.depth, path.state.beta * path.weight);
#endif

  // Sample direct illumination from an emitter (next-event estimation): a light sample, its
  // shadow ray, its contribution weighed against BSDF sampling (MIS).
  if (samplesLightAt(s)) {
    vec2 uLight = random2(sobol, pixel, sampleIndex, key.dim + kDimLightPoint, seed);
    LightSample ls = sampleLightAt(
        s, key, random2(sobol, pixel, sampleIndex, key.dim + kDimLightChoose, seed), uLight);
    if (ls.found) {
#ifndef PT_NO_BSDF_MATERIALS
      if (kAlphaCutouts) gAlphaU = shadowAlphaRandom(uLight);
#endif
      vec3 direction;
      uint shadow = traceShadowRayTo(ls.from, ls.to, direction);
      if (shadow != kShadowOccluded) {
        float weight;
        vec3 contribution = lightSampleContribution(s, key, ls, path.state.beta, weight);
        debugLightSample(path.depth, ls, weight);
        path.state.L += addOrDefer(shadow, ls.from, direction, contribution, retrace);
      }
    }
  }

  // Sample the BSDF for the next direction; the lobe choice takes the roulette dimension's
  // second number.
  vec2 uRoulette = random2(sobol, pixel, sampleIndex, key.dim + kDimRoulette, seed);
  vec3 wi;
  if (!sampleBsdfAt(s, key, path.state, uRoulette.y,
                    random2(sobol, pixel, sampleIndex, key.dim + kDimBsdf, seed), wi)) {
    return true;
  }
  if (maxComponent(path.state.beta) <= 0.0) return true;

  // Possibly terminate the path with Russian roulette (unbiased: survivors are scaled).
  if (!survivesRoulette(path.state, path.depth, uRoulette.x)) return true;

  // Leave the surface on the side of the new direction.
  path.origin = nextRayOrigin(s, wi);
  path.direction = wi;
  return false;
}
#endif

#ifdef PT_SPPM_PHOTONS
void main() {
  sppmTracePhotons();
}
#elif defined(PT_BDPT)
void main() {
  bdptMain();
}
#else
void main() {
  params = paramsBuffer;
  uvec2 pixel = gl_GlobalInvocationID.xy;
  if (pixel.x >= params.camera.width || pixel.y >= params.camera.height) return;
  uint index = pixel.y * params.camera.width + pixel.x;
  gDebug = index == pass.debugPixel;
#ifdef PT_SPPM_CAMERA
  gSppmPixel = index;
#endif
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
        if (!found) PATH_RADIANCE(path) += retrace.contribution;
      } else {
        path.hitReady = true;
        path.hitFound = found;
        path.hit = exactHit;
      }
    }
    if (!ended) continue;
    // The camera sample's weight: 1 but for the negative lobes of some filters (filter.h).
    vec3 L = PATH_RADIANCE(path) * path.weight;
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
#endif
