// CPU reference integrator: unbiased path tracing with next-event estimation, BSDF sampling
// and multiple importance sampling (power heuristic), Russian roulette. Follows the outline
// of pbrt's PathIntegrator::Li; the shader's loop is a separate GLSL transcription.
#include "cpu/integrator.h"

#include <algorithm>
#include <atomic>
#include <barrier>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <thread>
#include <vector>

#include <sched.h>

#include "bsdf.h"
#include "bvh/traverse.h"
#include "common/check.h"
#include "cpu/bounce_random.h"
#include "cpu/integrator_lanes.h"
#include "environment.h"
#include "filter.h"
#include "lights.h"
#include "render/environment_map.h"

namespace pt {
namespace {

// The CPUs this process may run on: what Slurm, taskset or a container allotted, which can be
// fewer than the machine has (std::thread::hardware_concurrency counts those).
int availableCpus() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof(set), &set) == 0 && CPU_COUNT(&set) > 0) return CPU_COUNT(&set);
  return int(std::max(1u, std::thread::hardware_concurrency()));
}

// A uniform point on an emitter chosen from the alias table with uChoose (uLight: the point).
struct LightPoint {
  vec3 point;
  vec3 normal;  // the emitter's unit geometric normal (it emits on this side)
  float area;
  float magnitude;  // for the ray offset at the light
  float pmf;        // probability of choosing this emitter
  vec3 Le;
  uint triangle;
  bool twoSided;  // emits on both sides
};

// The emitter the alias table gives for uChoose.
const Emitter& pickEmitter(const SceneData& scene, vec2 uChoose) {
  const uint slot = aliasTableSlot(uChoose.x, scene.params.emitterCount);
  return scene.emitters[aliasTablePick(slot, scene.emitters[slot], uChoose.y)];
}

LightPoint pointOnEmitter(const SceneData& scene, const CpuSceneCopies& copies,
                          const Emitter& emitter, vec2 uLight) {
  const Triangle& light = scene.bvh.triangles[emitter.triangle];
  const TriangleShading& lightShading = copies.shading[emitter.triangle];
  const vec2 b = sampleTriangleBarycentrics(uLight);
  return LightPoint{(1.0f - b.x - b.y) * light.v0 + b.x * light.v1 + b.y * light.v2,
                    lightShading.normal,
                    lightShading.area,
                    lightShading.magnitude,
                    emitter.pmf,
                    scene.materials[light.material].emission,
                    emitter.triangle,
                    scene.materials[light.material].twoSided != 0u};
}

// The unit direction from p towards a light point, the squared distance, and the cosine at the
// light (> 0: p sees the emitting side).
struct ToLight {
  vec3 wl;
  float dist2;
  float cosLight;
};

ToLight towardsLight(const LightPoint& light, vec3 p) {
  const vec3 toLight = light.point - p;
  const float dist2 = dot(toLight, toLight);
  const vec3 wl = toLight / std::sqrt(dist2);
  return ToLight{wl, dist2, -dot(light.normal, wl)};
}

// A two-sided light seen from its back: the side p sees is the emitting one, its normal turned
// towards p (for the cosine and the shadow ray's offset).
void faceTwoSided(LightPoint& light, ToLight& toward) {
  if (light.twoSided && toward.cosLight < 0.0f) {
    toward.cosLight = -toward.cosLight;
    light.normal = -light.normal;
  }
}

// --debug-pixel's line about a light sample.
void printLightSample(const SceneData& scene, const LightPoint& light, float lightPdf, float weight,
                      bool debugPrint, uint depth) {
  if (debugPrint) {
    std::fprintf(
        stderr, "cpu depth %u: light sample on triangle %u (primitive %u) pdf=%g weight=%g\n",
        depth, light.triangle, scene.bvh.triangles[light.triangle].primitive, lightPdf, weight);
  }
}

// Alpha cut-outs (texture.h's alphaKeepsHit) as the traversal's filter of one ray's hits;
// u is the ray's number (pathAlphaRandom, shadowAlphaRandom).
struct AlphaCutouts {
  const SceneData* scene;
  TextureTables tables;
  float u;
  static bool accept(const void* context, uint32_t triangle, const Hit& hit) {
    const AlphaCutouts& a = *static_cast<const AlphaCutouts*>(context);
    const Triangle& tri = a.scene->bvh.triangles[triangle];
    return alphaKeepsHit(a.tables, tri.material, tri.primitive, hit.barycentrics, a.u);
  }
};

// The scene's ray queries: the closest hit along a path's `ray`, and whether anything lies on a
// shadow ray's segment t in [0, 1) whose light sample drew uLight, cut-outs passed by where the
// scene has them.
std::optional<Hit> closestSurface(const SceneData& scene, const Ray& ray, Intersection test,
                                  uvec2 pixel, uint32_t sampleIndex, uint depth) {
  if (!scene.effects.alphaCutouts) return closestHit(scene.wideBvh(), ray, INFINITY, test);
  const AlphaCutouts cutouts{&scene, scene.textureTables(),
                             pathAlphaRandom(pixel, sampleIndex, depth, scene.params.seed)};
  const HitFilter filter{AlphaCutouts::accept, &cutouts};
  return closestHit(scene.wideBvh(), ray, INFINITY, test, &filter);
}
bool occluded(const SceneData& scene, const Ray& ray, Intersection test, vec2 uLight) {
  if (!scene.effects.alphaCutouts) return anyHit(scene.wideBvh(), ray, 1.0f, test);
  const AlphaCutouts cutouts{&scene, scene.textureTables(), shadowAlphaRandom(uLight)};
  const HitFilter filter{AlphaCutouts::accept, &cutouts};
  return anyHit(scene.wideBvh(), ray, 1.0f, test, &filter);
}

// The analytic light (lights.h) an emitter names, or null for an emissive triangle.
const Light* analyticLight(const SceneData& scene, const Emitter& emitter) {
  if ((emitter.triangle & kEmitterLight) == 0u) return nullptr;
  return &scene.lights[emitter.triangle & ~kEmitterLight];
}

// A sample of an analytic light from p: the environment image's (environment.h) for an infinite
// light that has one, lights.h's otherwise.
AnalyticLightSample sampleLight(const SceneData& scene, const Light& light, vec3 p, vec2 u) {
  const RenderParams& params = scene.params;
  if (light.type == kLightInfinite && params.environmentWidth != 0u) {
    return sampleEnvironmentLight(environmentMapOf(params, scene.environmentTexels), p, u,
                                  params.sceneRadius);
  }
  return sampleAnalyticLight(light, p, u, params.sceneRadius);
}

// A light sample of an analytic light (chosen with probability pmf), given the BSDF's
// f * |cos| towards it (fCos) and its density (bsdfDensity, read only for MIS): traces the
// shadow ray from `from` and returns the contribution, weighed by the power heuristic unless
// the light is a delta (which BSDF sampling never finds).
vec3 analyticLightContribution(const SceneData& scene, const AnalyticLightSample& ls, vec2 uLight,
                               float pmf, vec3 from, vec3 beta, vec3 fCos, float bsdfDensity,
                               bool misOn, Intersection test, uint64_t& rays, bool debugPrint,
                               uint depth) {
  ++rays;
  if (occluded(scene, Ray{from, ls.target - from}, test, uLight)) return vec3(0.0f);
  const float lightPdf = pmf * ls.pdf;
  const float weight = (misOn && !ls.delta) ? powerHeuristic(lightPdf, bsdfDensity) : 1.0f;
  if (debugPrint) {
    std::fprintf(stderr, "cpu depth %u: light sample on analytic light pdf=%g weight=%g\n", depth,
                 lightPdf, weight);
  }
  return beta * fCos * ls.Li * (weight / lightPdf);
}

// Samples direct illumination at diffuse vertex p with shading normal n (next-event
// estimation, pbrt's SampleLd): picks an emitter from the alias table with uChoose, a uniform
// point on its triangle with uLight, and traces a shadow ray to it. Returns the light's
// contribution to L, beta * f * Le * cos / pdf, weighted by the power heuristic against BSDF
// sampling when misOn; zero when the point faces away or is occluded. The shadow ray leaves
// along n, or with shading normals (n then interpolated) on the side of the geometric normal
// ng that the light is on.
vec3 sampleDirectLight(const SceneData& scene, const CpuSceneCopies& copies, vec3 p, vec3 n,
                       vec3 ng, bool shadingNormals, float magnitude, vec3 beta, vec3 f,
                       vec2 uChoose, vec2 uLight, bool misOn, Intersection test, uint64_t& rays,
                       bool debugPrint, uint depth) {
  // Pick an emitter from the alias table, then a uniform point on its triangle (or a sample
  // of an analytic light).
  const Emitter& emitter = pickEmitter(scene, uChoose);
  if ((emitter.triangle & kEmitterLight) != 0u) {
    return sampleAnalyticLightDiffuse(scene, emitter, p, n, ng, shadingNormals, magnitude, beta, f,
                                      uLight, misOn, test, rays, debugPrint, depth);
  }
  LightPoint light = pointOnEmitter(scene, copies, emitter, uLight);

  ToLight toward = towardsLight(light, p);
  faceTwoSided(light, toward);
  const float cosSurface = dot(n, toward.wl);
  if (!(toward.cosLight > 0.0f && cosSurface > 0.0f)) return vec3(0.0f);

  // Shadow ray between the two offset points; t in [0, 1) spans the segment.
  const vec3 side = shadingNormals ? (dot(ng, toward.wl) > 0.0f ? ng : -ng) : n;
  const vec3 from = offsetRayOrigin(p, side, magnitude);
  const vec3 to = offsetRayOrigin(light.point, light.normal, light.magnitude);
  ++rays;
  if (occluded(scene, Ray{from, to - from}, test, uLight)) return vec3(0.0f);

  const float lightPdf = light.pmf * toward.dist2 / (toward.cosLight * light.area);
  const float weight = misOn ? powerHeuristic(lightPdf, cosSurface * kInvPi) : 1.0f;
  printLightSample(scene, light, lightPdf, weight, debugPrint, depth);
  return beta * f * light.Le * (cosSurface * weight / lightPdf);
}

// sampleDirectLight at a vertex with one of bsdf.h's BSDFs: the same light sample, with the
// BSDF's value and density in place of the Lambertian's, in the local shading frame. The
// shadow ray leaves from the side of the geometric normal ng the light is on; f * |cos| is
// zero where the BSDF does not scatter that way.
vec3 sampleDirectLightBsdf(const SceneData& scene, const CpuSceneCopies& copies, vec3 p, vec3 ng,
                           const ShadingFrame& frame, const Material& material, vec3 wo,
                           float magnitude, vec3 beta, vec2 uChoose, vec2 uLight,
                           RandomStream evalStream, RandomStream pdfStream, bool misOn,
                           Intersection test, uint64_t& rays, bool debugPrint, uint depth) {
  const Emitter& emitter = pickEmitter(scene, uChoose);
  if (const Light* analytic = analyticLight(scene, emitter)) {
    const AnalyticLightSample ls = sampleLight(scene, *analytic, p, uLight);
    if (!(maxComponent(ls.Li) > 0.0f)) return vec3(0.0f);
    const vec3 wi = toLocal(frame, ls.wi);
    const vec3 fCos = bsdfF(material, wo, wi, evalStream) * absCosTheta(wi);
    if (!(maxComponent(fCos) > 0.0f)) return vec3(0.0f);
    const float density = (misOn && !ls.delta) ? bsdfPdf(material, wo, wi, pdfStream) : 0.0f;
    const vec3 from = offsetRayOrigin(p, dot(ng, ls.wi) > 0.0f ? ng : -ng, magnitude);
    return analyticLightContribution(scene, ls, uLight, emitter.pmf, from, beta, fCos, density,
                                     misOn, test, rays, debugPrint, depth);
  }
  LightPoint light = pointOnEmitter(scene, copies, emitter, uLight);
  ToLight toward = towardsLight(light, p);
  faceTwoSided(light, toward);
  if (!(toward.cosLight > 0.0f)) return vec3(0.0f);
  const vec3 wi = toLocal(frame, toward.wl);
  const vec3 f = bsdfF(material, wo, wi, evalStream) * absCosTheta(wi);
  if (!(maxComponent(f) > 0.0f)) return vec3(0.0f);

  const vec3 from = offsetRayOrigin(p, dot(ng, toward.wl) > 0.0f ? ng : -ng, magnitude);
  const vec3 to = offsetRayOrigin(light.point, light.normal, light.magnitude);
  ++rays;
  if (occluded(scene, Ray{from, to - from}, test, uLight)) return vec3(0.0f);

  const float lightPdf = light.pmf * toward.dist2 / (toward.cosLight * light.area);
  const float weight =
      misOn ? powerHeuristic(lightPdf, bsdfPdf(material, wo, wi, pdfStream)) : 1.0f;
  printLightSample(scene, light, lightPdf, weight, debugPrint, depth);
  return beta * f * light.Le * (weight / lightPdf);
}

}  // namespace

vec3 sampleAnalyticLightDiffuse(const SceneData& scene, const Emitter& emitter, vec3 p, vec3 n,
                                vec3 ng, bool shadingNormals, float magnitude, vec3 beta, vec3 f,
                                vec2 uLight, bool misOn, Intersection test, uint64_t& rays,
                                bool debugPrint, uint depth) {
  const AnalyticLightSample ls = sampleLight(scene, *analyticLight(scene, emitter), p, uLight);
  const float cosWi = dot(n, ls.wi);
  if (!(cosWi > 0.0f) || !(maxComponent(ls.Li) > 0.0f)) return vec3(0.0f);
  const vec3 side = shadingNormals ? (dot(ng, ls.wi) > 0.0f ? ng : -ng) : n;
  return analyticLightContribution(scene, ls, uLight, emitter.pmf,
                                   offsetRayOrigin(p, side, magnitude), beta, f * cosWi,
                                   cosWi * kInvPi, misOn, test, rays, debugPrint, depth);
}

vec3 environmentSeen(const SceneData& scene, vec3 direction, vec3 beta, bool specularBounce,
                     float bsdfPdf) {
  const RenderParams& params = scene.params;
  if (params.environmentEmitter == kNoEmitter) return vec3(0.0f);
  vec3 Le = params.environment;
  float lightPdf = params.environmentPdf;
  if (params.environmentWidth != 0u) {
    // The image: the direction's texel, and its density times the light's pmf.
    const EnvironmentLookup e =
        environmentLookup(environmentMapOf(params, scene.environmentTexels), direction);
    Le = e.Le;
    lightPdf = params.environmentPdf * e.pdf;
  }
  if (specularBounce) return beta * Le;
  if (params.strategy == kStrategyNee) return vec3(0.0f);
  const float weight = params.strategy == kStrategyMis ? powerHeuristic(bsdfPdf, lightPdf) : 1.0f;
  return beta * weight * Le;
}

bool scatterAtBsdfVertex(const SceneData& scene, const BsdfVertex& v, PathState& state, vec3& wi,
                         vec3& side, uint64_t& rays, bool debugPrint) {
  const CpuSceneCopies& copies = scene.cpuCopies();
  const RenderParams& params = scene.params;
  const Material& material = *v.material;
  const bool misOn = params.strategy == kStrategyMis;
  const bool neeOn = params.strategy != kStrategyBsdf && params.emitterCount > 0;
  const Intersection test =
      params.fastIntersection != 0u ? Intersection::kFast : Intersection::kWatertight;
  auto stream = [&](uint purpose) {
    return makeRandomStream(v.pixel, v.sampleIndex, v.dim, params.seed, purpose);
  };
  // The shading frame about the shading normal, not turned towards the ray: a dielectric
  // tells inside from outside by it.
  const ShadingFrame frame = makeShadingFrame(v.ns, v.triangle->v1 - v.triangle->v0);
  const vec3 wo = toLocal(frame, v.wo);
  // Sample direct illumination from an emitter, unless the BSDF has only delta lobes.
  if (neeOn && bsdfHasNonSpecular(material)) {
    state.L +=
        sampleDirectLightBsdf(scene, copies, v.p, v.ng, frame, material, wo, v.magnitude,
                              state.beta, v.u.lightChoose, v.u.lightPoint, stream(kStreamEval),
                              stream(kStreamLightPdf), misOn, test, rays, debugPrint, v.depth);
  }
  // Sample the BSDF; the lobe choice takes the roulette dimension's second number.
  const BsdfSample bs = bsdfSample(material, wo, v.u.roulette.y, v.u.bsdf, stream(kStreamSample));
  if (bs.flags == 0u) return false;
  wi = fromLocal(frame, bs.wi);
  state.beta *= bs.f * (absCosTheta(bs.wi) / bs.pdf);
  state.specularBounce = (bs.flags & kBsdfSpecular) != 0u;
  state.bsdfPdf =
      bs.pdfIsProportional ? bsdfPdf(material, wo, bs.wi, stream(kStreamSamplePdf)) : bs.pdf;
  if ((bs.flags & kBsdfTransmission) != 0u) state.etaScale *= bs.eta * bs.eta;
  // The new ray leaves from the side it goes to.
  side = dot(v.ng, wi) > 0.0f ? v.ng : -v.ng;
  return true;
}

Ray cameraRay(const Camera& cam, vec2 filmPoint) {
  return Ray{cam.position, cameraDirection(cam, filmPoint)};
}

vec3 sampleRadiance(const SceneData& scene, uvec2 imagePixel, uint32_t sampleIndex, uint64_t& rays,
                    bool debugPrint) {
  const RenderParams& params = scene.params;
  // The film's pixel, which the random numbers and the camera ray are of: a crop renders its
  // pixels of the whole film's image.
  const uvec2 pixel = imagePixel + uvec2(params.camera.cropX, params.camera.cropY);
  const Bvh& bvh = scene.bvh;
  const CpuSceneCopies& copies = scene.cpuCopies();  // the wide BVH, TriangleShading
  const uint seed = params.seed;
  const bool sobol = params.samplerType == kSamplerSobol;  // else independent random numbers
  const bool misOn = params.strategy == kStrategyMis;
  const bool neeOn = params.strategy != kStrategyBsdf && params.emitterCount > 0;
  const bool bsdfEmissionOn = params.strategy != kStrategyNee;
  const Intersection test =
      params.fastIntersection != 0u ? Intersection::kFast : Intersection::kWatertight;

  // The camera ray through a point of the pixel's filter (and of the lens: a pinhole draws no
  // numbers for it, so that its paths are those of the renderer before lenses).
  const vec2 uLens = params.camera.lensRadius > 0.0f
                         ? random2(sobol, pixel, sampleIndex, kDimLens, seed)
                         : vec2(0.0f);
  const CameraSample camera = generateCameraRay(
      params.camera, pixel, random2(sobol, pixel, sampleIndex, kDimPixel, seed), uLens);
  Ray ray{camera.origin, camera.direction};
  vec3 L(0.0f);     // radiance gathered so far
  vec3 beta(1.0f);  // path throughput
  // The camera ray counts as specular: emission it finds is taken at full weight.
  bool specularBounce = true;
  float bsdfPdf = 0.0f;  // solid-angle pdf of the BSDF sample that produced `ray`
  // Product of the squared relative indices of the refractions so far: radiance is scaled by
  // 1 / eta^2 on each, which Russian roulette leaves out (pbrt-v4's etaScale).
  float etaScale = 1.0f;

  for (uint depth = 0;;) {
    // Find the closest surface along the ray; the background is black.
    ++rays;
    const std::optional<Hit> hit = closestSurface(scene, ray, test, pixel, sampleIndex, depth);
    if (!hit) {
      // The ray leaves the scene: the infinite light's radiance, weighed as an emitter's.
      L += environmentSeen(scene, ray.direction, beta, specularBounce, bsdfPdf);
      break;
    }
    const Triangle& tri = bvh.triangles[hit->triangle];
    // The parameters that textures give, at the hit's texture coordinates.
    const Material* untextured = &scene.materials[tri.material];
    const bool textures = scene.params.texturesPresent != 0u;
    Material textured;
    vec2 uv(0.0f);
    if (textures) {
      uv = interpolatedUV(scene.uvs[tri.primitive], hit->barycentrics);
      textured = resolveMaterial(scene.textureTables(), *untextured,
                                 scene.materialTextures[tri.material], uv);
    }
    const Material& material = textures ? textured : *untextured;
    // Hit point from barycentrics (more accurate than origin + t * direction).
    const vec3 p =
        hit->barycentrics.x * tri.v0 + hit->barycentrics.y * tri.v1 + hit->barycentrics.z * tri.v2;
    // The geometric normal, the area and the coordinates' scale (for the ray offsets), as
    // computed once per triangle (TriangleShading; the shader computes them here).
    const TriangleShading& shading = copies.shading[hit->triangle];
    const vec3 ng = shading.normal;
    const vec3 wo = -ray.direction;
    const float cosOut = dot(ng, wo);
    const float magnitude = shading.magnitude;
    if (debugPrint) {
      std::fprintf(stderr,
                   "cpu depth %u: hit triangle %u (primitive %u) t=%g p=(%g, %g, %g) "
                   "beta=(%g, %g, %g)\n",
                   depth, hit->triangle, tri.primitive, hit->t, p.x, p.y, p.z, beta.x, beta.y,
                   beta.z);
    }

    // Add emitted light found by this ray: on the geometric normal's side, or on both.
    const float cosEmit = material.twoSided != 0u ? std::fabs(cosOut) : cosOut;
    if (tri.emitter != kNoEmitter && cosEmit > 0.0f) {
      const vec3 Le = material.emission;
      if (specularBounce) {
        L += beta * Le;
      } else if (bsdfEmissionOn) {
        // Weigh against the chance that light sampling had produced this point.
        float weight = 1.0f;
        if (misOn) {
          const Emitter& emitter = scene.emitters[tri.emitter];
          // A sphere light's triangle: light sampling draws its cone (seen from the ray's
          // origin); any other: a uniform point on the triangle.
          const float lightPdf =
              (emitter.triangle & kEmitterLight) != 0u
                  ? emitter.pmf * sphereLightPdf(*analyticLight(scene, emitter), ray.origin)
                  : emitter.pmf * hit->t * hit->t /
                        (cosEmit * shading.area);  // |direction| = 1: t is the distance
          weight = powerHeuristic(bsdfPdf, lightPdf);
        }
        L += beta * weight * Le;
      }
    }

    // Stop after maxDepth scattering events.
    if (depth == params.maxDepth) break;
    const uint dim = kDimFirstBounce + kDimsPerBounce * depth;
    ++depth;

    // The shading normal: the mesh's vertex normals interpolated where it has them, else ng.
    // (pbrt-v4 does not guard against the light leaks a shading normal can cause, and nor do
    // we: BSDFs are evaluated about ns whichever side of the geometric surface wi is on; rays
    // leave on the side of ng they go to.)
    bool shadingNormals = !scene.normals.empty();  // ns may differ from ng
    vec3 ns = shadingNormals
                  ? interpolatedNormal(scene.normals[tri.primitive], hit->barycentrics, ng)
                  : ng;
    // A bump map moves the shading normal (texture.h).
    if (textures && scene.materialTextures[tri.material].displacement != kNoTexture) {
      const vec3 bumped =
          bumpedNormal(scene.textureTables(), scene.materialTextures[tri.material].displacement,
                       tri, scene.uvs[tri.primitive], uv, ng, ns, shadingNormals,
                       shadingNormals ? scene.normals[tri.primitive] : TriangleNormals{});
      if (bumped != ns) {
        ns = bumped;
        shadingNormals = true;
      }
    }
    // Diffuse and mirror surfaces are two-sided: shaded with the normal facing the ray.
    vec3 n = cosOut >= 0.0f ? ng : -ng;
    if (shadingNormals) n = dot(ns, wo) >= 0.0f ? ns : -ns;
    // This event's random numbers, all four dimensions at once (the shader draws each where
    // it is used: the same numbers).
    const BounceRandom u = bounceRandomSimd(sobol, pixel, sampleIndex, dim, seed);
    vec3 wi;
    if (material.type == kMaterialMirror) {
      // Ideal reflection: the BSDF is a delta, f * cos / pdf = reflectance.
      wi = ray.direction - 2.0f * dot(ray.direction, n) * n;
      beta *= material.reflectance;
      specularBounce = true;
    } else if (material.type != kMaterialDiffuse) {
      // One of bsdf.h's BSDFs: light sampling and BSDF sampling in its shading frame.
      PathState state{L, beta, etaScale, bsdfPdf, specularBounce};
      const BsdfVertex vertex{&tri,      &material, p,     ng,          ns,  wo,
                              magnitude, u,         pixel, sampleIndex, dim, depth};
      const bool goesOn = scatterAtBsdfVertex(scene, vertex, state, wi, n, rays, debugPrint);
      L = state.L;
      beta = state.beta;
      etaScale = state.etaScale;
      bsdfPdf = state.bsdfPdf;
      specularBounce = state.specularBounce;
      if (!goesOn) break;
    } else {
      const vec3 f = material.reflectance * kInvPi;
      // Sample direct illumination from an emitter (next-event estimation).
      if (neeOn && material.reflectance != vec3(0.0f)) {
        L += sampleDirectLight(scene, copies, p, n, ng, shadingNormals, magnitude, beta, f,
                               u.lightChoose, u.lightPoint, misOn, test, rays, debugPrint, depth);
      }
      // Sample the BSDF: cosine-weighted, so f * cos / pdf = reflectance.
      wi = localToWorld(sampleCosineHemisphere(u.bsdf), n);
      bsdfPdf = dot(wi, n) * kInvPi;
      if (!(bsdfPdf > 0.0f)) break;  // direction in the tangent plane: zero contribution
      beta *= material.reflectance;
      specularBounce = false;
    }
    if (maxComponent(beta) <= 0.0f) break;

    // Possibly terminate the path with Russian roulette (unbiased: survivors are scaled).
    if (params.russianRoulette != 0u && depth >= params.rrStartDepth) {
      const float q = std::max(0.0f, 1.0f - maxComponent(beta * etaScale));
      if (u.roulette.x < q) break;
      beta /= 1.0f - q;
    }

    // Leave the surface on the side of the new direction.
    if (shadingNormals) n = dot(ng, wi) > 0.0f ? ng : -ng;
    ray = Ray{offsetRayOrigin(p, n, magnitude), wi};
  }
  // The camera sample's weight: 1 but for the negative lobes of some filters (filter.h).
  L *= camera.weight;
  if (debugPrint) {
    std::fprintf(stderr, "cpu sample %u: L=(%g, %g, %g)\n", sampleIndex, L.x, L.y, L.z);
  }
  return L;
}

CpuRenderStats renderCpu(const SceneData& scene, const CpuRenderOptions& options, Film& film) {
  const Camera& cam = scene.params.camera;
  PT_CHECK(film.width == int(cam.width) && film.height == int(cam.height));
  const auto callStart = std::chrono::steady_clock::now();
  scene.cpuCopies();  // built here on a first render: set-up, not render time
  const auto start = std::chrono::steady_clock::now();
  CpuRenderStats stats;
  stats.threads = options.threads > 0 ? options.threads : availableCpus();

  // Progressive passes over the whole image, one sample index per pass, so that the film
  // always holds whole passes: stopped at any moment, it is a uniform image of k samples per
  // pixel. Samples go into the film as they are traced and are also kept in `pass`; a stop
  // drops the pass under way by taking its traced tiles back out, which the film's exact sums
  // undo bit for bit. So the time to stop is one tile, not one pass. Within a pass, tiles are
  // handed out through an atomic counter and each pixel belongs to one tile, so threads write
  // disjoint pixels. Random numbers depend on (pixel, sample) only and the sums are exact, so
  // the image's bits do not depend on the thread count, the tile order, or how the passes
  // were split between runs.
  constexpr int kTile = 8;  // small: a pass ends with less waiting for the last tiles
  const int tilesX = (film.width + kTile - 1) / kTile;
  const int tilesY = (film.height + kTile - 1) / kTile;
  const int tileCount = tilesX * tilesY;
  std::vector<vec3> pass(film.pixelCount());
  std::vector<char> traced(static_cast<size_t>(tileCount));  // tiles of this pass in the film
  auto forTilePixels = [&](int tile, auto&& f) {
    const int x0 = (tile % tilesX) * kTile;
    const int y0 = (tile / tilesX) * kTile;
    for (int y = y0; y < std::min(y0 + kTile, film.height); ++y) {
      for (int x = x0; x < std::min(x0 + kTile, film.width); ++x) {
        f(x, y, pass[size_t(y) * size_t(film.width) + size_t(x)]);
      }
    }
  };
  auto stopRequested = [&] {
    return options.stop && options.stop->load(std::memory_order_relaxed);
  };

  // The threads meet at a barrier twice a pass: before tracing (the main thread has set the
  // pass up) and after it (the main thread then checkpoints, or takes a dropped pass out).
  std::barrier sync(stats.threads);
  int passIndex = 0;      // written by the main thread between passes only
  bool finished = false;  // likewise
  // Each thread has its share of the tiles, the same in every pass, so that the film entries
  // it adds to stay in its own core's caches (two cores may not even share a last-level
  // cache); a thread done with its share helps with the others'. Tiles are numbered column by
  // column: tiles traced at the same time lie one above the other, so their pixels' film
  // entries share no cache line, as those of neighbours in a row do at their common edge.
  struct alignas(64) Share {
    std::atomic<int> next{0};  // the share's next tile number
    int end = 0;
  };
  std::vector<Share> shares(size_t(stats.threads));
  std::atomic<int> tilesDone{0};
  std::atomic<bool> dropped{false};
  std::atomic<uint64_t> totalRays{0};
  std::mutex progressMutex;

  auto nextTile = [&](int thread) {
    for (int s = 0; s < stats.threads; ++s) {
      Share& share = shares[size_t((thread + s) % stats.threads)];
      if (share.next.load(std::memory_order_relaxed) >= share.end) continue;
      const int k = share.next.fetch_add(1, std::memory_order_relaxed);
      if (k < share.end) return (k % tilesY) * tilesX + k / tilesY;
    }
    return -1;  // the pass is done
  };
  auto trace = [&](int thread, uint64_t& rays) {
    const uint32_t sampleIndex = options.firstSample + uint32_t(passIndex);
    for (int tile; (tile = nextTile(thread)) >= 0;) {
      if (stopRequested()) {
        dropped = true;
        break;
      }
      // The tile's paths, several at a time (sampleRadianceLanes: sampleRadiance's
      // results, bit for bit).
      uvec2 tilePixels[kTile * kTile];
      vec3 samples[kTile * kTile];
      size_t count = 0;
      forTilePixels(tile, [&](int x, int y, vec3&) {
        film.prefetch(x, y);  // on its way while the tile's paths are traced
        tilePixels[count++] = uvec2(x, y);
      });
      sampleRadianceLanes(scene, tilePixels, count, sampleIndex, samples, rays);
      count = 0;
      forTilePixels(tile, [&](int x, int y, vec3& sample) {
        sample = samples[count++];
        film.add(x, y, sample);
      });
      traced[size_t(tile)] = 1;
      const int done = tilesDone.fetch_add(1) + 1;
      if (options.progress) {
        std::unique_lock lock(progressMutex, std::try_to_lock);
        if (lock.owns_lock()) {
          options.progress((double(passIndex) + double(done) / double(tileCount)) /
                           double(options.spp));
        }
      }
    }
  };
  auto worker = [&](int thread) {
    uint64_t rays = 0;
    for (;;) {
      sync.arrive_and_wait();
      if (finished) break;
      trace(thread, rays);
      sync.arrive_and_wait();
    }
    totalRays += rays;
  };
  std::vector<std::thread> threads;
  for (int i = 1; i < stats.threads; ++i) threads.emplace_back(worker, i);

  // The main thread traces too, and between passes reports progress and checkpoints.
  // However it leaves the loop (a stop, or a checkpoint that throws), the workers are released.
  uint64_t rays = 0;
  auto releaseWorkers = [&] {
    finished = true;
    sync.arrive_and_wait();
    for (std::thread& t : threads) t.join();
  };
  try {
    for (; passIndex < options.spp && !stopRequested(); ++passIndex) {
      for (int t = 0; t < stats.threads; ++t) {
        shares[size_t(t)].next = int(int64_t(tileCount) * t / stats.threads);
        shares[size_t(t)].end = int(int64_t(tileCount) * (t + 1) / stats.threads);
      }
      tilesDone = 0;
      std::fill(traced.begin(), traced.end(), 0);
      sync.arrive_and_wait();
      trace(0, rays);
      sync.arrive_and_wait();
      if (dropped) {
        for (int tile = 0; tile < tileCount; ++tile) {
          if (traced[size_t(tile)]) {
            forTilePixels(tile, [&](int x, int y, vec3& sample) { film.takeBack(x, y, sample); });
          }
        }
        break;
      }
      stats.samplesDone = passIndex + 1;
      if (options.checkpoint) options.checkpoint(stats.samplesDone);
    }
  } catch (...) {
    releaseWorkers();
    throw;
  }
  releaseWorkers();
  totalRays += rays;
  stats.stopped = stats.samplesDone < options.spp;
  if (options.progress && !stats.stopped) options.progress(1.0);

  stats.rays = totalRays;
  stats.invalidSamples = film.totalInvalid();
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  stats.wallSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - callStart).count();
  return stats;
}

}  // namespace pt
