// The volume integrator's outline on the CPU: pbrt-v4's VolPathIntegrator::Li over the steps
// of volume_vertex.h (flights through media, shadow rays' transmittance, emission and light
// samples weighed over the channels) and path_vertex.h (shading points, light and BSDF
// samples), which the shader's volume variant calls in the same order. What is this file's
// own: tracing rays (the wide BVH), and crossing the interfaces on a shadow ray's way.
#include "cpu/volpath.h"

#include <cmath>
#include <cstdio>
#include <optional>

#include "cpu/bounce_random.h"
#include "cpu/integrator.h"
#include "filter.h"
#include "volume_vertex.h"

namespace pt {
namespace {

// Traces the shadow ray of light sample ls, which starts in `medium`, through the interfaces
// and media on its way: false when a surface blocks it; tr gathers the media's transmittance.
bool traceShadowThroughMedia(const SceneData& scene, const PathScene& ps, const LightSample& ls,
                             uint medium, uint hero, vec2 uLight, ShadowTransmittance& tr,
                             uint64_t& rays) {
  // Without interface surfaces every surface on the way blocks the ray: an any-hit query
  // answers that (cheaper than the closest hit, which the loop below needs to cross
  // interfaces), and the whole segment lies in `medium`.
  if (!scene.effects.interfaces) {
    if (!traceShadowRay(scene, ls, uLight, rays)) return false;
    if (medium == kNoMedium) return true;
    const vec3 d = ls.to - ls.from;
    const float length = glm::length(d);
    return trackShadowSegment(ps, tr, medium, hero, ls.from, d / length, length);
  }
  const Intersection test =
      scene.params.fastIntersection != 0u ? Intersection::kFast : Intersection::kWatertight;
  vec3 from = ls.from;
  for (uint crossing = 0; crossing <= kMaxInterfaceCrossings; ++crossing) {
    ++rays;
    const Ray ray{from, ls.to - from};
    const std::optional<Hit> hit = closestShadowHit(scene, ray, test, uLight);
    const Triangle* tri = hit ? &scene.bvh.triangles[hit->triangle] : nullptr;
    if (tri != nullptr && scene.materials[tri->material].type != kMaterialInterface) return false;
    if (medium != kNoMedium) {
      const float length = glm::length(ray.direction);
      const float tEnd = (hit ? hit->t : 1.0f) * length;
      if (!trackShadowSegment(ps, tr, medium, hero, from, ray.direction / length, tEnd)) {
        return false;
      }
    }
    if (tri == nullptr) return true;
    medium =
        crossInterface(ps, hit->triangle, *tri, hit->barycentrics, ray.direction, medium, from);
  }
  return false;
}

}  // namespace

vec3 sampleRadianceVolume(const SceneData& scene, uvec2 imagePixel, uint32_t sampleIndex,
                          uint64_t& rays, bool debugPrint) {
  const RenderParams& params = scene.params;
  const PathScene ps = scene.pathScene();
  const uvec2 pixel = imagePixel + uvec2(params.camera.cropX, params.camera.cropY);
  const uint seed = params.seed;
  const bool sobol = params.samplerType == kSamplerSobol;
  const Intersection test =
      params.fastIntersection != 0u ? Intersection::kFast : Intersection::kWatertight;

  // The camera ray through a point of the pixel's filter (and of the lens).
  const CameraSample camera = cameraSampleOf(params.camera, sobol, pixel, sampleIndex, seed);
  Ray ray{camera.origin, camera.direction};
  // L, beta, the densities over the channels, the hero channel, the camera's medium.
  VolumePath v = startVolumePath(ps, pixel, sampleIndex, camera);
  uint crossings = 0;  // interfaces crossed since the last scattering event

  for (;;) {
    // Find the closest surface along the ray; in a homogeneous medium that scatters, only up
    // to where the flight's first collision will be (volume_vertex.h's firstCollisionAhead,
    // a little beyond): a surface farther away does not change the path, and the shorter
    // search is cheaper (volumetric-caustic 0.96 of the time, the same image).
    ++rays;
    float tLimit = INFINITY;
    if (v.medium != kNoMedium) {
      const float ahead = firstCollisionAhead(scene.media[v.medium], v);
      if (ahead < kMaxFloat) tLimit = ahead / glm::length(ray.direction) * 1.0001f;
    }
    const std::optional<Hit> hit =
        closestSurface(scene, ray, test, pixel, sampleIndex, v.depth, tLimit);

    // In a medium: fly through it to that surface by delta tracking, which may end the path
    // (absorption) or scatter it at a point of the medium.
    if (v.medium != kNoMedium) {
      const float length = glm::length(ray.direction);
      const vec3 d = ray.direction / length;
      vec3 p;
      float g;
      const uint flight = trackFlight(ps, v, ray.origin, d, hit ? hit->t * length : INFINITY, p, g);
      if (flight == kFlightEnded) break;
      if (flight == kFlightScattered) {
        // A scattering event in the medium: light sampling with the phase function, then the
        // phase function's sample for the next direction.
        if (v.depth == params.maxDepth) break;
        const VertexKey key{pixel, sampleIndex, kDimFirstBounce + kDimsPerBounce * v.depth};
        ++v.depth;
        const BounceRandom u = bounceRandomSimd(sobol, pixel, sampleIndex, key.dim, seed);
        if (neeOn(ps)) {
          const LightSample ls =
              sampleLightAt(ps, mediumPoint(p, -d, g), key, u.lightChoose, u.lightPoint);
          if (ls.found) {
            ShadowTransmittance tr = startShadowTransmittance(ps, key);
            if (traceShadowThroughMedia(scene, ps, ls, v.medium, v.hero, u.lightPoint, tr, rays)) {
              v.path.L += volumeLightContribution(ps, v, ls.f, ls.f.x, ls, tr);
            }
          }
        }
        vec3 wi;
        if (!scatterInMedium(v, -d, g, u.bsdf, wi)) break;
        startFlight(ps, v, key, p);
        crossings = 0;
        ray = Ray{p, wi};
        continue;
      }
    }

    if (!hit) {
      // The ray leaves the scene: the infinite light's radiance, weighed as an emitter's.
      addVolumeEnvironmentFound(ps, v, ray.direction);
      break;
    }
    const Triangle& tri = scene.bvh.triangles[hit->triangle];
    // A surface that only bounds media: the ray goes on beyond it, in the medium there.
    if (scene.materials[tri.material].type == kMaterialInterface) {
      if (++crossings > kMaxInterfaceCrossings) break;
      v.medium = crossInterface(ps, hit->triangle, tri, hit->barycentrics, ray.direction, v.medium,
                                ray.origin);
      continue;
    }
    const SurfacePoint s =
        surfacePointAt(ps, hit->triangle, tri, hit->barycentrics, -ray.direction, v.path.rd);
    if (debugPrint) {
      std::fprintf(stderr, "cpu depth %u: hit triangle %u (primitive %u) t=%g medium %d\n", v.depth,
                   hit->triangle, tri.primitive, hit->t, int(v.medium));
    }

    // Emitted light found by this ray, weighed against light sampling.
    addVolumeEmissionFound(ps, v, tri, s);

    // Stop after maxDepth scattering events.
    if (v.depth == params.maxDepth) break;
    const VertexKey key{pixel, sampleIndex, kDimFirstBounce + kDimsPerBounce * v.depth};
    ++v.depth;
    const BounceRandom u = bounceRandomSimd(sobol, pixel, sampleIndex, key.dim, seed);

    // Light sampling: the shadow ray leaves into the medium on the light's side.
    if (samplesLightAt(ps, s)) {
      const LightSample ls = sampleLightAt(ps, s, key, u.lightChoose, u.lightPoint);
      if (ls.found) {
        ShadowTransmittance tr = startShadowTransmittance(ps, key);
        const uint medium = mediumAfter(ps, tri.primitive, s.ng, ls.to - ls.from, v.medium);
        if (traceShadowThroughMedia(scene, ps, ls, medium, v.hero, u.lightPoint, tr, rays)) {
          v.path.L += volumeLightContribution(ps, v, ls.f * ls.scale,
                                              lightSampleBsdfPdf(ps, s, key, ls), ls, tr);
        }
      }
    }

    // The BSDF's sample for the next direction, and the medium it leads into.
    vec3 wi;
    if (!sampleBsdfAt(ps, s, key, v.path, u.roulette.y, u.bsdf, wi)) break;
    afterSurfaceScatter(v);
    if (maxComponent(v.path.beta) <= 0.0f) break;
    if (!survivesVolumeRoulette(ps, v, u.roulette.x)) break;
    v.medium = mediumAfter(ps, tri.primitive, s.ng, wi, v.medium);
    startFlight(ps, v, key, s.p);
    crossings = 0;
    ray = Ray{nextRayOrigin(s, wi), wi};
  }
  const vec3 L = v.path.L * camera.weight;
  if (debugPrint) {
    std::fprintf(stderr, "cpu sample %u: L=(%g, %g, %g)\n", sampleIndex, L.x, L.y, L.z);
  }
  return L;
}

}  // namespace pt
