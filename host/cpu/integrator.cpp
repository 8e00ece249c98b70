// CPU reference integrator: unbiased path tracing with next-event estimation, BSDF sampling
// and multiple importance sampling (power heuristic), Russian roulette. sampleRadiance is the
// outline of pbrt-v4's PathIntegrator::Li over path_vertex.h's steps, which the CPU's lanes and
// the shader call too; what is this file's own is how rays are traced (the wide BVH) and how
// the image is scheduled over threads.
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

#include "bvh/traverse.h"
#include "common/check.h"
#include "cpu/bdpt.h"
#include "cpu/bounce_random.h"
#include "cpu/integrator_lanes.h"
#include "cpu/sppm.h"
#include "cpu/volpath.h"
#include "filter.h"
#include "path_vertex.h"

namespace pt {
namespace {

// Whether anything lies on a shadow ray's segment t in [0, 1) whose light sample drew uLight,
// cut-outs passed by where the scene has them.
bool occluded(const SceneData& scene, const Ray& ray, Intersection test, vec2 uLight) {
  if (!scene.effects.alphaCutouts) return anyHit(scene.wideBvh(), ray, 1.0f, test);
  const AlphaCutouts cutouts = AlphaCutouts::ofShadowRay(scene, uLight);
  const HitFilter filter = cutouts.filter();
  return anyHit(scene.wideBvh(), ray, 1.0f, test, &filter);
}

}  // namespace

int availableCpus() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof(set), &set) == 0 && CPU_COUNT(&set) > 0) return CPU_COUNT(&set);
  return int(std::max(1u, std::thread::hardware_concurrency()));
}

void prefetchHitRecords(const SceneData& scene, const Hit& hit) {
  const auto prefetch = [](const auto* record) {
    __builtin_prefetch(record);
    __builtin_prefetch(reinterpret_cast<const char*>(record) + sizeof(*record) - 1);
  };
  prefetch(&scene.bvh.triangles[hit.triangle]);
  prefetch(&scene.cpuCopies().shading[hit.triangle]);
  if (!scene.normals.empty()) prefetch(&scene.normals[hit.primitive]);
  if (!scene.uvs.empty()) prefetch(&scene.uvs[hit.primitive]);
  if (!scene.mediumInterfaces.empty()) prefetch(&scene.mediumInterfaces[hit.primitive]);
}

std::optional<Hit> closestSurface(const SceneData& scene, const Ray& ray, Intersection test,
                                  uvec2 pixel, uint32_t sampleIndex, uint depth, float tMax) {
  std::optional<Hit> hit;
  if (!scene.effects.alphaCutouts) {
    hit = closestHit(scene.wideBvh(), ray, tMax, test);
  } else {
    const AlphaCutouts cutouts = AlphaCutouts::ofPathRay(scene, pixel, sampleIndex, depth);
    const HitFilter filter = cutouts.filter();
    hit = closestHit(scene.wideBvh(), ray, tMax, test, &filter);
  }
  if (hit) prefetchHitRecords(scene, *hit);
  return hit;
}

std::optional<Hit> closestShadowHit(const SceneData& scene, const Ray& ray, Intersection test,
                                    vec2 uLight) {
  if (!scene.effects.alphaCutouts) return closestHit(scene.wideBvh(), ray, 1.0f, test);
  const AlphaCutouts cutouts = AlphaCutouts::ofShadowRay(scene, uLight);
  const HitFilter filter = cutouts.filter();
  return closestHit(scene.wideBvh(), ray, 1.0f, test, &filter);
}

AlphaCutouts AlphaCutouts::ofPathRay(const SceneData& scene, uvec2 pixel, uint32_t sampleIndex,
                                     uint depth) {
  return AlphaCutouts{&scene, scene.cpuCopies().cutouts.data(), scene.textureTables(),
                      pathAlphaRandom(pixel, sampleIndex, depth, scene.params.seed)};
}

AlphaCutouts AlphaCutouts::ofShadowRay(const SceneData& scene, vec2 uLight) {
  return AlphaCutouts{&scene, scene.cpuCopies().cutouts.data(), scene.textureTables(),
                      shadowAlphaRandom(uLight)};
}

bool AlphaCutouts::accept(const void* context, uint32_t triangle, const Hit& hit) {
  const AlphaCutouts& a = *static_cast<const AlphaCutouts*>(context);
  if (a.cutouts == nullptr || ((a.cutouts[triangle / 64] >> (triangle % 64)) & 1u) == 0u) {
    return true;
  }
  const Triangle& tri = a.scene->bvh.triangles[triangle];
  return alphaKeepsHit(a.tables, tri.material, tri.primitive, hit.barycentrics, a.u);
}

Ray cameraRay(const Camera& cam, vec2 filmPoint) {
  return Ray{cam.position, cameraDirection(cam, filmPoint)};
}

bool traceShadowRay(const SceneData& scene, const LightSample& ls, vec2 uLight, uint64_t& rays) {
  ++rays;
  const Intersection test =
      scene.params.fastIntersection != 0u ? Intersection::kFast : Intersection::kWatertight;
  return !occluded(scene, Ray{ls.from, ls.to - ls.from}, test, uLight);
}

void printLightSample(const SceneData& scene, uint depth, const LightSample& ls, float weight) {
  if ((ls.emitter & kEmitterLight) != 0u) {
    std::fprintf(stderr, "cpu depth %u: light sample on analytic light pdf=%g weight=%g\n", depth,
                 ls.lightPdf, weight);
  } else {
    std::fprintf(stderr,
                 "cpu depth %u: light sample on triangle %u (primitive %u) pdf=%g weight=%g\n",
                 depth, ls.emitter, scene.bvh.triangles[ls.emitter].primitive, ls.lightPdf, weight);
  }
}

vec3 sampleRadiance(const SceneData& scene, uvec2 imagePixel, uint32_t sampleIndex, uint64_t& rays,
                    bool debugPrint) {
  if (scene.params.mediaPresent != 0u) {
    return sampleRadianceVolume(scene, imagePixel, sampleIndex, rays, debugPrint);
  }
  return sampleRadianceUntil(scene, imagePixel, sampleIndex, rays, nullptr, debugPrint);
}

vec3 sampleRadianceUntil(const SceneData& scene, uvec2 imagePixel, uint32_t sampleIndex,
                         uint64_t& rays, const PathEnd* end, bool debugPrint) {
  const RenderParams& params = scene.params;
  const PathScene ps = scene.pathScene();  // the arrays path_vertex.h reads
  // The film's pixel, which the random numbers and the camera ray are of: a crop renders its
  // pixels of the whole film's image.
  const uvec2 pixel = imagePixel + uvec2(params.camera.cropX, params.camera.cropY);
  const uint seed = params.seed;
  const bool sobol = params.samplerType == kSamplerSobol;  // else independent random numbers
  const Intersection test =
      params.fastIntersection != 0u ? Intersection::kFast : Intersection::kWatertight;

  // The camera ray through a point of the pixel's filter (and of the lens).
  const CameraSample camera = cameraSampleOf(params.camera, sobol, pixel, sampleIndex, seed);
  Ray ray{camera.origin, camera.direction};
  PathState path = cameraPathState(ps, camera);  // L, beta, etaScale, bsdfPdf, specularBounce
  bool ending = false;                           // `end` has asked: the path's last ray

  for (uint depth = 0;;) {
    // Find the closest surface along the ray.
    ++rays;
    const std::optional<Hit> hit = closestSurface(scene, ray, test, pixel, sampleIndex, depth);
    if (!hit) {
      // The ray leaves the scene: the infinite light's radiance, weighed as an emitter's.
      addEnvironmentFound(ps, path, ray.direction);
      break;
    }
    // The shading point: material (textures resolved), hit point from the barycentrics (more
    // accurate than origin + t * direction), normals, how it scatters.
    const Triangle& tri = scene.bvh.triangles[hit->triangle];
    const SurfacePoint s =
        surfacePointAt(ps, hit->triangle, tri, hit->barycentrics, -ray.direction, path.rd);
    if (debugPrint) {
      std::fprintf(stderr,
                   "cpu depth %u: hit triangle %u (primitive %u) t=%g p=(%g, %g, %g) "
                   "beta=(%g, %g, %g)\n",
                   depth, hit->triangle, tri.primitive, hit->t, s.p.x, s.p.y, s.p.z, path.beta.x,
                   path.beta.y, path.beta.z);
    }

    // Add emitted light found by this ray, weighed against light sampling (MIS).
    addEmissionFound(ps, path, tri, s, hit->t, ray.origin);

    // Stop after maxDepth scattering events (or where `end` asked).
    if (depth == params.maxDepth || ending) break;
    const VertexKey key{pixel, sampleIndex, kDimFirstBounce + kDimsPerBounce * depth};
    ++depth;
    if (end != nullptr) ending = (*end)(s, key, depth, path.beta * camera.weight);
    // This event's random numbers, all four dimensions at once (the shader draws each where
    // it is used: the same numbers).
    const BounceRandom u = bounceRandomSimd(sobol, pixel, sampleIndex, key.dim, seed);

    // Sample direct illumination from an emitter (next-event estimation): a light sample, its
    // shadow ray, its contribution weighed against BSDF sampling (MIS).
    if (samplesLightAt(ps, s)) {
      const LightSample ls = sampleLightAt(ps, s, key, u.lightChoose, u.lightPoint);
      if (ls.found && traceShadowRay(scene, ls, u.lightPoint, rays)) {
        float weight;
        path.L += lightSampleContribution(ps, s, key, ls, path.beta, weight);
        if (debugPrint) printLightSample(scene, depth, ls, weight);
      }
    }

    // Sample the BSDF for the next direction; the lobe choice takes the roulette dimension's
    // second number.
    vec3 wi;
    if (!sampleBsdfAt(ps, s, key, path, u.roulette.y, u.bsdf, wi)) break;
    if (maxComponent(path.beta) <= 0.0f) break;

    // Possibly terminate the path with Russian roulette (unbiased: survivors are scaled).
    if (!survivesRoulette(ps, path, depth, u.roulette.x)) break;

    // Leave the surface on the side of the new direction.
    ray = Ray{nextRayOrigin(s, wi), wi};
  }
  // The camera sample's weight: 1 but for the negative lobes of some filters (filter.h).
  const vec3 L = path.L * camera.weight;
  if (debugPrint) {
    std::fprintf(stderr, "cpu sample %u: L=(%g, %g, %g)\n", sampleIndex, L.x, L.y, L.z);
  }
  return L;
}

CpuRenderStats renderCpu(const SceneData& scene, const CpuRenderOptions& options, Film& film) {
  if (scene.integrator == kIntegratorBdpt) return renderBdpt(scene, options, film);
  if (scene.integrator == kIntegratorSppm) return renderSppm(scene, options, film);
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
      reportTileProgress(options, progressMutex, passIndex, tilesDone.fetch_add(1) + 1, tileCount);
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
  finishCpuRenderStats(options, film, totalRays, start, callStart, stats);
  return stats;
}

void reportTileProgress(const CpuRenderOptions& options, std::mutex& progressMutex, int passIndex,
                        int tilesDone, int tileCount) {
  if (!options.progress) return;
  std::unique_lock lock(progressMutex, std::try_to_lock);
  if (lock.owns_lock()) {
    options.progress((double(passIndex) + double(tilesDone) / double(tileCount)) /
                     double(options.spp));
  }
}

void finishCpuRenderStats(const CpuRenderOptions& options, const Film& film, uint64_t rays,
                          std::chrono::steady_clock::time_point start,
                          std::chrono::steady_clock::time_point callStart, CpuRenderStats& stats) {
  stats.stopped = stats.samplesDone < options.spp;
  if (options.progress && !stats.stopped) options.progress(1.0);
  stats.rays = rays;
  stats.invalidSamples = film.totalInvalid();
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  stats.wallSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - callStart).count();
}

}  // namespace pt
