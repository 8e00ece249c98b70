// The CPU reference's stochastic progressive photon mapping: the outline of pbrt-v4's
// SPPMIntegrator::Render over shaders/sppm_vertex.h's steps. The camera paths are the path tracer's
// (sampleRadianceUntil), ended past their visible point; the photons start as BDPT's light
// subpaths do (sampleBdptLightStart) and scatter by bdptScatter for importance. What is this
// file's own is the schedule: the passes of an iteration across threads, the pixels' state, and
// the exact sums that make the image independent of the order photons arrive in.
#include "cpu/sppm.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include "bdpt_vertex.h"
#include "bvh/workers.h"
#include "common/check.h"
#include "common/memory.h"
#include "cpu/bounce_random.h"
#include "cpu/sppm_grid.h"
#include "image/exact_sum.h"
#include "sppm_vertex.h"

namespace pt {
namespace {

// What the iteration under way gathers for a pixel (its state across iterations is its
// SppmPixelRecord).
struct SppmPixel {
  vec3 ldPass{0.0f};  // this iteration's direct light
  SppmVisiblePoint vp;
  bool hasVp = false;
  // The photons' flux this iteration, summed exactly (any order, the same bits), and their
  // count; `lock` guards both.
  std::array<ExactSum, 3> phi;
  uint32_t m = 0;
  bool invalid = false;  // a photon brought NaN or infinite flux: the pixel's estimate is invalid
  std::atomic_flag lock;

  void addPhoton(vec3 flux) {
    while (lock.test_and_set(std::memory_order_acquire)) {
    }
    if (std::isfinite(flux.x) && std::isfinite(flux.y) && std::isfinite(flux.z)) {
      for (int c = 0; c < 3; ++c) phi[size_t(c)].add(flux[c]);
    } else {
      invalid = true;
    }
    ++m;
    lock.clear(std::memory_order_release);
  }
};

// Traces photon `photon` of iteration `iteration` (pbrt-v4's photon path): a light chosen by
// power and its emission (sampleBdptLightStart), then up to maxDepth surface hits, each after
// the first adding its flux to the visible points within their radius, each scattered by the
// BSDF for importance and continued by Russian roulette.
void sppmTracePhoton(const SceneData& scene, const PathScene& ps, const SppmGrid& grid,
                     std::vector<SppmPixel>& pixels, uint photon, uint iteration, uint maxDepth,
                     uint64_t& rays) {
  const RenderParams& params = scene.params;
  const bool sobol = params.samplerType == kSamplerSobol;
  const Intersection test =
      params.fastIntersection != 0u ? Intersection::kFast : Intersection::kWatertight;
  const VertexKey start = sppmPhotonKey(photon, iteration, 0u);
  const BounceRandom u0 = bounceRandomSimd(sobol, start.pixel, iteration, start.dim, params.seed);
  const BdptLightStart light =
      sampleBdptLightStart(ps, u0.lightChoose, u0.lightPoint, u0.bsdf, start);
  if (!light.found) return;
  vec3 beta = light.beta;
  Ray ray{light.origin, light.direction};
  BdptVertex prev = light.vertex;
  for (uint depth = 0; depth < maxDepth; ++depth) {
    const VertexKey key = sppmPhotonKey(photon, iteration, depth + 1u);
    ++rays;
    const std::optional<Hit> hit = closestSurface(scene, ray, test, key.pixel, iteration, key.dim);
    if (!hit) break;
    const Triangle& tri = scene.bvh.triangles[hit->triangle];
    const SurfacePoint s = surfacePointAt(ps, hit->triangle, tri, hit->barycentrics, -ray.direction,
                                          noRayDifferential());
    if (sppmPhotonCounts(depth, maxDepth)) {
      grid.forWithin(s.p, [&](uint32_t i) {
        SppmPixel& px = pixels[i];
        px.addPhoton(sppmPhotonFlux(ps, px.vp, beta, -ray.direction));
      });
    }
    BdptVertex v = bdptSurfaceVertex(s, tri.emitter, key, beta, 0.0f, prev);
    const BounceRandom u = bounceRandomSimd(sobol, key.pixel, iteration, key.dim, params.seed);
    vec3 betaNew = beta;
    float pdf;
    vec3 wi;
    if (!bdptScatter(ps, v, prev, u.roulette.y, u.bsdf, /*radiance=*/false, betaNew, pdf, wi)) {
      break;
    }
    if (!sppmPhotonSurvives(beta, betaNew, u.roulette.x)) break;
    prev = v;
    ray = Ray{nextRayOrigin(s, wi), wi};
  }
}

SppmPixelState stateOf(const SppmPixelRecord& r) {
  SppmPixelState p;
  p.radius = r.radius;
  p.n = r.n;
  p.tau = r.tau;
  return p;
}

}  // namespace

SppmPixels& sppmStartState(const SceneData& scene, const RenderOptions& options, size_t pixelCount,
                           SppmPixels& local) {
  SppmPixels& pixels = options.sppmPixels ? *options.sppmPixels : local;
  if (pixels.empty()) {
    PT_CHECK(options.firstSample == 0u, "SPPM continues only from the state of its iterations");
    const SppmPixelState start = sppmStartPixel(scene.sppm.radius);
    pixels.assign(pixelCount, SppmPixelRecord{start.radius, start.n, start.tau, vec3(0.0f), false});
  } else {
    PT_CHECK(options.firstSample > 0u && pixels.size() == pixelCount,
             "an SPPM state continued has a record a pixel and iterations done");
  }
  return pixels;
}

void sppmUpdateRecord(SppmPixelRecord& r, vec3 phi, uint32_t m, vec3 ld) {
  const SppmPixelState next = sppmUpdatePixel(stateOf(r), phi, m);
  r.radius = next.radius;
  r.n = next.n;
  r.tau = next.tau;
  r.ldSum += ld;
}

void sppmEstimateToFilm(const SppmPixels& pixels, uint32_t iterations, uint32_t photons,
                        Film& film) {
  PT_CHECK(pixels.size() == film.pixelCount() && iterations > 0u);
  film = Film(film.width, film.height);
  for (size_t i = 0; i < pixels.size(); ++i) {
    const SppmPixelRecord& p = pixels[i];
    // (A pixel that took invalid flux is counted as an invalid sample by the film.)
    const vec3 L = p.invalid
                       ? vec3(NAN)
                       : sppmPixelRadiance(p.ldSum, stateOf(p), float(iterations), float(photons));
    film.add(int(i % size_t(film.width)), int(i / size_t(film.width)), L);
  }
}

uint32_t sppmPhotonsPerIteration(const SceneData& scene) {
  const int64_t n = scene.sppm.photonsPerIteration;
  if (n > 0) return uint32_t(n);
  return uint32_t(scene.params.camera.width) * uint32_t(scene.params.camera.height);
}

void checkSppmFitsInMemory(int width, int height, const std::string& what) {
  // The film, the pixels' state and the grid's inputs (renderSppm's vectors below).
  const size_t bytesPerPixel = Film::bytesPerPixel() + sizeof(SppmPixel) + sizeof(SppmPixelRecord) +
                               sizeof(vec3) + sizeof(float) + sizeof(char);
  const uint64_t n = uint64_t(std::max(width, 0)) * uint64_t(std::max(height, 0));
  checkFitsInMemory(
      n * bytesPerPixel,
      what + "sppm with a " + std::to_string(width) + "x" + std::to_string(height) + " film",
      std::to_string(bytesPerPixel) + " bytes per pixel: the film and sppm's state");
}

CpuRenderStats renderSppm(const SceneData& scene, const CpuRenderOptions& options, Film& film) {
  const Camera& cam = scene.params.camera;
  PT_CHECK(film.width == int(cam.width) && film.height == int(cam.height));
  PT_CHECK(scene.params.mediaPresent == 0u, "SPPM renders no media (checkBdptScene)");
  const auto callStart = std::chrono::steady_clock::now();
  scene.cpuCopies();  // built here on a first render: set-up, not render time
  const auto start = std::chrono::steady_clock::now();
  CpuRenderStats stats;
  stats.threads = options.threads > 0 ? options.threads : availableCpus();
  Workers workers(stats.threads);

  const PathScene ps = scene.pathScene();
  const uint maxDepth = scene.params.maxDepth;
  const uint32_t photons = sppmPhotonsPerIteration(scene);
  const size_t pixelCount = film.pixelCount();
  SppmPixels local;
  SppmPixels& records = sppmStartState(scene, options, pixelCount, local);
  std::vector<SppmPixel> pixels(pixelCount);
  std::vector<vec3> points(pixelCount);
  std::vector<float> radii(pixelCount);
  std::vector<char> present(pixelCount);
  std::atomic<uint64_t> totalRays{0};
  auto stopRequested = [&] {
    return options.stop && options.stop->load(std::memory_order_relaxed);
  };

  int done = 0;
  for (int k = 0; k < options.spp && !stopRequested(); ++k) {
    const uint32_t iteration = options.firstSample + uint32_t(k);
    // The camera pass: each pixel's path (the path tracer's, with its random numbers of
    // sample index `iteration`) to its visible point, and the direct light on the way.
    workers.forChunks(pixelCount, 64, [&](size_t begin, size_t end) {
      uint64_t rays = 0;
      for (size_t i = begin; i < end && !stopRequested(); ++i) {
        SppmPixel& px = pixels[i];
        px.hasVp = false;
        const PathEnd visiblePoint = [&px, maxDepth](const SurfacePoint& s, const VertexKey& key,
                                                     uint depth, vec3 beta) {
          if (!sppmTakesVisiblePoint(s, depth, maxDepth)) return false;
          px.vp = SppmVisiblePoint{s, key, beta};
          px.hasVp = true;
          return true;
        };
        const uvec2 pixel(uint32_t(i % size_t(film.width)), uint32_t(i / size_t(film.width)));
        px.ldPass = sampleRadianceUntil(scene, pixel, iteration, rays, &visiblePoint);
      }
      totalRays += rays;
    });
    if (stopRequested()) break;

    // The grid over the visible points that carry light to their pixel.
    for (size_t i = 0; i < pixelCount; ++i) {
      const SppmPixel& px = pixels[i];
      present[i] = px.hasVp && px.vp.beta != vec3(0.0f);
      points[i] = px.vp.s.p;
      radii[i] = records[i].radius;
    }
    const SppmGrid grid(points, radii, present);

    // The photon pass.
    workers.forChunks(photons, 256, [&](size_t begin, size_t end) {
      uint64_t rays = 0;
      for (size_t p = begin; p < end && !stopRequested(); ++p) {
        sppmTracePhoton(scene, ps, grid, pixels, uint(p), uint(iteration), maxDepth, rays);
      }
      totalRays += rays;
    });
    if (stopRequested()) break;

    // Every pixel's update from the photons it gathered.
    for (size_t i = 0; i < pixelCount; ++i) {
      SppmPixel& px = pixels[i];
      SppmPixelRecord& r = records[i];
      const vec3 phi(float(px.phi[0].toDouble()), float(px.phi[1].toDouble()),
                     float(px.phi[2].toDouble()));
      sppmUpdateRecord(r, phi, px.m, px.ldPass);
      r.invalid = r.invalid || px.invalid;
      px.phi = {};
      px.m = 0;
      px.invalid = false;
    }
    done = k + 1;
    if (options.progress) options.progress(double(done) / double(options.spp));
    if (options.checkpoint) {
      sppmEstimateToFilm(records, options.firstSample + uint32_t(done), photons, film);
      options.checkpoint(done);
    }
  }

  // Each pixel's estimate, as its one sample.
  if (options.firstSample + uint32_t(done) > 0u) {
    sppmEstimateToFilm(records, options.firstSample + uint32_t(done), photons, film);
  }
  stats.samplesDone = done;
  finishCpuRenderStats(options, film, totalRays, start, callStart, stats);
  return stats;
}

}  // namespace pt
