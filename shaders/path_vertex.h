// What a path does at a surface vertex, written once for the CPU reference, the CPU's vector
// lanes and the shader (C++ through GLM, GLSL through #include): the shading point of a hit,
// the emission a ray finds and its MIS weight, light sampling (choosing an emitter, a point or
// direction on it, the shadow ray's ends, the sample's MIS weight and contribution), the BSDF
// sample's continuation and Russian roulette. They are the steps of pbrt-v4's
// PathIntegrator::Li and SampleLd; each integrator calls them in that order and keeps only
// what is its own: how rays are traced (and when), how paths are scheduled, how the film is
// written. The BSDFs are bsdf.h's, the lights lights.h's and environment.h's, the textures
// texture.h's.
//
// What the functions read: in C++ a PathScene (the scene's arrays); in GLSL the includer
// defines loadTriangle(i), loadMaterial(i), loadEmitter(i), loadLight(i), loadNormals(i),
// triangleShadingAt(i, tri), environmentMap() and the global `params` before including this.
// PT_SCENE_PARAM / PT_SCENE_ARG pass the PathScene in C++ and nothing in GLSL.
//
// Effects a scene does not use fold away in the shader: it defines the PT_HAS_* switches as
// the constants it is compiled with for the scene (C++ has them all, and tests the data). The
// shader variant for scenes of Lambertian and mirror surfaces only defines PT_NO_BSDF_MATERIALS,
// and none of bsdf.h's other materials, lights.h, texture.h and environment.h is compiled in.
//
// Floating-point operations are in the order the images of the renderer were made with:
// backends that call these functions give the bits they gave before. Where a product is
// grouped oddly for that reason, the comment says so.
#ifndef PT_PATH_VERTEX_H
#define PT_PATH_VERTEX_H

#include "bsdf.h"
#include "differentials.h"
#include "filter.h"
#include "light_bvh.h"
#include "sampling.h"
#include "shared_types.h"
#ifndef PT_NO_BSDF_MATERIALS
#include "environment.h"
#include "lights.h"
#include "texture.h"
#endif

#ifndef PT_HAS_DIFFUSE
#define PT_HAS_DIFFUSE true
#define PT_HAS_MIRROR true
#define PT_HAS_NEE true
#define PT_HAS_MIS true
#define PT_HAS_BSDF_EMISSION true
#define PT_HAS_RUSSIAN_ROULETTE true
#define PT_HAS_SHADING_NORMALS true
#define PT_HAS_TWO_SIDED_EMITTERS true
#define PT_HAS_SPHERE_LIGHTS true
#define PT_HAS_LIGHT_BVH true
#define PT_HAS_ANALYTIC_LIGHTS true
#define PT_HAS_ENVIRONMENT true
#define PT_HAS_ENVIRONMENT_IMAGE true
#define PT_HAS_TEXTURES true
#define PT_HAS_BUMP_MAPS true
#define PT_HAS_FOOTPRINTS true
#define PT_HAS_BSDF_MATERIALS true
#define PT_HAS_MEDIA true
#endif

#ifdef __cplusplus
namespace pt {
#endif

// A triangle's geometric normal, area and the scale of the ray offsets there: what every hit
// and every light sample on it needs. The CPU computes them once per triangle
// (computeTriangleShading, render/prepare.h); the shader at each use. Same operations, same
// bits (host code is compiled without fused multiply-adds).
struct TriangleShading {
  vec3 normal;      // normalize(cross(v1 - v0, v2 - v0)): the unit geometric normal
  float magnitude;  // triangleMagnitude(v0, v1, v2): the scale of the ray offsets there
  float area;       // 0.5 * length(cross(v1 - v0, v2 - v0))
};

PT_INLINE TriangleShading triangleShadingOf(Triangle t) {
  vec3 edgeCross = cross(t.v1 - t.v0, t.v2 - t.v0);
  return TriangleShading(normalize(edgeCross), triangleMagnitude(t.v0, t.v1, t.v2),
                         0.5f * length(edgeCross));
}

#ifdef __cplusplus
// The scene's arrays as the vertex functions read them on the CPU.
struct PathScene {
  const RenderParams* params;
  const Triangle* triangles;       // Bvh::triangles
  const TriangleShading* shading;  // by triangle
  const Material* materials;
  const Emitter* emitters;
  const Light* lights;
  const TriangleNormals* normals;  // by Triangle::primitive; null without vertex normals
  TextureTables textures;
  const vec4* environmentTexels;
  // Participating media (medium.h, volume_vertex.h); null in a scene without any.
  const Medium* media;
  const float* mediumGrids;                 // grid floats, majorant grids included
  const MediumInterface* mediumInterfaces;  // by Triangle::primitive
  // The light BVH (light_bvh.h), null without one: its nodes, and its words (each Emitter's
  // leaf, then the unbounded Emitters).
  const LightBvhNode* lightBvh;
  const uint* lightBvhWords;
};
#define PT_SCENE_PARAM const PathScene &scene,
#define PT_SCENE_ARG scene,
#define PT_SCENE_ONLY scene
#define PT_SCENE_PARAM_ONLY const PathScene& scene
#define PT_PARAMS (*scene.params)
#define PT_SCENE_TEXTURES scene.textures,
inline const Triangle& loadTriangle(const PathScene& scene, uint i) {
  return scene.triangles[i];
}
inline const TriangleShading& triangleShadingAt(const PathScene& scene, uint i, const Triangle&) {
  return scene.shading[i];
}
inline const Material& loadMaterial(const PathScene& scene, uint i) {
  return scene.materials[i];
}
inline const Emitter& loadEmitter(const PathScene& scene, uint i) {
  return scene.emitters[i];
}
inline const Light& loadLight(const PathScene& scene, uint i) {
  return scene.lights[i];
}
inline const LightBvhNode& loadLightBvhNode(const PathScene& scene, uint i) {
  return scene.lightBvh[i];
}
inline uint loadEmitterLeaf(const PathScene& scene, uint emitter) {
  return scene.lightBvhWords[emitter];
}
inline uint loadUnboundedEmitter(const PathScene& scene, uint k) {
  return scene.lightBvhWords[scene.params->emitterCount + k];
}
inline const TriangleNormals& loadNormals(const PathScene& scene, uint primitive) {
  return scene.normals[primitive];
}
inline EnvironmentMap environmentMap(const PathScene& scene) {
  const RenderParams& p = *scene.params;
  return EnvironmentMap{p.environmentX,         p.environmentY,      p.environmentZ,
                        p.environmentWidth,     p.environmentHeight, p.environmentMapping,
                        scene.environmentTexels};
}
#else
TriangleShading triangleShadingAt(uint i, Triangle tri) {
  return triangleShadingOf(tri);
}
#define PT_SCENE_PARAM
#define PT_SCENE_ARG
#define PT_SCENE_ONLY
#define PT_SCENE_PARAM_ONLY
#define PT_PARAMS params
#define PT_SCENE_TEXTURES
#endif

// ---- The strategy ---------------------------------------------------------------------------
// Light sampling, BSDF-sampled emission, their MIS and Russian roulette, as the scene and the
// command line ask (--strategy, --rr) and the effects allow.

PT_INLINE bool neeOn(PT_SCENE_PARAM_ONLY) {
  return PT_HAS_NEE && PT_PARAMS.emitterCount > 0u && PT_PARAMS.strategy != kStrategyBsdf;
}
PT_INLINE bool misOn(PT_SCENE_PARAM_ONLY) {
  return PT_HAS_MIS && PT_PARAMS.strategy == kStrategyMis;
}
PT_INLINE bool bsdfEmissionOn(PT_SCENE_PARAM_ONLY) {
  return PT_HAS_BSDF_EMISSION && PT_PARAMS.strategy != kStrategyNee;
}
PT_INLINE bool rouletteOn(PT_SCENE_PARAM_ONLY) {
  return PT_HAS_RUSSIAN_ROULETTE && PT_PARAMS.russianRoulette != 0u;
}
// Whether textures read the ray's footprint (differentials.h): paths then carry differentials.
PT_INLINE bool footprintsOn(PT_SCENE_PARAM_ONLY) {
  return PT_HAS_FOOTPRINTS && PT_PARAMS.footprints != 0u;
}

// ---- The path and its vertex ------------------------------------------------------------------

// What a path carries from one vertex to the next (pbrt-v4's names).
struct PathState {
  vec3 L;               // radiance gathered so far
  vec3 beta;            // path throughput
  float etaScale;       // product of the squared relative indices refracted through (for RR)
  float bsdfPdf;        // solid-angle pdf of the BSDF sample that produced the ray
  bool specularBounce;  // the ray leaves a specular bounce (or the camera)
  vec3 prevP;           // the last scattering vertex (the camera's position at first) and the
  vec3 prevN;           // normal the light BVH weighs there (zero in a medium): the light
                        // choice's probability for emission the ray finds is measured there
  RayDifferential rd;   // the ray's differentials, where textures read footprints
};

// A path at the camera: nothing gathered, throughput 1; the camera ray counts as specular, so
// that emission it finds is taken at full weight.
PT_INLINE PathState startPathState() {
  return PathState(vec3(0.0f), vec3(1.0f), 1.0f, 0.0f, true, vec3(0.0f), vec3(0.0f),
                   noRayDifferential());
}

// The path of camera sample c (filter.h): as startPathState, with the camera ray's
// differentials where textures read footprints.
PT_INLINE PathState cameraPathState(PT_SCENE_PARAM PT_IN(CameraSample) c) {
  PathState path = startPathState();
  if (footprintsOn(PT_SCENE_ONLY)) {
    path.rd = cameraRayDifferential(PT_PARAMS.camera, c.filmPoint, c.lensOffset, c.origin,
                                    c.direction, PT_PARAMS.differentialScale);
  }
  return path;
}

// The coordinates of a scattering event's random numbers (sampling.h): the BSDFs' random
// streams are drawn from them (bsdf.h's makeRandomStream).
struct VertexKey {
  uvec2 pixel;  // the film's pixel
  uint sampleIndex;
  uint dim;  // the event's first dimension, kDimFirstBounce + kDimsPerBounce * bounce
};

// How a vertex scatters: Lambertian and the ideal mirror about the normal facing the viewer in
// world space, or one of bsdf.h's materials in its shading frame.
PT_CONST uint kScatterLambertian = 0u;
PT_CONST uint kScatterMirror = 1u;
PT_CONST uint kScatterBsdf = 2u;
// A point in a medium (volume_vertex.h): the phase function of asymmetry material.g.
PT_CONST uint kScatterPhase = 3u;

// A path's vertex on a surface: what light sampling, BSDF sampling and the next ray read.
struct SurfacePoint {
  Material material;    // its textured parameters resolved at the hit
  vec3 p;               // the hit point, from the barycentrics
  vec3 ng;              // unit geometric normal
  vec3 ns;              // shading normal (ng without vertex normals or bump), not turned to wo
  vec3 n;               // ns or ng turned towards wo: Lambertian and mirror shade about it
  vec3 wo;              // unit direction towards the previous vertex
  float cosOut;         // dot(ng, wo)
  float magnitude;      // the ray offsets' scale (sampling.h's offsetRayOrigin)
  float area;           // the triangle's area (the density of light sampling's points on it)
  bool shadingNormals;  // ns may differ from ng
  uint scatter;         // kScatter*
  ShadingFrame frame;   // bsdf.h's frame about ns (kScatterBsdf only)
  vec3 woLocal;         // wo in that frame
  vec3 dpdx;            // where textures read footprints: p's change across the pixel
  vec3 dpdy;
  vec3 dndx;  // and the shading normal's (zero without vertex normals)
  vec3 dndy;
};

// The shading point of a hit on triangle `index` (tri) at barycentrics b (weights of v0, v1,
// v2), seen from direction wo by a ray with differentials rd (where textures read footprints).
PT_INLINE SurfacePoint surfacePointAt(PT_SCENE_PARAM uint index, Triangle tri, vec3 b, vec3 wo,
                                      PT_IN(RayDifferential) rd) {
  SurfacePoint s;
  s.material = loadMaterial(PT_SCENE_ARG tri.material);
  s.dpdx = vec3(0.0f);
  s.dpdy = vec3(0.0f);
  s.dndx = vec3(0.0f);
  s.dndy = vec3(0.0f);
  // The normals in locals, stored into s once: reading them back from s would wait on its
  // stores (a store-to-load stall on the CPU).
  TriangleShading shading = triangleShadingAt(PT_SCENE_ARG index, tri);
  vec3 ng = shading.normal;
  bool shadingNormals = PT_HAS_SHADING_NORMALS && PT_PARAMS.normalsPresent != 0u;
#ifndef PT_NO_BSDF_MATERIALS
  // The parameters that textures give, at the hit's texture coordinates and footprint.
  UVFootprint uv = pointFootprint(vec2(0.0f));
  MaterialTextures textures;
  TriangleUVs uvs;
  TriangleDerivatives derivatives;
  bool textured = (PT_HAS_TEXTURES || PT_HAS_BUMP_MAPS) && PT_PARAMS.texturesPresent != 0u;
  bool footprints = textured && footprintsOn(PT_SCENE_ONLY);
  bool footprintUVs = false;  // uv.duvdx, uv.duvdy and derivatives hold the hit's
  if (textured) {
    textures = materialTexturesAt(PT_SCENE_TEXTURES tri.material);
    bool reads = anyTexture(textures);
    // The footprint (pbrt-v4's ComputeDifferentials, about the geometric normal) where it is
    // read: by a texture, or by a specular bounce, which carries it on to the textures the
    // path reaches next. (pbrt-v4 takes it at every hit; elsewhere it goes unused.)
    footprints =
        footprints && (reads || s.material.type == kMaterialMirror || bsdfHasSpecular(s.material));
    if (footprints) {
      surfaceDpdxy(PT_PARAMS, rd, b.x * tri.v0 + b.y * tri.v1 + b.z * tri.v2, ng, s.dpdx, s.dpdy);
    }
    // The texture coordinates only where the material reads them, or where vertex normals
    // turn the differentials of a specular bounce: on a large mesh without textures their load
    // is a cache miss at every hit.
    if (reads || (footprints && shadingNormals)) {
      uvs = uvsAt(PT_SCENE_TEXTURES tri.primitive);
      uv.uv = interpolatedUV(uvs, b);
      footprintUVs = footprints;
      if (footprints || (PT_HAS_BUMP_MAPS && textures.displacement != kNoTexture) ||
          (PT_TEXTURE_USES(kTextureUsesNormalMap) && textures.normalMap != kNoTexture) ||
          (PT_TEXTURE_USES(kTextureUsesCoatNormal) && textures.clearcoatNormal != kNoTexture)) {
        derivatives = triangleDerivatives(tri, uvs);
      }
      if (footprints) {
        footprintUV(derivatives.dpdu, derivatives.dpdv, s.dpdx, s.dpdy, uv.duvdx, uv.duvdy);
      }
    }
    if (PT_HAS_TEXTURES) s.material = resolveMaterialAt(PT_SCENE_TEXTURES s.material, textures, uv);
  }
#endif
  float cosOut = dot(ng, wo);
  // Lambertian and mirror surfaces are two-sided: shaded with the normal facing the ray. With
  // vertex normals, about the interpolated normal. (pbrt-v4 does not guard against the light
  // leaks a shading normal can cause, and nor do we: BSDFs are evaluated about ns whichever
  // side of the geometric surface wi is on; rays leave on the side of ng they go to.)
  vec3 n = cosOut >= 0.0f ? ng : -ng;
  vec3 ns = ng;
#ifndef PT_NO_BSDF_MATERIALS
  // (Zeros unless loaded: read only where shadingNormals, but GCC cannot tell.)
  TriangleNormals normals = TriangleNormals(vec3(0.0f), 0u, vec3(0.0f), 0u, vec3(0.0f), 0u);
  if (shadingNormals) {
    normals = loadNormals(PT_SCENE_ARG tri.primitive);
    ns = interpolatedNormal(normals, b, ng);
    n = dot(ns, wo) >= 0.0f ? ns : -ns;
  }
  bool vertexNormals = shadingNormals;
  bool bumped = PT_HAS_BUMP_MAPS && textured && textures.displacement != kNoTexture;
  // The vertex normals' changes along u and v: for a bump map and for the differentials of
  // specular bounces.
  vec3 dndu = vec3(0.0f);
  vec3 dndv = vec3(0.0f);
  if (shadingNormals && (bumped || footprintUVs)) {
    normalDerivatives(uvs, normals, derivatives.determinant, dndu, dndv);
  }
  if (footprintUVs) {
    s.dndx = dndu * uv.duvdx.x + dndv * uv.duvdx.y;
    s.dndy = dndu * uv.duvdy.x + dndv * uv.duvdy.y;
  }
  // A bump map moves the shading normal (texture.h).
  if (bumped) {
    vec3 moved = bumpedNormal(PT_SCENE_TEXTURES textures.displacement, derivatives, uv, ng, ns,
                              shadingNormals, dndu, dndv);
    if (moved != ns) {
      ns = moved;
      shadingNormals = true;
      n = dot(ns, wo) >= 0.0f ? ns : -ns;
    }
  }
  // A glTF clear coat's own normal (with its kTextureUsesCoatNormal): its clearcoatNormalTexture
  // (scale in textures.scale) on the normal before the base's normal map, or without one that
  // normal itself (the coat is not normal-mapped by the base's normalTexture).
  bool coatNormal = PT_HAS_TEXTURES && PT_TEXTURE_USES(kTextureUsesCoatNormal) && textured &&
                    s.material.type == kMaterialGltf &&
                    (s.material.nSamples & kGltfClearcoat) != 0u &&
                    (textures.clearcoatNormal != kNoTexture || textures.normalMap != kNoTexture);
  bool coatMapped = coatNormal && textures.clearcoatNormal != kNoTexture;
  bool normalMapped = PT_HAS_TEXTURES && PT_TEXTURE_USES(kTextureUsesNormalMap) && textured &&
                      textures.normalMap != kNoTexture;
  vec4 tangent = vec4(0.0f);
  if ((coatMapped || normalMapped) && vertexNormals) tangent = interpolatedTangent(normals, b);
  vec3 coatNs = ns;
  if (coatMapped) {
    coatNs = normalMappedNormal(PT_SCENE_TEXTURES textures.clearcoatNormal, textures.scale,
                                derivatives, tangent, uv, ns);
  }
  // A normal map (glTF's normalTexture) replaces it (texture.h), in the frame of the vertices'
  // tangents where the mesh has them.
  if (normalMapped) {
    ns = normalMappedNormal(PT_SCENE_TEXTURES textures.normalMap, textures.normalScale, derivatives,
                            tangent, uv, ns);
    shadingNormals = true;
    n = dot(ns, wo) >= 0.0f ? ns : -ns;
  }
#endif
  s.p = b.x * tri.v0 + b.y * tri.v1 + b.z * tri.v2;
  s.ng = ng;
  s.ns = ns;
  s.n = n;
  s.wo = wo;
  s.cosOut = cosOut;
  s.magnitude = shading.magnitude;
  s.area = shading.area;
  s.shadingNormals = shadingNormals;
  // The switches fold the type tests away where a scene has one kind of surface.
  uint type = s.material.type;
  if (PT_HAS_MIRROR && ((!PT_HAS_DIFFUSE && !PT_HAS_BSDF_MATERIALS) || type == kMaterialMirror)) {
    s.scatter = kScatterMirror;
  } else if (PT_HAS_BSDF_MATERIALS && (!PT_HAS_DIFFUSE || type != kMaterialDiffuse)) {
    s.scatter = kScatterBsdf;
  } else {
    s.scatter = kScatterLambertian;
  }
#ifndef PT_NO_BSDF_MATERIALS
  if (s.scatter == kScatterBsdf) {
    // The frame about the shading normal, not turned towards the ray: a dielectric tells
    // inside from outside by it.
    s.frame = makeShadingFrame(ns, tri.v1 - tri.v0);
    s.woLocal = toLocal(s.frame, wo);
    // The coat's normal in that frame, for the layered BSDF (bsdf.h).
    if (coatNormal) s.material = gltfWithCoatNormal(s.material, toLocal(s.frame, coatNs));
  }
#endif
  return s;
}

// ---- Choosing an emitter ------------------------------------------------------------------
// Light sampling chooses its emitter from the alias table (by power or uniformly, as the
// renderer's --light-sampler asks) or, where the scene has a light BVH, from the shading point
// p and the normal n it weighs, as pbrt-v4's BVHLightSampler does: one of the U unbounded
// emitters (distant and infinite lights) with probability U / (U + 1), shared equally, else
// down the tree, each step by the two children's importance (light_bvh.h).

struct EmitterChoice {
  Emitter emitter;  // emitter.triangle kNoEmitter: no light can reach the point
  float pmf;        // the probability of the choice
};

PT_INLINE bool lightBvhOn(PT_SCENE_PARAM_ONLY) {
  return PT_HAS_LIGHT_BVH && PT_PARAMS.lightBvhNodes > 0u;
}

// The normal the light BVH weighs at s: its shading normal; none at a point of a medium.
PT_INLINE vec3 lightChoiceNormal(PT_IN(SurfacePoint) s) {
  return (PT_HAS_MEDIA && s.scatter == kScatterPhase) ? vec3(0.0f) : s.ns;
}

// The probability that the light BVH's choice is an unbounded emitter.
PT_INLINE float unboundedShare(PT_SCENE_PARAM_ONLY) {
  return float(PT_PARAMS.unboundedEmitters) / float(PT_PARAMS.unboundedEmitters + 1u);
}

// The weights of a node's two children at p (first, second): their importance, or where their
// bounds differ in power alone, their power (the same ratio, without evaluating it).
PT_INLINE vec2 childWeights(PT_IN(LightBvhNode) node, PT_IN(LightBvhNode) first,
                            PT_IN(LightBvhNode) second, vec3 p, vec3 n) {
  if ((node.flags & kLightBvhSameBounds) != 0u) return vec2(first.phi, second.phi);
  return vec2(lightBoundsImportance(first, p, n), lightBoundsImportance(second, p, n));
}

PT_INLINE EmitterChoice chooseEmitter(PT_SCENE_PARAM vec3 p, vec3 n, vec2 u) {
  if (lightBvhOn(PT_SCENE_ONLY)) {
    Emitter none = Emitter(kNoEmitter, 0.0f, 0.0f, 0u);
    float pInfinite = unboundedShare(PT_SCENE_ONLY);
    if (u.x < pInfinite) {
      uint count = PT_PARAMS.unboundedEmitters;
      uint k = min(uint(u.x / pInfinite * float(count)), count - 1u);
      Emitter e = loadEmitter(PT_SCENE_ARG loadUnboundedEmitter(PT_SCENE_ARG k));
      return EmitterChoice(e, e.pmf);
    }
    float x = min((u.x - pInfinite) / (1.0f - pInfinite), 0.99999994f);
    float pmf = 1.0f - pInfinite;
    uint at = 0u;
    LightBvhNode node = loadLightBvhNode(PT_SCENE_ARG 0u);
    while ((node.flags & kLightBvhLeaf) == 0u) {
      PT_LOOP_TICK();
      LightBvhNode first = loadLightBvhNode(PT_SCENE_ARG at + 1u);
      LightBvhNode second = loadLightBvhNode(PT_SCENE_ARG node.child);
      vec2 c = childWeights(node, first, second, p, n);
      if (c.x == 0.0f && c.y == 0.0f) return EmitterChoice(none, 0.0f);
      float stepPmf;
      bool takeSecond = chooseSecondChild(c.x, c.y, x, stepPmf);
      pmf *= stepPmf;
      at = takeSecond ? node.child : at + 1u;
      node = takeSecond ? second : first;
    }
    // A tree of one light: its importance is tested here.
    if (at == 0u && !(lightBoundsImportance(node, p, n) > 0.0f)) return EmitterChoice(none, 0.0f);
    return EmitterChoice(loadEmitter(PT_SCENE_ARG node.child), pmf);
  }
  uint slot = aliasTableSlot(u.x, PT_PARAMS.emitterCount);
  Emitter e = loadEmitter(PT_SCENE_ARG aliasTablePick(slot, loadEmitter(PT_SCENE_ARG slot), u.y));
  return EmitterChoice(e, e.pmf);
}

// The probability that chooseEmitter from p and n chooses emitter `index` (its entry e): up
// the tree from the emitter's leaf, the share of each node against its sibling.
PT_INLINE float emitterChoicePmf(PT_SCENE_PARAM uint index, PT_IN(Emitter) e, vec3 p, vec3 n) {
  if (!lightBvhOn(PT_SCENE_ONLY)) return e.pmf;
  uint at = loadEmitterLeaf(PT_SCENE_ARG index);
  if (at == kNoEmitter) return e.pmf;  // an unbounded emitter
  LightBvhNode node = loadLightBvhNode(PT_SCENE_ARG at);
  float share = 1.0f - unboundedShare(PT_SCENE_ONLY);
  if (at == 0u) return lightBoundsImportance(node, p, n) > 0.0f ? share : 0.0f;
  float product = 1.0f;
  while (at != 0u) {
    PT_LOOP_TICK();
    LightBvhNode parent = loadLightBvhNode(PT_SCENE_ARG node.parent);
    bool second = parent.child == at;
    LightBvhNode sibling = loadLightBvhNode(PT_SCENE_ARG second ? node.parent + 1u : parent.child);
    vec2 c = childWeights(parent, second ? sibling : node, second ? node : sibling, p, n);
    float mine = second ? c.y : c.x;
    if (!(mine > 0.0f)) return 0.0f;
    product *= mine / (c.x + c.y);
    at = node.parent;
    node = parent;
  }
  return share * product;
}

// ---- Emission found by a ray -------------------------------------------------------------

// The density with which light sampling from `from` would have chosen the point of emissive
// triangle tri (shading point s, at distance t from `from`, seen at cosine cosEmit), per solid
// angle: uniform on the triangle, or the cone of a sphere light. The emitter's choice is the
// one made at the path's last vertex (path.prevP, prevN).
PT_INLINE float emitterPdfFound(PT_SCENE_PARAM PT_IN(Triangle) tri, PT_IN(SurfacePoint) s,
                                float cosEmit, float t, vec3 from, PT_IN(PathState) path) {
  Emitter emitter = loadEmitter(PT_SCENE_ARG tri.emitter);
  float pmf = emitterChoicePmf(PT_SCENE_ARG tri.emitter, emitter, path.prevP, path.prevN);
  float lightPdf = pmf * t * t / (cosEmit * s.area);
#ifndef PT_NO_BSDF_MATERIALS
  // A sphere light's triangle: light sampling draws its cone (seen from the ray's origin).
  if (PT_HAS_SPHERE_LIGHTS && (emitter.triangle & kEmitterLight) != 0u) {
    lightPdf =
        pmf * sphereLightPdf(loadLight(PT_SCENE_ARG emitter.triangle & ~kEmitterLight), from);
  }
#endif
  return lightPdf;
}

// The radiance that material m of triangle tri emits at the point of barycentrics b (the
// weights of v1 and v2): its own emission, or its emission texture's value there.
PT_INLINE vec3 emissionAt(PT_SCENE_PARAM Material m, Triangle tri, vec2 b) {
  vec3 Le = m.emission;
#ifndef PT_NO_BSDF_MATERIALS
  if (PT_HAS_TEXTURES && PT_TEXTURE_USES(kTextureUsesEmission) && PT_PARAMS.texturesPresent != 0u) {
    uint texture = materialTexturesAt(PT_SCENE_TEXTURES tri.material).emission;
    if (texture != kNoTexture) {
      vec2 uv =
          interpolatedUV(uvsAt(PT_SCENE_TEXTURES tri.primitive), vec3(1.0f - b.x - b.y, b.x, b.y));
      Le = max(evalTexture(PT_SCENE_TEXTURES texture, uv), vec3(0.0f));
    }
  }
#endif
  return Le;
}

// The cosine at which the surface at s emits towards the ray that found it: on its geometric
// normal's side, or on both; not above zero where it does not.
PT_INLINE float emissionCosine(PT_IN(SurfacePoint) s) {
  return (PT_HAS_TWO_SIDED_EMITTERS && s.material.twoSided != 0u) ? abs(s.cosOut) : s.cosOut;
}

// Adds the emission of the surface the path's ray found (triangle tri, `t` along the unit ray
// from rayOrigin) where it emits towards the ray. At full weight after a specular bounce (or
// from the camera); else weighed against the chance that light sampling had produced the same
// point (MIS), or not counted (light sampling alone).
PT_INLINE void addEmissionFound(PT_SCENE_PARAM PT_INOUT(PathState) path, PT_IN(Triangle) tri,
                                PT_IN(SurfacePoint) s, float t, vec3 rayOrigin) {
  float cosEmit = emissionCosine(s);
  if (tri.emitter == kNoEmitter || !(cosEmit > 0.0f)) return;
  vec3 Le = s.material.emission;
  if (path.specularBounce) {
    path.L += path.beta * Le;
  } else if (bsdfEmissionOn(PT_SCENE_ONLY)) {
    float weight = 1.0f;
    if (misOn(PT_SCENE_ONLY)) {
      weight = powerHeuristic(path.bsdfPdf,
                              emitterPdfFound(PT_SCENE_ARG tri, s, cosEmit, t, rayOrigin, path));
    }
    path.L += path.beta * weight * Le;
  }
}

#ifndef PT_NO_BSDF_MATERIALS
// The infinite light's radiance along `direction` (an image's by direction) and light
// sampling's density of that direction (the light's pmf included).
struct EnvironmentFound {
  vec3 Le;
  float lightPdf;
};
PT_INLINE EnvironmentFound environmentFound(PT_SCENE_PARAM vec3 direction) {
  EnvironmentFound e = EnvironmentFound(PT_PARAMS.environment, PT_PARAMS.environmentPdf);
  if (PT_HAS_ENVIRONMENT_IMAGE && PT_PARAMS.environmentWidth != 0u) {
    // The image: the direction's texel, and its density times the light's pmf.
    EnvironmentLookup l = environmentLookup(environmentMap(PT_SCENE_ONLY), direction);
    e.Le = l.Le;
    e.lightPdf = PT_PARAMS.environmentPdf * l.pdf;
  }
  return e;
}
#endif

// Adds the infinite light's radiance seen by a ray that leaves the scene along `direction`
// (none without one), weighed as emission found on a surface is.
PT_INLINE void addEnvironmentFound(PT_SCENE_PARAM PT_INOUT(PathState) path, vec3 direction) {
#ifndef PT_NO_BSDF_MATERIALS
  if (!PT_HAS_ENVIRONMENT || PT_PARAMS.environmentEmitter == kNoEmitter) return;
  EnvironmentFound e = environmentFound(PT_SCENE_ARG direction);
  if (path.specularBounce) {
    path.L += path.beta * e.Le;
  } else if (bsdfEmissionOn(PT_SCENE_ONLY)) {
    float weight = 1.0f;
    if (misOn(PT_SCENE_ONLY)) weight = powerHeuristic(path.bsdfPdf, e.lightPdf);
    path.L += path.beta * weight * e.Le;
  }
#endif
}

// ---- Light sampling (next-event estimation) -----------------------------------------------

// Whether light sampling is done at the vertex: the strategy asks for it, and the surface has
// a lobe it can find (not a mirror, not black, not only delta lobes).
PT_INLINE bool samplesLightAt(PT_SCENE_PARAM PT_IN(SurfacePoint) s) {
  if (!neeOn(PT_SCENE_ONLY) || s.scatter == kScatterMirror) return false;
#ifndef PT_NO_BSDF_MATERIALS
  if (s.scatter == kScatterBsdf) return bsdfHasNonSpecular(s.material);
#endif
  return s.material.reflectance != vec3(0.0f);
}

// A light sample seen from a vertex, before its shadow ray is traced. Its contribution, once
// the ray from `from` to `to` (t in [0, 1)) is found clear, is
//   beta * f * Li * (scale * weight / lightPdf)
// with the MIS weight from lightSampleContribution. f is the BSDF's value times |cos| towards
// the light, but for a Lambertian surface lit by an emissive triangle, whose cosine is `scale`
// (the products in the order the renderer's images were made with); scale is 1 otherwise.
struct LightSample {
  bool found;      // false: nothing to trace (the light faces away, or no BSDF value)
  vec3 from;       // the shadow ray's origin, offset from the surface
  vec3 to;         // its end: offset from the light's point, or beyond the scene
  vec3 f;          // see above
  float scale;     // see above
  vec3 Li;         // radiance arriving (a delta light's weight)
  float lightPdf;  // the probability of the emitter times the density of the sample
  float cosTheta;  // Lambertian: dot(n, wi), for the BSDF's density
  vec3 wiLocal;    // bsdf.h's materials: wi in the shading frame, for the BSDF's density
  bool delta;      // a point, spot or distant light: no MIS (BSDF sampling never finds it)
  uint emitter;    // Emitter::triangle of the emitter chosen (for --debug-pixel)
};

PT_INLINE LightSample noLightSample() {
  return LightSample(false, vec3(0.0f), vec3(0.0f), vec3(0.0f), 1.0f, vec3(0.0f), 0.0f, 0.0f,
                     vec3(0.0f), false, 0u);
}

// The side of the geometric surface a ray towards w leaves from.
PT_INLINE vec3 geometricSide(PT_IN(SurfacePoint) s, vec3 w) {
  return dot(s.ng, w) > 0.0f ? s.ng : -s.ng;
}

#ifndef PT_NO_BSDF_MATERIALS
// f * |cos| of one of bsdf.h's materials at vertex s towards wiLocal (its shading frame), with
// the coated material's estimate drawn from the event's kStreamEval stream.
PT_INLINE vec3 bsdfFCos(PT_SCENE_PARAM PT_IN(SurfacePoint) s, VertexKey key, vec3 wiLocal) {
  return bsdfF(s.material, s.woLocal, wiLocal,
               makeRandomStream(key.pixel, key.sampleIndex, key.dim, PT_PARAMS.seed, kStreamEval)) *
         absCosTheta(wiLocal);
}
#endif

// Samples the light from vertex s (pbrt-v4's SampleLd): an emitter chosen with uChoose, and with
// uLight a uniform point on its triangle or a sample of the analytic light (lights.h,
// environment.h) it names; the BSDF's value towards it (at a point of a medium, the phase
// function's), and the shadow ray's ends. The shadow ray leaves along n from a Lambertian surface
// without shading normals, else from the side of the geometric surface the light is on (a medium's
// point has no offset).
PT_INLINE LightSample sampleLightAt(PT_SCENE_PARAM PT_IN(SurfacePoint) s, VertexKey key,
                                    vec2 uChoose, vec2 uLight) {
  LightSample ls = noLightSample();
  EmitterChoice choice = chooseEmitter(PT_SCENE_ARG s.p, lightChoiceNormal(s), uChoose);
  Emitter emitter = choice.emitter;
  if (emitter.triangle == kNoEmitter) return ls;
  ls.emitter = emitter.triangle;
  bool lambertian = s.scatter < kScatterBsdf;  // mirrors sample no light
  vec3 wi;
  bool bsdfTowardsLight = false;  // bsdf.h's material: its value towards the light decides
  vec3 to = vec3(0.0f);
  vec3 Li = vec3(0.0f);
  float lightPdf = 0.0f;
  bool delta = false;
#ifndef PT_NO_BSDF_MATERIALS
  if (PT_HAS_ANALYTIC_LIGHTS && (emitter.triangle & kEmitterLight) != 0u) {
    // An analytic light: the environment image's sample for an infinite light that has one,
    // lights.h's otherwise.
    Light light = loadLight(PT_SCENE_ARG emitter.triangle & ~kEmitterLight);
    AnalyticLightSample analytic;
    if (PT_HAS_ENVIRONMENT_IMAGE && light.type == kLightInfinite &&
        PT_PARAMS.environmentWidth != 0u) {
      analytic =
          sampleEnvironmentLight(environmentMap(PT_SCENE_ONLY), s.p, uLight, PT_PARAMS.sceneRadius);
    } else {
      analytic = sampleAnalyticLight(light, s.p, uLight, PT_PARAMS.sceneRadius);
    }
    wi = analytic.wi;
    if (lambertian) {
      ls.cosTheta = dot(s.n, wi);
      if (!(ls.cosTheta > 0.0f) || !(maxComponent(analytic.Li) > 0.0f)) return ls;
      ls.f = s.material.reflectance * kInvPi * ls.cosTheta;
    } else if (PT_HAS_MEDIA && s.scatter == kScatterPhase) {
      if (!(maxComponent(analytic.Li) > 0.0f)) return ls;
      ls.f = vec3(henyeyGreenstein(dot(s.wo, wi), s.material.g));
    } else {
      if (!(maxComponent(analytic.Li) > 0.0f)) return ls;
      bsdfTowardsLight = true;
    }
    to = analytic.target;
    Li = analytic.Li;
    lightPdf = choice.pmf * analytic.pdf;
    delta = analytic.delta;
  } else
#endif
  {
    // An emissive triangle: a uniform point on it.
    Triangle light = loadTriangle(PT_SCENE_ARG emitter.triangle);
    TriangleShading lightShading = triangleShadingAt(PT_SCENE_ARG emitter.triangle, light);
    Material lightMaterial = loadMaterial(PT_SCENE_ARG light.material);
    vec2 b = sampleTriangleBarycentrics(uLight);
    vec3 point = (1.0f - b.x - b.y) * light.v0 + b.x * light.v1 + b.y * light.v2;
    vec3 lightNormal = lightShading.normal;  // it emits on this side
    vec3 toLight = point - s.p;
    float dist2 = dot(toLight, toLight);
    wi = toLight / sqrt(dist2);
    float cosLight = -dot(lightNormal, wi);  // > 0: the point sees the emitting side
    // A two-sided light seen from its back: the side the point sees is the emitting one, its
    // normal turned towards the point (for the cosine and the shadow ray's offset).
    if (PT_HAS_TWO_SIDED_EMITTERS && lightMaterial.twoSided != 0u && cosLight < 0.0f) {
      cosLight = -cosLight;
      lightNormal = -lightNormal;
    }
    if (lambertian) {
      ls.cosTheta = dot(s.n, wi);
      if (!(cosLight > 0.0f && ls.cosTheta > 0.0f)) return ls;
      ls.f = s.material.reflectance * kInvPi;
      ls.scale = ls.cosTheta;
    } else if (PT_HAS_MEDIA && s.scatter == kScatterPhase) {
      if (!(cosLight > 0.0f)) return ls;
      ls.f = vec3(henyeyGreenstein(dot(s.wo, wi), s.material.g));
    } else {
#ifndef PT_NO_BSDF_MATERIALS
      if (!(cosLight > 0.0f)) return ls;
      bsdfTowardsLight = true;
#endif
    }
    to = offsetRayOrigin(point, lightNormal, lightShading.magnitude);
    Li = emissionAt(PT_SCENE_ARG lightMaterial, light, b);
    lightPdf = choice.pmf * dist2 / (cosLight * lightShading.area);
  }
#ifndef PT_NO_BSDF_MATERIALS
  // One call of the BSDF for both kinds of light: a shader inlines every call, and lavapipe's
  // time to compile grows faster than the inlined code.
  if (bsdfTowardsLight) {
    ls.wiLocal = toLocal(s.frame, wi);
    ls.f = bsdfFCos(PT_SCENE_ARG s, key, ls.wiLocal);
    if (!(maxComponent(ls.f) > 0.0f)) return ls;
  }
#endif
  ls.to = to;
  ls.Li = Li;
  ls.lightPdf = lightPdf;
  ls.delta = delta;
  vec3 side = (lambertian && !s.shadingNormals) ? s.n : geometricSide(s, wi);
  ls.from = offsetRayOrigin(s.p, side, s.magnitude);
  ls.found = true;
  return ls;
}

// BSDF sampling's density of a light sample's direction (for MIS).
PT_INLINE float lightSampleBsdfPdf(PT_SCENE_PARAM PT_IN(SurfacePoint) s, VertexKey key,
                                   PT_IN(LightSample) ls) {
  float bsdfDensity = ls.cosTheta * kInvPi;
#ifndef PT_NO_BSDF_MATERIALS
  if (s.scatter == kScatterBsdf) {
    bsdfDensity = bsdfPdf(
        s.material, s.woLocal, ls.wiLocal,
        makeRandomStream(key.pixel, key.sampleIndex, key.dim, PT_PARAMS.seed, kStreamLightPdf));
  }
#endif
  return bsdfDensity;
}

// The contribution of a light sample whose shadow ray was found clear, with the path's
// throughput beta, weighed by the power heuristic against BSDF sampling's density of the same
// direction (MIS; not for delta lights); the weight in `weight`.
PT_INLINE vec3 lightSampleContribution(PT_SCENE_PARAM PT_IN(SurfacePoint) s, VertexKey key,
                                       PT_IN(LightSample) ls, vec3 beta, PT_OUT(float) weight) {
  weight = 1.0f;
  if (misOn(PT_SCENE_ONLY) && !ls.delta) {
    weight = powerHeuristic(ls.lightPdf, lightSampleBsdfPdf(PT_SCENE_ARG s, key, ls));
  }
  return beta * ls.f * ls.Li * (ls.scale * weight / ls.lightPdf);
}

// ---- BSDF sampling and Russian roulette ---------------------------------------------------

// The path's continuation from a Lambertian vertex s in a cosine-weighted direction of density
// pdf (so f * cos / pdf = reflectance); false for a direction in the tangent plane, which
// contributes nothing. (The CPU's lanes draw such directions for all lanes at once.)
PT_INLINE bool continueLambertian(PT_IN(SurfacePoint) s, PT_INOUT(PathState) path, float pdf) {
  path.prevP = s.p;
  path.prevN = s.ns;
  path.bsdfPdf = pdf;
  path.rd.present = false;
  if (!(pdf > 0.0f)) return false;
  path.beta *= s.material.reflectance;
  path.specularBounce = false;
  return true;
}

// Samples the BSDF at vertex s for the path's next direction wi (uLobe: the choice between
// lobes, uBsdf: the direction) and updates the path's throughput, the sample's density (for
// MIS at the next vertex), whether it was specular, and etaScale. False: no direction, the
// path ends.
PT_INLINE bool sampleBsdfAt(PT_SCENE_PARAM PT_IN(SurfacePoint) s, VertexKey key,
                            PT_INOUT(PathState) path, float uLobe, vec2 uBsdf, PT_OUT(vec3) wi) {
  if (s.scatter == kScatterMirror) {
    // Ideal reflection: the BSDF is a delta, f * cos / pdf = reflectance.
    vec3 d = -s.wo;
    wi = d - 2.0f * dot(d, s.n) * s.n;
    path.beta *= s.material.reflectance;
    path.specularBounce = true;
    if (footprintsOn(PT_SCENE_ONLY)) {
      path.rd = specularRayDifferential(path.rd, s.p, s.dpdx, s.dpdy, s.n, s.dndx, s.dndy, s.wo, wi,
                                        true, 1.0f);
    }
    return true;
  }
#ifndef PT_NO_BSDF_MATERIALS
  if (s.scatter == kScatterBsdf) {
    path.prevP = s.p;
    path.prevN = s.ns;
    BsdfSample bs = bsdfSample(
        s.material, s.woLocal, uLobe, uBsdf,
        makeRandomStream(key.pixel, key.sampleIndex, key.dim, PT_PARAMS.seed, kStreamSample));
    if (bs.flags == 0u) return false;
    wi = fromLocal(s.frame, bs.wi);
    path.beta *= bs.f * (absCosTheta(bs.wi) / bs.pdf);
    path.specularBounce = (bs.flags & kBsdfSpecular) != 0u;
    path.bsdfPdf = bs.pdfIsProportional
                       ? bsdfPdf(s.material, s.woLocal, bs.wi,
                                 makeRandomStream(key.pixel, key.sampleIndex, key.dim,
                                                  PT_PARAMS.seed, kStreamSamplePdf))
                       : bs.pdf;
    if ((bs.flags & kBsdfTransmission) != 0u) path.etaScale *= bs.eta * bs.eta;
    if (footprintsOn(PT_SCENE_ONLY)) {
      // Differentials through a specular reflection or transmission, none after the rest
      // (pbrt-v4's SpawnRay).
      uint kind = bs.flags & (kBsdfSpecular | kBsdfReflection | kBsdfTransmission);
      path.rd =
          (kind == (kBsdfSpecular | kBsdfReflection) || kind == (kBsdfSpecular | kBsdfTransmission))
              ? specularRayDifferential(path.rd, s.p, s.dpdx, s.dpdy, s.ns, s.dndx, s.dndy, s.wo,
                                        wi, kind == (kBsdfSpecular | kBsdfReflection), bs.eta)
              : noRayDifferential();
    }
    return true;
  }
#endif
  // Lambertian: cosine-weighted about n.
  wi = localToWorld(sampleCosineHemisphere(uBsdf), s.n);
  return continueLambertian(s, path, dot(wi, s.n) * kInvPi);
}

// Russian roulette after `depth` scattering events, with uniform number u: false when the path
// is terminated; the survivors' throughput is scaled up (unbiased). The probability follows
// beta times etaScale (pbrt-v4's), which refractions do not inflate.
PT_INLINE bool survivesRoulette(PT_SCENE_PARAM PT_INOUT(PathState) path, uint depth, float u) {
  if (!rouletteOn(PT_SCENE_ONLY) || depth < PT_PARAMS.rrStartDepth) return true;
  float q =
      max(0.0f, 1.0f - maxComponent(PT_HAS_BSDF_MATERIALS ? path.beta * path.etaScale : path.beta));
  if (u < q) return false;
  path.beta /= 1.0f - q;
  return true;
}

// Where the path's next ray, towards wi, starts: offset from the surface on the side it goes
// to (along n from a Lambertian or mirror surface without shading normals, which wi leaves on
// n's side).
PT_INLINE vec3 nextRayOrigin(PT_IN(SurfacePoint) s, vec3 wi) {
  vec3 side = (s.scatter != kScatterBsdf && !s.shadingNormals) ? s.n : geometricSide(s, wi);
  return offsetRayOrigin(s.p, side, s.magnitude);
}

#ifdef __cplusplus
}  // namespace pt
#endif

#endif  // PT_PATH_VERTEX_H
