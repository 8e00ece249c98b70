// The vertices of bidirectional path tracing (Veach 1997; pbrt-v4's BDPT Vertex, book 3rd edition
// 16.3), written once for the CPU reference and the shader: the vertex record of a camera or
// light subpath, its BSDF's value and densities towards other vertices, the emission a light
// vertex leaves, the densities with which each side would have sampled it (pdfFwd, pdfRev, per
// unit area, or per solid angle at infinity), the first vertex of a light subpath, and one step
// of the random walk that extends a subpath. The connections and their MIS weights are
// bdpt_connect.h's; how rays are traced and how the film is written are each backend's.
//
// In pbrt-v4's names (its Vertex, GenerateLightSubpath, RandomWalk), with these differences:
// RGB instead of sampled wavelengths; no participating media; the light is chosen from the
// emitter alias table (by power, as pbrt-v4's BDPT chooses, or uniformly where the scene asks
// for that light sampler); a spot light's emission directions are uniform in its outer cone
// (pbrt-v4 samples its smoothstep falloff); an infinite light's vertex stores the direction
// light travels (pbrt-v4 places it a unit along the ray). Lambertian and mirror surfaces are
// path_vertex.h's two-sided ones. A sphere light is an area light, as pbrt-v4's BDPT takes it:
// its points are drawn on the analytic sphere (uniform by area, outward normals) while rays
// find the triangles that stand for it, as the path tracer's light sampling already does.
#ifndef PT_BDPT_VERTEX_H
#define PT_BDPT_VERTEX_H

#include "bdpt_camera.h"
#include "bsdf.h"
#include "environment.h"
#include "lights.h"
#include "path_vertex.h"
#include "sampling.h"
#include "shared_types.h"

#ifdef __cplusplus
namespace pt {
#endif

// The most scattering events a path may have (pbrt-v4's maxdepth): subpaths are arrays of this
// bound. A camera subpath has up to maxDepth + 2 vertices (the camera's, and one found past the
// last scattering event), a light subpath up to maxDepth + 1.
PT_CONST uint kBdptMaxDepth = 32u;
#ifdef PT_BDPT_MAX_VERTICES
// The shader's arrays take the scene's maxdepth + 2 vertices (the host defines it): a
// scene's subpaths never need more, and each invocation holds two of them.
PT_CONST uint kBdptMaxVertices = PT_BDPT_MAX_VERTICES;
#else
PT_CONST uint kBdptMaxVertices = kBdptMaxDepth + 2u;
#endif

PT_CONST uint kBdptCamera = 0u;   // the camera's lens point (the pinhole)
PT_CONST uint kBdptLight = 1u;    // a light's point, or a direction at infinity
PT_CONST uint kBdptSurface = 2u;  // a surface hit, which may emit (an area light)

// What a light vertex lies on: the analytic lights' kLight* (point, spot, distant, infinite,
// sphere), or an emissive triangle.
PT_CONST uint kBdptLightTriangle = kLightTypeCount;

// The first dimension of a light subpath's random numbers (sampling.h): vertex j draws
// kDimsPerBounce dimensions from kDimLightSubpath + kDimsPerBounce * j, as a camera subpath's
// scattering events do from kDimFirstBounce. Far above any camera subpath's.
PT_CONST uint kDimLightSubpath = 0x40000000u;

struct BdptVertex {
  SurfacePoint s;  // kBdptSurface: the shading point (material, normals, frame, wo); a light
                   // vertex on a triangle or a sphere: the light's material, offset scale and
                   // area
  vec3 p;          // its position (an infinite light's: where its ray starts)
  uint type;       // kBdptCamera, kBdptLight, kBdptSurface
  vec3 ng;         // unit geometric normal on a surface (a triangle light's emitting side, a
                   // sphere light's outward normal); zero elsewhere (camera, point, spot, and
                   // lights at infinity)
  uint lightType;  // kBdptLight: kLight* or kBdptLightTriangle
  vec3 ns;         // shading normal (ng without one)
  uint emitter;    // the Emitter it emits by (a light vertex, an emissive surface), or none
  vec3 beta;       // the subpath's throughput up to here
  float pdfFwd;    // density of this vertex sampled from its subpath's side
  vec3 w;          // a light at infinity: the unit direction its light travels; the camera:
                   // the lens point's offset from the camera's position
  float pdfRev;    // density of this vertex sampled from the other side
  VertexKey key;   // its random numbers' coordinates (the BSDF's random streams)
  bool delta;      // the BSDF sample taken here was specular
};

// A subpath: its vertices, camera or light first.
struct BdptPath {
  BdptVertex v[kBdptMaxVertices];
  uint count;
};

// The two subpaths of a pixel sample, as the functions that read them both take them: const
// references in C++; in GLSL, which would copy arrays passed by value at every call, the
// shader's globals lightPath and cameraPath (shaders/bdpt.glsl).
#ifdef __cplusplus
#define PT_BDPT_PATHS_PARAM const BdptPath &lightPath, const BdptPath &cameraPath,
#define PT_BDPT_PATHS_ARG lightPath, cameraPath,
#else
#define PT_BDPT_PATHS_PARAM
#define PT_BDPT_PATHS_ARG
#endif

// The random-number dimension of camera subpath vertex k >= 1: the path tracer's scattering
// event k - 1, so that strategy (1, t) draws its light sample with the numbers the path
// tracer's light sample at the same vertex draws. Light subpath vertex j: kDimLightSubpath
// onwards.
PT_INLINE uint bdptCameraDim(uint k) {
  return kDimFirstBounce + kDimsPerBounce * (k - 1u);
}
PT_INLINE uint bdptLightDim(uint j) {
  return kDimLightSubpath + kDimsPerBounce * j;
}

PT_INLINE bool bdptOnSurface(PT_IN(BdptVertex) v) {
  return v.ng != vec3(0.0f);
}
PT_INLINE bool bdptIsInfiniteLight(PT_IN(BdptVertex) v) {
  return v.type == kBdptLight && (v.lightType == kLightInfinite || v.lightType == kLightDistant);
}
// A light of zero extent in position or direction: no ray finds it.
PT_INLINE bool bdptIsDeltaLight(PT_IN(BdptVertex) v) {
  return v.type == kBdptLight &&
         (v.lightType == kLightPoint || v.lightType == kLightSpot || v.lightType == kLightDistant);
}
PT_INLINE bool bdptIsLight(PT_IN(BdptVertex) v) {
  return v.type == kBdptLight || (v.type == kBdptSurface && v.emitter != kNoEmitter);
}
// Whether a connection can end at v: not at a surface of delta lobes only, nor at a distant
// light.
PT_INLINE bool bdptIsConnectible(PT_IN(BdptVertex) v) {
  if (v.type == kBdptLight) return v.lightType != kLightDistant;
  if (v.type == kBdptCamera) return true;
  if (v.s.scatter == kScatterMirror) return false;
  if (v.s.scatter == kScatterBsdf) return bsdfHasNonSpecular(v.s.material);
  return true;
}

// Unit direction from vertex a towards vertex b (zero where they coincide); towards or from a
// light at infinity, along its direction.
PT_INLINE vec3 bdptDirection(PT_IN(BdptVertex) a, PT_IN(BdptVertex) b) {
  if (bdptIsInfiniteLight(b)) return -b.w;
  if (bdptIsInfiniteLight(a)) return a.w;
  vec3 d = b.p - a.p;
  float len2 = dot(d, d);
  return len2 > 0.0f ? d / sqrt(len2) : vec3(0.0f);
}

// A density `pdf` per unit solid angle at vertex `from` as a density per unit area at `next`
// (pbrt-v4's ConvertDensity); kept per solid angle where next is at infinity.
PT_INLINE float bdptConvertDensity(float pdf, PT_IN(BdptVertex) from, PT_IN(BdptVertex) next) {
  if (bdptIsInfiniteLight(next)) return pdf;
  vec3 d = next.p - from.p;
  float len2 = dot(d, d);
  if (!(len2 > 0.0f)) return 0.0f;
  if (bdptOnSurface(next)) pdf *= abs(dot(next.ng, d / sqrt(len2)));
  return pdf / len2;
}

// ---- The vertices' records ------------------------------------------------------------------

PT_INLINE BdptVertex bdptEmptyVertex(uint type, vec3 p, vec3 beta, VertexKey key) {
  BdptVertex v;
  v.type = type;
  v.p = p;
  v.ng = vec3(0.0f);
  v.ns = vec3(0.0f);
  v.lightType = 0u;
  v.emitter = kNoEmitter;
  v.beta = beta;
  v.pdfFwd = 0.0f;
  v.pdfRev = 0.0f;
  v.w = vec3(0.0f);
  v.key = key;
  v.delta = false;
  v.s.scatter = kScatterLambertian;
  v.s.magnitude = 0.0f;
  v.s.area = 0.0f;
  v.s.shadingNormals = false;
  return v;
}

// The camera's vertex: its lens point (the pinhole), lensOffset from its position.
PT_INLINE BdptVertex bdptCameraVertex(PT_IN(Camera) cam, vec3 lensOffset, vec3 beta,
                                      VertexKey key) {
  BdptVertex v = bdptEmptyVertex(kBdptCamera, cam.position + lensOffset, beta, key);
  v.w = lensOffset;
  return v;
}

// The vertex a subpath's ray finds at shading point s (the triangle's emitter `emitter`), with
// throughput beta, sampled from prev with solid-angle density pdf.
PT_INLINE BdptVertex bdptSurfaceVertex(PT_IN(SurfacePoint) s, uint emitter, VertexKey key,
                                       vec3 beta, float pdf, PT_IN(BdptVertex) prev) {
  BdptVertex v = bdptEmptyVertex(kBdptSurface, s.p, beta, key);
  v.s = s;
  v.ng = s.ng;
  v.ns = s.ns;
  v.emitter = emitter;
  v.pdfFwd = bdptConvertDensity(pdf, prev, v);
  return v;
}

// The infinite light that a camera subpath's ray leaving the scene along `direction` sees, with
// throughput beta and the solid-angle density pdf of that direction.
PT_INLINE BdptVertex bdptEnvironmentVertex(PT_SCENE_PARAM vec3 origin, vec3 direction, vec3 beta,
                                           float pdf, VertexKey key) {
  BdptVertex v = bdptEmptyVertex(kBdptLight, origin + direction, beta, key);
  v.lightType = kLightInfinite;
  v.w = -direction;
  v.emitter = PT_PARAMS.environmentEmitter;
  v.pdfFwd = pdf;
  return v;
}

// A point on emissive triangle `emitter` (Emitter index) at position p (barycentrics b, the
// weights of v1 and v2), for a light subpath or a light sample.
PT_INLINE BdptVertex bdptTriangleLightVertex(PT_SCENE_PARAM uint emitter, vec3 p, vec2 b, vec3 beta,
                                             VertexKey key) {
  Emitter e = loadEmitter(PT_SCENE_ARG emitter);
  Triangle tri = loadTriangle(PT_SCENE_ARG e.triangle);
  TriangleShading shading = triangleShadingAt(PT_SCENE_ARG e.triangle, tri);
  BdptVertex v = bdptEmptyVertex(kBdptLight, p, beta, key);
  v.lightType = kBdptLightTriangle;
  v.emitter = emitter;
  v.ng = shading.normal;
  v.ns = shading.normal;
  v.s.material = loadMaterial(PT_SCENE_ARG tri.material);
  v.s.material.emission = emissionAt(PT_SCENE_ARG v.s.material, tri, b);
  v.s.magnitude = shading.magnitude;
  v.s.area = shading.area;
  return v;
}

// The area of sphere light `light`: its points' density by area is the inverse.
PT_INLINE float bdptSphereLightArea(Light light) {
  return 4.0f * kPi * light.radius * light.radius;
}

// The point of sphere light `light` (Emitter index `emitter`) with unit outward normal n, for a
// light subpath or a light sample: an area emitter on the analytic sphere (its material, the
// triangles', emits its radiance outwards), whose points have the density 1 / area by area.
PT_INLINE BdptVertex bdptSphereLightVertex(PT_SCENE_PARAM uint emitter, Light light, vec3 n,
                                           vec3 beta, VertexKey key) {
  BdptVertex v = bdptEmptyVertex(kBdptLight, light.position + light.radius * n, beta, key);
  v.lightType = kLightSphere;
  v.emitter = emitter;
  v.ng = n;
  v.ns = n;
  v.s.material = loadMaterial(PT_SCENE_ARG light.material);
  v.s.material.emission = light.radiance;
  vec3 ap = abs(v.p);
  v.s.magnitude = max(ap.x, max(ap.y, ap.z));
  v.s.area = bdptSphereLightArea(light);
  return v;
}

// ---- What a vertex does to light -------------------------------------------------------------

// Whether a light vertex or emissive surface v emits on both sides.
PT_INLINE bool bdptTwoSided(PT_IN(BdptVertex) v) {
  return PT_HAS_TWO_SIDED_EMITTERS && v.s.material.twoSided != 0u;
}

// The BSDF at shading point s (its random streams at key) from wo to wi (world space; zero for
// a mirror's delta lobe), for radiance (a camera subpath's vertex, a photon map's visible point)
// or importance (a light subpath's, a photon's).
PT_INLINE vec3 surfaceBsdfF(PT_SCENE_PARAM PT_IN(SurfacePoint) s, VertexKey key, vec3 wo, vec3 wi,
                            bool radiance) {
  if (s.scatter == kScatterMirror) return vec3(0.0f);
  if (s.scatter == kScatterBsdf) {
    return bsdfFTransport(
        s.material, toLocal(s.frame, wo), toLocal(s.frame, wi), radiance,
        makeRandomStream(key.pixel, key.sampleIndex, key.dim, PT_PARAMS.seed, kStreamEval));
  }
  // Lambertian about the shading normal, on wo's side of it.
  bool sameSide = dot(wo, s.ns) * dot(wi, s.ns) > 0.0f;
  return sameSide ? s.material.reflectance * kInvPi : vec3(0.0f);
}

// The BSDF at surface vertex v from wo to wi (surfaceBsdfF).
PT_INLINE vec3 bdptBsdfF(PT_SCENE_PARAM PT_IN(BdptVertex) v, vec3 wo, vec3 wi, bool radiance) {
  return surfaceBsdfF(PT_SCENE_ARG v.s, v.key, wo, wi, radiance);
}

// The solid-angle density with which the BSDF at surface vertex v samples wi given wo.
PT_INLINE float bdptBsdfPdf(PT_SCENE_PARAM PT_IN(BdptVertex) v, vec3 wo, vec3 wi) {
  if (v.s.scatter == kScatterMirror) return 0.0f;
  if (v.s.scatter == kScatterBsdf) {
    return bsdfPdf(v.s.material, toLocal(v.s.frame, wo), toLocal(v.s.frame, wi),
                   makeRandomStream(v.key.pixel, v.key.sampleIndex, v.key.dim, PT_PARAMS.seed,
                                    kStreamLightPdf));
  }
  bool sameSide = dot(wo, v.ns) * dot(wi, v.ns) > 0.0f;
  return sameSide ? abs(dot(wi, v.ns)) * kInvPi : 0.0f;
}

// The BSDF at v towards vertex `next`, for its stored wo (pbrt-v4's Vertex::f).
PT_INLINE vec3 bdptF(PT_SCENE_PARAM PT_IN(BdptVertex) v, PT_IN(BdptVertex) next, bool radiance) {
  vec3 wi = bdptDirection(v, next);
  if (wi == vec3(0.0f)) return vec3(0.0f);
  return bdptBsdfF(PT_SCENE_ARG v, v.s.wo, wi, radiance);
}

// The radiance light vertex or emissive surface v sends towards vertex `towards` (pbrt-v4's
// Vertex::Le).
PT_INLINE vec3 bdptLe(PT_SCENE_PARAM PT_IN(BdptVertex) v, PT_IN(BdptVertex) towards) {
  if (!bdptIsLight(v)) return vec3(0.0f);
  vec3 w = bdptDirection(v, towards);
  if (w == vec3(0.0f)) return vec3(0.0f);
  if (v.type == kBdptLight && v.lightType == kLightInfinite) {
    return environmentFound(PT_SCENE_ARG - w).Le;
  }
  if (v.type == kBdptLight && v.lightType != kBdptLightTriangle && v.lightType != kLightSphere) {
    return vec3(0.0f);  // a point or spot light: no ray finds it
  }
  float cosEmit = dot(v.ng, w);
  if (bdptTwoSided(v)) cosEmit = abs(cosEmit);
  return cosEmit > 0.0f ? v.s.material.emission : vec3(0.0f);
}

// The solid-angle density of a spot light's emission directions: uniform in its outer cone.
PT_INLINE float spotEmissionPdf(Light light) {
  return 1.0f / (2.0f * kPi * (1.0f - light.cosFalloffEnd));
}

// The density with which light vertex (or emissive surface) v's emission reaches vertex `next`
// (pbrt-v4's PDFLight): per unit area at next, a light at infinity's over the disk its rays
// start from.
PT_INLINE float bdptPdfLight(PT_SCENE_PARAM PT_IN(BdptVertex) v, PT_IN(BdptVertex) next) {
  vec3 w = bdptDirection(v, next);
  float pdf;
  if (bdptIsInfiniteLight(v)) {
    pdf = 1.0f / (kPi * PT_PARAMS.sceneRadius * PT_PARAMS.sceneRadius);
  } else {
    vec3 d = next.p - v.p;
    float invDist2 = 1.0f / dot(d, d);
    float pdfDir;
    if (bdptOnSurface(v)) {
      // An emissive triangle or a sphere light: cosine-weighted on the emitting side (either
      // side, half each, where it emits on both).
      pdfDir =
          bdptTwoSided(v) ? abs(dot(v.ng, w)) * (0.5f * kInvPi) : max(dot(v.ng, w), 0.0f) * kInvPi;
    } else if (v.lightType == kLightSpot) {
      Light light =
          loadLight(PT_SCENE_ARG loadEmitter(PT_SCENE_ARG v.emitter).triangle & ~kEmitterLight);
      pdfDir = dot(w, light.direction) >= light.cosFalloffEnd ? spotEmissionPdf(light) : 0.0f;
    } else {
      pdfDir = kInv4Pi;  // a point light
    }
    pdf = pdfDir * invDist2;
  }
  if (bdptOnSurface(next)) pdf *= abs(dot(next.ng, w));
  return pdf;
}

// The density with which a light subpath starts at light vertex (or emissive surface) v, seen
// from vertex `next` (pbrt-v4's PDFLightOrigin): the light's probability times the density of
// the point on it; for the infinite light, the solid-angle density of the direction from next.
// A surface vertex on a sphere light's triangle takes the analytic sphere's density by area,
// with which the light's points are drawn (sampleBdptLightStart, strategy s = 1).
PT_INLINE float bdptPdfLightOrigin(PT_SCENE_PARAM PT_IN(BdptVertex) v, PT_IN(BdptVertex) next) {
  vec3 w = bdptDirection(v, next);
  if (w == vec3(0.0f)) return 0.0f;
  if (bdptIsInfiniteLight(v)) {
    return v.lightType == kLightInfinite ? environmentFound(PT_SCENE_ARG - w).lightPdf : 0.0f;
  }
  Emitter e = loadEmitter(PT_SCENE_ARG v.emitter);
  if (PT_HAS_SPHERE_LIGHTS && v.type == kBdptSurface && (e.triangle & kEmitterLight) != 0u) {
    return e.pmf / bdptSphereLightArea(loadLight(PT_SCENE_ARG e.triangle & ~kEmitterLight));
  }
  if (bdptOnSurface(v)) return e.pmf / v.s.area;
  return e.pmf;  // a point or spot light: a delta in position
}

// The density with which vertex v, reached from prev (the camera has none), samples vertex
// `next`, per unit area at next (pbrt-v4's Vertex::PDF).
PT_INLINE float bdptPdf(PT_SCENE_PARAM PT_IN(BdptVertex) prev, PT_IN(BdptVertex) v,
                        PT_IN(BdptVertex) next) {
  if (v.type == kBdptLight) return bdptPdfLight(PT_SCENE_ARG v, next);
  vec3 wn = bdptDirection(v, next);
  if (wn == vec3(0.0f)) return 0.0f;
  float pdf;
  if (v.type == kBdptCamera) {
    pdf = cameraDirectionPdf(PT_PARAMS.camera, v.w, wn);
  } else {
    vec3 wp = bdptDirection(v, prev);
    if (wp == vec3(0.0f)) return 0.0f;
    pdf = bdptBsdfPdf(PT_SCENE_ARG v, wp, wn);
  }
  return bdptConvertDensity(pdf, v, next);
}

// ---- The first vertex of a light subpath --------------------------------------------------------

// A light's emission sampled for a light subpath (pbrt-v4's SampleLe after the light sampler's
// choice): its vertex, and the ray that leaves it with the subpath's throughput beta and the
// ray's solid-angle density pdfDir. pdfPos: the density of the point (over a light at
// infinity's disk). found false: no light, or one that sends nothing.
struct BdptLightStart {
  bool found;
  BdptVertex vertex;
  vec3 origin;
  vec3 direction;
  vec3 beta;
  float pdfPos;
  float pdfDir;
};

// A point of the disk of radius sceneRadius about the scene's centre, perpendicular to unit w,
// drawn uniformly with u: where the rays of a light at infinity travelling along w start (a
// sceneRadius upstream).
PT_INLINE vec3 bdptInfiniteRayOrigin(PT_SCENE_PARAM vec3 w, vec2 u) {
  vec2 disk = sampleConcentricDisk(u);
  vec3 offset = localToWorld(vec3(disk.x, disk.y, 0.0f), w);
  return PT_PARAMS.sceneCenter + PT_PARAMS.sceneRadius * (offset - w);
}

// Samples the light subpath's start with the numbers of its dimensions: the emitter from the
// alias table with uChoose, the point on it with uPos, the direction with uDir.
PT_INLINE BdptLightStart sampleBdptLightStart(PT_SCENE_PARAM vec2 uChoose, vec2 uPos, vec2 uDir,
                                              VertexKey key) {
  BdptLightStart ls;
  ls.found = false;
  ls.vertex = bdptEmptyVertex(kBdptLight, vec3(0.0f), vec3(0.0f), key);
  if (PT_PARAMS.emitterCount == 0u) return ls;
  uint slot = aliasTableSlot(uChoose.x, PT_PARAMS.emitterCount);
  uint index = aliasTablePick(slot, loadEmitter(PT_SCENE_ARG slot), uChoose.y);
  Emitter e = loadEmitter(PT_SCENE_ARG index);
  vec3 Le;
  float cosTheta = 1.0f;
  if ((e.triangle & kEmitterLight) != 0u) {
    Light light = loadLight(PT_SCENE_ARG e.triangle & ~kEmitterLight);
    ls.vertex.p = light.position;
    ls.vertex.lightType = light.type;
    ls.vertex.emitter = index;
    Le = light.radiance;
    if (PT_HAS_SPHERE_LIGHTS && light.type == kLightSphere) {
      // A uniform point of the sphere (by area), a cosine-weighted direction about its outward
      // normal (pbrt-v4's diffuse area light's SampleLe); the ray leaves from just outside it,
      // where the triangles that stand for it, inside the sphere, are not in its way.
      vec3 n = sampleUniformSphere(uPos);
      ls.vertex = bdptSphereLightVertex(PT_SCENE_ARG index, light, n, vec3(0.0f), key);
      vec3 local = sampleCosineHemisphere(uDir);
      cosTheta = local.z;
      ls.direction = localToWorld(local, n);
      ls.pdfDir = cosTheta * kInvPi;
      ls.pdfPos = 1.0f / ls.vertex.s.area;
      ls.origin = offsetRayOrigin(ls.vertex.p, n, ls.vertex.s.magnitude);
    } else if (light.type == kLightPoint || light.type == kLightSpot) {
      ls.origin = light.position;
      ls.pdfPos = 1.0f;
      if (light.type == kLightPoint) {
        ls.direction = sampleUniformSphere(uDir);
        ls.pdfDir = kInv4Pi;
      } else {
        // Uniform in the outer cone about the spot's axis.
        float cosCone = 1.0f - uDir.x * (1.0f - light.cosFalloffEnd);
        float sinCone = sqrt(max(0.0f, 1.0f - cosCone * cosCone));
        vec2 cs = cosSinTwoPi(uDir.y);
        ls.direction = localToWorld(vec3(sinCone * cs.x, sinCone * cs.y, cosCone), light.direction);
        ls.pdfDir = spotEmissionPdf(light);
        Le *= lightSmoothStep(cosCone, light.cosFalloffEnd, light.cosFalloffStart);
      }
    } else {
      // Distant or infinite: a direction (the distant light's own), then a point on the disk
      // across the scene perpendicular to it.
      if (light.type == kLightDistant) {
        ls.direction = -light.direction;
        ls.pdfDir = 1.0f;  // a delta in direction
      } else {
        AnalyticLightSample a;
        if (PT_HAS_ENVIRONMENT_IMAGE && PT_PARAMS.environmentWidth != 0u) {
          a = sampleEnvironmentLight(environmentMap(PT_SCENE_ONLY), PT_PARAMS.sceneCenter, uDir,
                                     PT_PARAMS.sceneRadius);
        } else {
          a = sampleAnalyticLight(light, PT_PARAMS.sceneCenter, uDir, PT_PARAMS.sceneRadius);
        }
        ls.direction = -a.wi;
        ls.pdfDir = a.pdf;
        Le = a.Li;
      }
      ls.origin = bdptInfiniteRayOrigin(PT_SCENE_ARG ls.direction, uPos);
      ls.pdfPos = 1.0f / (kPi * PT_PARAMS.sceneRadius * PT_PARAMS.sceneRadius);
      ls.vertex.p = ls.origin;
      ls.vertex.w = ls.direction;
    }
  } else {
    // An emissive triangle: a uniform point, a cosine-weighted direction on its emitting side
    // (where it emits on both, either side with probability 1/2).
    Triangle tri = loadTriangle(PT_SCENE_ARG e.triangle);
    vec2 b = sampleTriangleBarycentrics(uPos);
    vec3 point = (1.0f - b.x - b.y) * tri.v0 + b.x * tri.v1 + b.y * tri.v2;
    ls.vertex = bdptTriangleLightVertex(PT_SCENE_ARG index, point, b, vec3(0.0f), key);
    vec3 n = ls.vertex.ng;
    float sideShare = 1.0f;
    if (bdptTwoSided(ls.vertex)) {
      sideShare = 0.5f;
      bool back = uDir.x >= 0.5f;
      uDir.x = min((back ? uDir.x - 0.5f : uDir.x) * 2.0f, 0.99999994f);
      if (back) n = -n;
    }
    vec3 local = sampleCosineHemisphere(uDir);
    cosTheta = local.z;
    ls.direction = localToWorld(local, n);
    ls.pdfDir = cosTheta * kInvPi * sideShare;
    ls.pdfPos = 1.0f / ls.vertex.s.area;
    ls.origin = offsetRayOrigin(point, n, ls.vertex.s.magnitude);
    Le = ls.vertex.s.material.emission;
  }
  float pdfOrigin = e.pmf * ls.pdfPos;
  ls.vertex.pdfFwd = pdfOrigin;
  ls.vertex.beta = Le;
  ls.beta = Le * (cosTheta / (pdfOrigin * ls.pdfDir));
  ls.found = ls.pdfDir > 0.0f && ls.pdfPos > 0.0f && maxComponent(Le) > 0.0f;
  return ls;
}

// Where the light subpath starts at infinity, pbrt-v4 corrects its first two densities once
// the walk is done: its second vertex's is the disk point's density projected onto the surface
// there, its first the solid-angle density of its direction (that light sampling from a point
// of the scene would have). first, second: the subpath's first two vertices (second only where
// `count`, the subpath's vertices, is above 1). Vertices, not the subpath: GLSL would copy it.
PT_INLINE void bdptCorrectInfiniteStart(PT_SCENE_PARAM PT_INOUT(BdptVertex) first,
                                        PT_INOUT(BdptVertex) second, uint count, float pdfPos) {
  if (!bdptIsInfiniteLight(first)) return;
  if (count > 1u) {
    second.pdfFwd = pdfPos;
    if (bdptOnSurface(second)) second.pdfFwd *= abs(dot(first.w, second.ng));
  }
  // (Its direction alone matters: any vertex will do as the one it is seen from.)
  first.pdfFwd = bdptPdfLightOrigin(PT_SCENE_ARG first, first);
}

// ---- The random walk ----------------------------------------------------------------------------

// One step of a subpath's random walk at surface vertex v, reached from prev (pbrt-v4's
// RandomWalk after the vertex is made): samples the BSDF for the next direction wi (uLobe: the
// lobe, u: the direction) for radiance (a camera subpath) or importance (a light subpath),
// multiplies beta by f |cos| / pdf, gives the direction's solid-angle density in pdfFwd, and
// sets prev's pdfRev to the density of the reverse step. A specular sample marks v delta, with
// both densities 0. False: no direction, the walk ends.
PT_INLINE bool bdptScatter(PT_SCENE_PARAM PT_INOUT(BdptVertex) v, PT_INOUT(BdptVertex) prev,
                           float uLobe, vec2 u, bool radiance, PT_INOUT(vec3) beta,
                           PT_OUT(float) pdfFwd, PT_OUT(vec3) wi) {
  float pdfRev;
  pdfFwd = 0.0f;
  if (v.s.scatter == kScatterMirror) {
    vec3 d = -v.s.wo;
    wi = d - 2.0f * dot(d, v.s.n) * v.s.n;
    beta *= v.s.material.reflectance;
    v.delta = true;
    pdfRev = 0.0f;
  } else if (v.s.scatter == kScatterBsdf) {
    BsdfSample bs = bsdfSampleTransport(
        v.s.material, v.s.woLocal, uLobe, u, radiance,
        makeRandomStream(v.key.pixel, v.key.sampleIndex, v.key.dim, PT_PARAMS.seed, kStreamSample));
    if (bs.flags == 0u) return false;
    wi = fromLocal(v.s.frame, bs.wi);
    beta *= bs.f * (absCosTheta(bs.wi) / bs.pdf);
    if ((bs.flags & kBsdfSpecular) != 0u) {
      v.delta = true;
      pdfRev = 0.0f;
    } else {
      pdfFwd = bs.pdfIsProportional ? bdptBsdfPdf(PT_SCENE_ARG v, v.s.wo, wi) : bs.pdf;
      pdfRev = bdptBsdfPdf(PT_SCENE_ARG v, wi, v.s.wo);
    }
  } else {
    // Lambertian: cosine-weighted about the normal facing wo.
    wi = localToWorld(sampleCosineHemisphere(u), v.s.n);
    pdfFwd = dot(wi, v.s.n) * kInvPi;
    if (!(pdfFwd > 0.0f)) return false;
    beta *= v.s.material.reflectance;
    pdfRev = abs(dot(v.s.wo, v.s.n)) * kInvPi;
  }
  prev.pdfRev = bdptConvertDensity(pdfRev, v, prev);
  return maxComponent(beta) > 0.0f;
}

#ifdef __cplusplus
}  // namespace pt
#endif

#endif  // PT_BDPT_VERTEX_H
