// The CPU reference's bidirectional path tracer. bdptSample is the outline of pbrt-v4's
// BDPTIntegrator::Li over bdpt_vertex.h's and bdpt_connect.h's steps: the camera subpath, the
// light subpath, then every strategy (s, t) between them, its shadow ray and its MIS weight.
// What is this file's own is how rays are traced (the wide BVH) and how the image is scheduled.
#include "cpu/bdpt.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <utility>
#include <vector>

#include "bdpt_connect.h"
#include "bdpt_sample.h"
#include "bdpt_vertex.h"
#include "bvh/traverse.h"
#include "bvh/workers.h"
#include "common/check.h"
#include "cpu/bounce_random.h"
#include "scene/camera_filter.h"

namespace pt {
namespace {

// Whether something lies on the segment from `from` to `to` (t in [0, 1)), cut-outs passed by
// with the number u.
bool bdptSegmentBlocked(const SceneData& scene, vec3 from, vec3 to, vec2 u) {
  const Ray ray{from, to - from};
  const Intersection test =
      scene.params.fastIntersection != 0u ? Intersection::kFast : Intersection::kWatertight;
  if (!scene.effects.alphaCutouts) return anyHit(scene.wideBvh(), ray, 1.0f, test);
  const AlphaCutouts cutouts = AlphaCutouts::ofShadowRay(scene, u);
  const HitFilter filter = cutouts.filter();
  return anyHit(scene.wideBvh(), ray, 1.0f, test, &filter);
}

// A subpath's random walk from its first vertex (path.count == 1), until it has maxVertices
// vertices, leaves the scene or is absorbed (pbrt-v4's RandomWalk; its steps bdpt_sample.h's
// bdptWalkStep). A camera subpath (radiance) that leaves the scene ends at the infinite light,
// where there is one.
void bdptRandomWalk(const SceneData& scene, const PathScene& ps, BdptPath& path, BdptWalk walk,
                    uint maxVertices, bool radiance, uvec2 pixel, uint32_t sampleIndex,
                    uint64_t& rays) {
  const RenderParams& params = scene.params;
  const bool sobol = params.samplerType == kSamplerSobol;
  const Intersection test =
      params.fastIntersection != 0u ? Intersection::kFast : Intersection::kWatertight;
  while (path.count < maxVertices) {
    const uint k = path.count;
    const VertexKey key{pixel, sampleIndex, radiance ? bdptCameraDim(k) : bdptLightDim(k)};
    // Find the closest surface along the ray.
    ++rays;
    const std::optional<Hit> hit =
        closestSurface(scene, Ray{walk.origin, walk.direction}, test, pixel, sampleIndex, key.dim);
    if (!hit) {
      if (radiance && params.environmentEmitter != kNoEmitter) {
        path.v[path.count++] =
            bdptEnvironmentVertex(ps, walk.origin, walk.direction, walk.beta, walk.pdf, key);
      }
      break;
    }
    const Triangle& tri = scene.bvh.triangles[hit->triangle];
    const SurfacePoint s = surfacePointAt(ps, hit->triangle, tri, hit->barycentrics,
                                          -walk.direction, noRayDifferential());
    const bool last = k + 1u >= maxVertices;
    const BounceRandom u =
        last ? BounceRandom{} : bounceRandomSimd(sobol, pixel, sampleIndex, key.dim, params.seed);
    const bool more = bdptWalkStep(ps, s, tri.emitter, key, last, u.roulette.y, u.bsdf, radiance,
                                   walk, path.v[k - 1u], path.v[k]);
    path.count++;
    if (!more) break;
  }
}

}  // namespace

std::optional<BdptStrategy> parseBdptStrategy(const std::string& text) {
  int s = -1, t = -1;
  char extra = 0;
  if (std::sscanf(text.c_str(), "%d,%d%c", &s, &t, &extra) != 2) return std::nullopt;
  if (s < 0 || t < 1 || (s == 1 && t == 1)) return std::nullopt;
  return BdptStrategy{s, t};
}

void checkBdptScene(const SceneData& scene, const std::string& what,
                    const std::string& integrator) {
  auto refuse = [&](const std::string& why) {
    throw InputError(what + ": the " + integrator + " integrator does not render " + why +
                     " yet (use the path integrator)");
  };
  if (scene.effects.media || scene.params.mediaPresent != 0u) refuse("participating media");
}

uint bdptMaxDepth(const SceneData& scene) {
  return std::min(scene.params.maxDepth, kBdptMaxDepth);
}

float bdptInverseFilterIntegral(const Camera& camera) {
  return static_cast<float>(1.0 / filterIntegral(camera));
}

BdptSplatter::BdptSplatter(const Camera& camera)
    : cam(camera), scale(bdptSplatScale(camera, bdptInverseFilterIntegral(camera))) {}

float bdptSubpaths(const SceneData& scene, uvec2 imagePixel, uint32_t sampleIndex, BdptPath& camera,
                   BdptPath& light, uint64_t& rays) {
  const RenderParams& params = scene.params;
  const uint maxDepth = bdptMaxDepth(scene);
  const PathScene ps = scene.pathScene();
  const uvec2 pixel = imagePixel + uvec2(params.camera.cropX, params.camera.cropY);
  const bool sobol = params.samplerType == kSamplerSobol;
  const BdptStarts starts = bdptStarts(ps, sobol, pixel, sampleIndex, params.seed);

  // The camera subpath: the camera's vertex, then the random walk, up to maxDepth + 2 vertices.
  camera.v[0] = starts.cameraVertex;
  camera.count = 1;
  bdptRandomWalk(scene, ps, camera, starts.cameraWalk, maxDepth + 2u, /*radiance=*/true, pixel,
                 sampleIndex, rays);

  // The light subpath: a light's emission, then the random walk, up to maxDepth + 1 vertices.
  light.count = 0;
  const BdptLightStart& start = starts.light;
  if (start.found) {
    light.v[0] = start.vertex;
    light.count = 1;
    bdptRandomWalk(scene, ps, light, bdptLightWalk(start), maxDepth + 1u, /*radiance=*/false, pixel,
                   sampleIndex, rays);
    bdptCorrectInfiniteStart(ps, light.v[0], light.v[1], light.count, start.pdfPos);
  }
  return starts.camera.weight;
}

void bdptSample(const SceneData& scene, uvec2 imagePixel, uint32_t sampleIndex,
                const BdptStrategy& strategy, uint64_t& rays,
                const std::function<void(const BdptContribution&)>& sink) {
  BdptPath camera;
  BdptPath light;
  const float filterWeight = bdptSubpaths(scene, imagePixel, sampleIndex, camera, light, rays);
  const RenderParams& params = scene.params;
  const PathScene ps = scene.pathScene();
  const uvec2 pixel = imagePixel + uvec2(params.camera.cropX, params.camera.cropY);
  const bool sobol = params.samplerType == kSamplerSobol;
  const uint maxDepth = bdptMaxDepth(scene);

  // Every strategy (s, t) of depth s + t - 2 <= maxDepth: its contribution, shadow ray and
  // MIS weight.
  for (uint t = 1; t <= camera.count; ++t) {
    for (uint s = 0; s <= light.count; ++s) {
      if (!bdptTakesStrategy(s, t, maxDepth, strategy.s, strategy.t)) continue;
      const BdptStrategyRandom u = bdptStrategyRandom(sobol, pixel, sampleIndex, params.seed,
                                                      params.camera.lensRadius, s, t);
      const BdptConnection c = bdptConnect(ps, light, camera, s, t, u.uChoose, u.uLight);
      if (!c.found) continue;
      if (c.visibility) {
        ++rays;
        if (bdptSegmentBlocked(scene, c.from, c.to, u.uLight)) continue;
      }
      BdptContribution out;
      out.s = int(s);
      out.t = int(t);
      out.L = bdptStrategyL(c, t, filterWeight);
      out.weight = bdptStrategyWeight(ps, light, camera, c, s, t, strategy.all());
      out.splat = t == 1;
      out.filmPoint = c.filmPoint;
      sink(out);
    }
  }
}

CpuRenderStats renderBdpt(const SceneData& scene, const CpuRenderOptions& options, Film& film) {
  const BdptStrategy& strategy = options.bdptStrategy;
  const Camera& cam = scene.params.camera;
  PT_CHECK(film.width == int(cam.width) && film.height == int(cam.height));
  const BdptSplatter splatter(cam);
  const auto callStart = std::chrono::steady_clock::now();
  scene.cpuCopies();  // built here on a first render: set-up, not render time
  const auto start = std::chrono::steady_clock::now();
  CpuRenderStats stats;
  stats.threads = options.threads > 0 ? options.threads : availableCpus();

  // Passes of one sample index over the image, as renderCpu's. Within a pass, the workers (one
  // team for the whole render) take tiles through an atomic counter and add their pixels' own
  // samples to the film (each pixel is one tile's); the splats of light tracing, which land
  // anywhere, are kept per tile and added once the pass is done. The film's sums are exact, so the
  // order they are added in changes no bit: the image is the same for every thread count. A stop
  // drops the pass under way: its own samples taken back, its splats never added.
  constexpr int kTile = 8;
  const int tilesX = (film.width + kTile - 1) / kTile;
  const int tilesY = (film.height + kTile - 1) / kTile;
  const int tileCount = tilesX * tilesY;
  struct Splat {
    int x, y;
    vec3 value;
  };
  std::vector<std::vector<Splat>> splats(static_cast<size_t>(tileCount));
  std::vector<vec3> pass(film.pixelCount());
  std::vector<char> traced(static_cast<size_t>(tileCount));
  std::atomic<uint64_t> totalRays{0};
  std::mutex progressMutex;
  Workers workers(stats.threads);

  for (int passIndex = 0; passIndex < options.spp; ++passIndex) {
    if (options.stop && options.stop->load(std::memory_order_relaxed)) break;
    const uint32_t sampleIndex = options.firstSample + uint32_t(passIndex);
    std::atomic<int> nextTile{0};
    std::atomic<int> tilesDone{0};
    std::atomic<bool> dropped{false};
    std::fill(traced.begin(), traced.end(), 0);
    auto worker = [&] {
      uint64_t rays = 0;
      for (int tile; (tile = nextTile.fetch_add(1)) < tileCount;) {
        if (options.stop && options.stop->load(std::memory_order_relaxed)) {
          dropped = true;
          break;
        }
        std::vector<Splat>& tileSplats = splats[size_t(tile)];
        tileSplats.clear();
        const int x0 = (tile % tilesX) * kTile;
        const int y0 = (tile / tilesX) * kTile;
        for (int y = y0; y < std::min(y0 + kTile, film.height); ++y) {
          for (int x = x0; x < std::min(x0 + kTile, film.width); ++x) {
            vec3 L(0.0f);
            bdptSample(scene, uvec2(x, y), sampleIndex, strategy, rays,
                       [&](const BdptContribution& c) {
                         const vec3 value = c.L * c.weight;
                         if (!c.splat) {
                           L += value;
                           return;
                         }
                         splatter.forPixels(c.filmPoint, [&](int sx, int sy, float w) {
                           tileSplats.push_back(Splat{sx, sy, value * w});
                         });
                       });
            pass[size_t(y) * size_t(film.width) + size_t(x)] = L;
            film.add(x, y, L);
          }
        }
        traced[size_t(tile)] = 1;
        reportTileProgress(options, progressMutex, passIndex, tilesDone.fetch_add(1) + 1,
                           tileCount);
      }
      totalRays += rays;
    };
    workers.run([&](int) { worker(); });
    if (dropped) {
      for (int tile = 0; tile < tileCount; ++tile) {
        if (!traced[size_t(tile)]) continue;
        const int x0 = (tile % tilesX) * kTile;
        const int y0 = (tile / tilesX) * kTile;
        for (int y = y0; y < std::min(y0 + kTile, film.height); ++y) {
          for (int x = x0; x < std::min(x0 + kTile, film.width); ++x) {
            film.takeBack(x, y, pass[size_t(y) * size_t(film.width) + size_t(x)]);
          }
        }
      }
      break;
    }
    for (const std::vector<Splat>& tileSplats : splats) {
      for (const Splat& s : tileSplats) film.addSplat(s.x, s.y, s.value);
    }
    stats.samplesDone = passIndex + 1;
    if (options.checkpoint) options.checkpoint(stats.samplesDone);
  }
  finishCpuRenderStats(options, film, totalRays, start, callStart, stats);
  return stats;
}

}  // namespace pt
