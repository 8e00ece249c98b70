// Ray benchmark (not a test; tools/performance.sh runs it for docs/performance.md): fixed ray
// sets per scene, traced by every traversal backend, timed by Google Benchmark.
//
// Ray sets, made once per scene from the renderer's own scene data (configs/*.json through
// prepareScene, or the generated sphere) and its random numbers (sample 0, independent):
//   primary  one camera ray per pixel of a size x size film, jittered in the pixel (closest
//            hit; coherent);
//   bounce   from every primary hit, a cosine-weighted direction about the surface normal,
//            from the offset origin the integrator uses (closest hit; incoherent);
//   shadow   from every primary hit to a point on an emitter picked from the alias table, as
//            the integrator's next-event estimation traces them, when both sides face each
//            other (any hit, t in (0, 1)).
// Backends (kBackends below): our CPU traversal over the renderer's BVH (binary, and the
// 8-wide tree collapsed from it that the CPU renderer uses), the GPU ray-query
// shader on the chosen Vulkan device (host/vulkan/raycast.h), and Embree 3 (rtcIntersect1 and
// rtcOccluded1 over Embree's own BVH) where it was found at build time.
//
// Before timing, an agreement check traces every set once per backend and counts, for every
// pair of backends and against a double-precision brute force (on every ray, or on an evenly
// spread subset sized to --brute-budget), the rays whose closest hits differ (one misses, or
// the distances differ by more than 1e-5 relative: see sameClosest) or whose occlusion
// differs.
#include <benchmark/benchmark.h>
#include <sched.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <tuple>
#include <vector>

#include "bench_util.h"
#include "bvh/traverse.h"
#include "common/check.h"
#include "cpu/integrator.h"
#include "render/prepare.h"
#include "scene/scene.h"
#include "vulkan/context.h"
#include "vulkan/raycast.h"
#ifdef PT_HAVE_EMBREE
#include "embree_scene.h"
#include "scene/load_scene.h"
#include "scene/reader_helpers.h"
#endif

namespace pt {
namespace {

using bench::Clock;
using bench::secondsSince;

// ---- Options -------------------------------------------------------------------------------

struct Options {
  std::vector<std::string> scenes{"cornell-box", "bunny-box", "sphere", "bunny-dragon"};
  std::string configDir = PT_SOURCE_DIR "/configs";
  std::vector<std::string> backends;  // empty: every backend built in
  int size = 256;                     // primary rays: one per pixel of a size x size film
  int threads = 0;                    // CPU backends; 0: every CPU this process may run on
  std::string device;                 // Vulkan device: index or part of the name
  std::string builder{nameOf(kBuilderNames, kDefaultBuilder)};
  int leafSize = kDefaultLeafSizeCpu;   // the CPU renderer's tree, for every backend
  double minTime = 0.5;                 // Google Benchmark: least seconds per repetition
  int repetitions = 3;                  // the summary takes the median over these
  size_t gpuMinRays = size_t(1) << 20;  // see RayQueryBackend
  double bruteBudget = 2e8;             // triangle tests per ray set for the brute force
  bool embreeRobust = false;            // RTC_SCENE_FLAG_ROBUST instead of Embree's default
  std::string embreeConfig;             // rtcNewDevice's string, e.g. "verbose=2"
  bool checkOnly = false;
  bool requireAgreement = false;
  std::string csv, agreementCsv;
  std::string exportEmbree;  // prefix: write the first scene for Embree's tutorials and stop
};

// The CPUs this process may run on (what taskset, Slurm or a container allot).
int availableCpus() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof(set), &set) == 0 && CPU_COUNT(&set) > 0) return CPU_COUNT(&set);
  return int(std::max(1u, std::thread::hardware_concurrency()));
}

// Runs f(begin, end) over [0, n) in chunks handed out to `threads` threads through an atomic
// counter: rays differ in cost, so a static split would leave threads idle. The calling thread
// only waits. When it traced too, about 4 in 10 processes ran every backend (Embree's as well)
// at half speed with two threads, slower than with one, depending on where the process's
// memory landed (always slow or always fast with address-space randomisation off, by
// binary); with the work on new threads only, 16 of 16 processes ran at full speed.
template <class F>
void parallelChunks(size_t n, int threads, const F& f) {
  constexpr size_t kChunk = 256;
  if (threads <= 1 || n <= kChunk) {
    f(size_t(0), n);
    return;
  }
  std::atomic<size_t> next{0};
  auto work = [&] {
    for (size_t begin; (begin = next.fetch_add(kChunk)) < n;) f(begin, std::min(n, begin + kChunk));
  };
  std::vector<std::thread> pool;
  for (int i = 0; i < threads; ++i) pool.emplace_back(work);
  for (std::thread& t : pool) t.join();
}

// ---- Scenes and ray sets ---------------------------------------------------------------------

struct BenchScene {
  std::string name;
  std::string description;
  SceneData data;                    // the BVH as the renderer builds it, emitters, camera
  std::vector<Triangle> sceneOrder;  // the same triangles by Triangle::primitive
};

struct RaySet {
  std::string type;  // primary, bounce, shadow
  std::vector<Ray> rays;
  bool anyHit = false;
  float tMax = INFINITY;
};

// The 1.05M-triangle UV sphere with a camera and a light, so that it has all three ray sets:
// the camera looks at it from 3.4 radii (it fills most of the film, the corners miss), and a
// one-sided 1 x 1 emitter above and in front of it, out of the camera's view, takes the
// shadow rays. Convex, so shadow rays from the lit side are rarely occluded: they measure
// traversal that must prove there is no hit.
Scene sphereScene() {
  Scene scene;
  scene.camera.position = vec3(0.0f, 0.0f, -3.4f);
  scene.camera.target = vec3(0.0f);
  scene.camera.vfovDegrees = 45.0f;
  scene.materials = {defaultMaterial(kMaterialDiffuse), defaultMaterial(kMaterialDiffuse)};
  scene.materials[0].reflectance = vec3(0.8f);
  scene.materials[1].reflectance = vec3(0.0f);
  scene.materials[1].emission = vec3(10.0f);
  scene.materialNames = {"white", "light"};
  scene.triangles = bench::uvSphere(726, 725, 0);
  // Wound so that the geometric normal, cross(v1 - v0, v2 - v0), points down: the lit side.
  const vec3 a(0.5f, 2.5f, -2.0f), b(1.5f, 2.5f, -2.0f), c(1.5f, 2.5f, -1.0f), d(0.5f, 2.5f, -1.0f);
  for (const auto& [p, q, r] : {std::tuple{a, b, c}, std::tuple{a, c, d}}) {
    scene.triangles.push_back(Triangle{p, 1, q, kNoEmitter, r, uint(scene.triangles.size())});
  }
  return scene;
}

std::optional<BenchScene> loadBenchScene(const std::string& name, const Options& o) {
  Scene scene;
  std::string description;
  if (name == "sphere") {
    scene = sphereScene();
    description = "UV sphere 726 x 725 and a light";
  } else {
    const std::filesystem::path file = std::filesystem::path(o.configDir) / (name + ".json");
    if (!std::filesystem::exists(file)) {
      std::printf("%s: skipped (no %s)\n", name.c_str(), file.c_str());
      return std::nullopt;
    }
    try {
      scene = loadScene(file);
    } catch (const std::exception& e) {  // e.g. a mesh it names is missing
      std::printf("%s: skipped (%s)\n", name.c_str(), e.what());
      return std::nullopt;
    }
    description = file.filename().string();
  }
  RenderSettings settings;
  settings.width = settings.height = o.size;
  settings.maxLeafSize = o.leafSize;
  settings.builder = *valueNamed(kBuilderNames, o.builder);  // checked by the command line
  BenchScene bench{name, description, prepareScene(std::move(scene), settings), {}};
  bench.sceneOrder.resize(bench.data.bvh.triangles.size());
  for (const Triangle& t : bench.data.bvh.triangles) bench.sceneOrder[t.primitive] = t;
  return bench;
}

std::vector<RaySet> makeRaySets(const SceneData& scene) {
  const Bvh& bvh = scene.bvh;
  const Camera& cam = scene.params.camera;
  const uint seed = scene.params.seed;
  constexpr bool kSobol = false;  // independent numbers: no structure shared between sets
  constexpr uint32_t kSample = 0;
  RaySet primary{"primary", {}, false, INFINITY}, bounce{"bounce", {}, false, INFINITY};
  RaySet shadow{"shadow", {}, true, 1.0f};
  for (uint y = 0; y < cam.height; ++y) {
    for (uint x = 0; x < cam.width; ++x) {
      const uvec2 pixel(x, y);
      const Ray ray =
          cameraRay(cam, vec2(pixel) + random2(kSobol, pixel, kSample, kDimPixel, seed));
      primary.rays.push_back(ray);
      const std::optional<Hit> hit = closestHit(bvh, ray);
      if (!hit) continue;
      // The integrator's first vertex (host/cpu/integrator.cpp).
      const Triangle& tri = bvh.triangles[hit->triangle];
      const vec3 p = hit->barycentrics.x * tri.v0 + hit->barycentrics.y * tri.v1 +
                     hit->barycentrics.z * tri.v2;
      const vec3 ng = normalize(cross(tri.v1 - tri.v0, tri.v2 - tri.v0));
      const vec3 n = dot(ng, -ray.direction) >= 0.0f ? ng : -ng;
      const float magnitude = triangleMagnitude(tri.v0, tri.v1, tri.v2);
      const uint dim = kDimFirstBounce;
      const vec3 wi = localToWorld(
          sampleCosineHemisphere(random2(kSobol, pixel, kSample, dim + kDimBsdf, seed)), n);
      bounce.rays.push_back(Ray{offsetRayOrigin(p, n, magnitude), wi});
      if (scene.emitters.empty()) continue;
      const vec2 uChoose = random2(kSobol, pixel, kSample, dim + kDimLightChoose, seed);
      const vec2 uLight = random2(kSobol, pixel, kSample, dim + kDimLightPoint, seed);
      const uint slot = aliasTableSlot(uChoose.x, scene.params.emitterCount);
      const Emitter& e = scene.emitters[aliasTablePick(slot, scene.emitters[slot], uChoose.y)];
      const Triangle& light = bvh.triangles[e.triangle];
      const vec2 b = sampleTriangleBarycentrics(uLight);
      const vec3 lightPoint = (1.0f - b.x - b.y) * light.v0 + b.x * light.v1 + b.y * light.v2;
      const vec3 lightNormal = normalize(cross(light.v1 - light.v0, light.v2 - light.v0));
      const vec3 toLight = lightPoint - p;
      if (!(dot(lightNormal, toLight) < 0.0f && dot(n, toLight) > 0.0f)) continue;
      const vec3 from = offsetRayOrigin(p, n, magnitude);
      const vec3 to =
          offsetRayOrigin(lightPoint, lightNormal, triangleMagnitude(light.v0, light.v1, light.v2));
      shadow.rays.push_back(Ray{from, to - from});
    }
  }
  std::vector<RaySet> sets;
  for (RaySet* s : {&primary, &bounce, &shadow}) {
    if (!s->rays.empty()) sets.push_back(std::move(*s));
  }
  return sets;
}

// ---- Backends --------------------------------------------------------------------------------

// A closest hit: the distance in units of |direction| and the triangle's index in scene
// order (Triangle::primitive, Embree's primID), or a miss.
struct HitRecord {
  float t = INFINITY;
  uint32_t primitive = kMiss;
  static constexpr uint32_t kMiss = 0xFFFFFFFFu;
  bool missed() const { return primitive == kMiss; }
};

// One traversal backend, set up for one scene. Adding a backend: a line in kBackends and a
// function that sets it up, usually one of: treeBackend (a CPU tree with closestHit / anyHit
// overloads, e.g. a wide BVH built from scene.data.bvh), perRayBackend (any two per-ray
// functions), RayQueryBackend (a GPU call on a batch of RayQuery).
class TraversalBackend {
 public:
  virtual ~TraversalBackend() = default;
  // The closest hit with t > 0 of every ray (hits is resized to rays.size()).
  virtual void closest(const std::vector<Ray>& rays, std::vector<HitRecord>& hits) = 0;
  // Whether anything lies on each ray with 0 < t < tMax (occluded is resized likewise).
  virtual void any(const std::vector<Ray>& rays, float tMax, std::vector<uint8_t>& occluded) = 0;

  // Called once after the agreement check, before the timed runs.
  virtual void prepareForTiming() {}
  // Rays traced by one call on n rays (a backend may trace copies of a small batch).
  virtual size_t raysPerCall(size_t n) const { return n; }
  // Seconds of the last call that were tracing, for backends that time their own tracing (the
  // GPU's dispatch, without the set-up and copies around it); none: the wall time of the call.
  virtual std::optional<double> lastTraceSeconds() const { return std::nullopt; }
  // Rays of the last call that the backend gave up on (lavapipe's loop cap).
  virtual uint64_t lastTruncated() const { return 0; }
};

template <class Closest, class Any>
class PerRayBackend : public TraversalBackend {
 public:
  PerRayBackend(int threads, Closest closest, Any any)
      : threads_(threads), closest_(std::move(closest)), any_(std::move(any)) {}
  void closest(const std::vector<Ray>& rays, std::vector<HitRecord>& hits) override {
    hits.resize(rays.size());
    parallelChunks(rays.size(), threads_, [&](size_t begin, size_t end) {
      for (size_t i = begin; i < end; ++i) hits[i] = closest_(rays[i]);
    });
  }
  void any(const std::vector<Ray>& rays, float tMax, std::vector<uint8_t>& occluded) override {
    occluded.resize(rays.size());
    parallelChunks(rays.size(), threads_, [&](size_t begin, size_t end) {
      for (size_t i = begin; i < end; ++i) occluded[i] = any_(rays[i], tMax) ? 1 : 0;
    });
  }

 private:
  int threads_;
  Closest closest_;  // HitRecord(const Ray&)
  Any any_;          // bool(const Ray&, float tMax)
};

// A CPU backend from two per-ray functions, each ray traced on one thread, the batch spread
// over --threads threads. Templated so that the calls inline (no std::function per ray).
template <class Closest, class Any>
std::unique_ptr<TraversalBackend> perRayBackend(int threads, Closest closest, Any any) {
  return std::make_unique<PerRayBackend<Closest, Any>>(threads, std::move(closest), std::move(any));
}

// Our traversal over a tree with closestHit / anyHit overloads (traverse.h: a hit names its
// triangle's place in scene order, Hit::primitive), held alive by the backend.
template <class Tree>
std::unique_ptr<TraversalBackend> treeBackend(std::shared_ptr<const Tree> tree, int threads) {
  return perRayBackend(
      threads,
      [tree](const Ray& ray) {
        // The hit's primitive comes from the leaf, as Embree's primID does (no lookup).
        const std::optional<Hit> hit = closestHit(*tree, ray);
        return hit ? HitRecord{hit->t, hit->primitive} : HitRecord{};
      },
      [tree](const Ray& ray, float tMax) { return anyHit(*tree, ray, tMax); });
}

std::unique_ptr<TraversalBackend> makeCpuBackend(const BenchScene& scene, const Options& o) {
  // The scene owns the tree: a shared_ptr that does not own it.
  const std::shared_ptr<const Bvh> tree(std::shared_ptr<const void>(), &scene.data.bvh);
  return treeBackend(tree, o.threads);
}

// One line on the wide tree's shape and its SAH cost in the form Embree's statistics print
// (`--embree-config verbose=2`): the sum over nodes of area / root area (each node costs 1),
// plus the sum over leaves of area / root area times its packets of four (each costs 1).
std::string wideTreeSummary(const WideBvh& wide) {
  auto area = [](vec3 lo, vec3 hi) {
    const vec3 e = hi - lo;
    return double(e.x) * e.y + double(e.y) * e.z + double(e.z) * e.x;
  };
  const double root = area(wide.rootMin, wide.rootMax);
  double nodeCost = root, leafCost = 0.0;
  size_t lanes = 0, leaves = 0;
  for (const WideNode& node : wide.nodes) {
    for (int i = 0; i < kWideLanes; ++i) {
      if (node.child[i] == kWideEmpty) continue;
      ++lanes;
      const double a = area(vec3(node.bounds[0][i], node.bounds[1][i], node.bounds[2][i]),
                            vec3(node.bounds[3][i], node.bounds[4][i], node.bounds[5][i]));
      if (node.child[i] & kWideLeaf) {
        ++leaves;
        leafCost += a * node.packetCount[i];
      } else {
        nodeCost += a;
      }
    }
  }
  char s[256];
  std::snprintf(s, sizeof s,
                "%zu nodes (%.2f lanes in use), %zu leaves, %zu packets; SAH cost %.2f (nodes) + "
                "%.2f (packets)",
                wide.nodes.size(), double(lanes) / double(wide.nodes.size()), leaves,
                wide.packets.size(), nodeCost / root, leafCost / root);
  return s;
}

// The wide tree the CPU renderer traverses (wide_bvh.h), collapsed from the same BVH.
std::unique_ptr<TraversalBackend> makeWideBackend(const BenchScene& scene, const Options& o) {
  const std::shared_ptr<const WideBvh> tree(std::shared_ptr<const void>(), &scene.data.wideBvh());
  std::printf("cpu-wide: %s\n", wideTreeSummary(*tree).c_str());
  return treeBackend(tree, o.threads);
}

// A GPU backend that traces a whole batch of RayQuery in one call of `trace` (results in
// Bvh::triangles indices), such as traceRaysVulkan, which sets up a Vulkan context, compiles
// the shader, uploads the BVH and the rays, dispatches and reads the results back, on every
// call. What is timed is the dispatch alone (RaycastStats::deviceSeconds, from timestamp
// queries: reading the rays from device memory, tracing, writing the hits), and a batch
// smaller than --gpu-min-rays is traced as that many copies of itself, enough rays to fill a
// GPU. The agreement check traces each batch once, without copies.
class RayQueryBackend : public TraversalBackend {
 public:
  using Trace = std::function<std::vector<RayResult>(const std::vector<RayQuery>&, RaycastStats&)>;
  RayQueryBackend(std::string name, const Bvh& bvh, size_t minRays, Trace trace)
      : name_(std::move(name)), bvh_(bvh), minRays_(minRays), trace_(std::move(trace)) {}

  void closest(const std::vector<Ray>& rays, std::vector<HitRecord>& hits) override {
    const std::vector<RayResult> results = trace(rays, INFINITY, false);
    hits.resize(rays.size());
    for (size_t i = 0; i < rays.size(); ++i) {
      hits[i] = results[i].found != 0u
                    ? HitRecord{results[i].t, bvh_.triangles[results[i].triangle].primitive}
                    : HitRecord{};
    }
  }
  void any(const std::vector<Ray>& rays, float tMax, std::vector<uint8_t>& occluded) override {
    const std::vector<RayResult> results = trace(rays, tMax, true);
    occluded.resize(rays.size());
    for (size_t i = 0; i < rays.size(); ++i) occluded[i] = results[i].found != 0u ? 1 : 0;
  }

  void prepareForTiming() override { timing_ = true; }
  size_t raysPerCall(size_t n) const override { return n * copies(n); }
  std::optional<double> lastTraceSeconds() const override { return lastDispatch_; }
  uint64_t lastTruncated() const override { return truncated_; }

 private:
  size_t copies(size_t n) const {
    return timing_ && n > 0 && n < minRays_ ? (minRays_ + n - 1) / n : 1;
  }
  std::vector<RayResult> trace(const std::vector<Ray>& rays, float tMax, bool anyHit) {
    const size_t k = copies(rays.size());
    std::vector<RayQuery> queries;
    queries.reserve(rays.size() * k);
    for (size_t c = 0; c < k; ++c) {
      for (const Ray& r : rays) queries.push_back(RayQuery{r.origin, tMax, r.direction, anyHit});
    }
    RaycastStats stats;
    std::vector<RayResult> results = trace_(queries, stats);
    lastDispatch_ = stats.deviceSeconds;
    truncated_ = stats.truncated;
    return results;
  }

  std::string name_;
  const Bvh& bvh_;
  size_t minRays_;
  Trace trace_;
  bool timing_ = false;
  double lastDispatch_ = 0.0;
  uint64_t truncated_ = 0;
};

std::unique_ptr<TraversalBackend> makeVulkanBackend(const BenchScene& scene, const Options& o) {
  return std::make_unique<RayQueryBackend>(
      "vulkan", scene.data.bvh, o.gpuMinRays,
      [&bvh = scene.data.bvh, options = ContextOptions{.device = o.device}](
          const std::vector<RayQuery>& queries, RaycastStats& stats) {
        return traceRaysVulkan(bvh, queries, options, &stats);
      });
}

#ifdef PT_HAVE_EMBREE
// Embree 3 with its own BVH over the scene-order triangles (bench/embree_scene.h), one ray per
// rtcIntersect1 / rtcOccluded1 call. Rays start at t = 0 as ours do (Embree's tnear is
// inclusive, ours exclusive: equal in practice). Shadow rays end one float short of tMax,
// since Embree's tfar is inclusive and our tMax exclusive.
struct EmbreeScene {
  explicit EmbreeScene(const std::string& config)
      : device(config.empty() ? nullptr : config.c_str()) {}
  bench::EmbreeDevice device;
  RTCScene scene = nullptr;
  ~EmbreeScene() {
    if (scene) rtcReleaseScene(scene);
  }
};

std::unique_ptr<TraversalBackend> makeEmbreeBackend(const BenchScene& scene, const Options& o) {
  auto embree = std::make_shared<EmbreeScene>(o.embreeConfig);
  embree->scene =
      bench::newEmbreeScene(embree->device.get(), scene.sceneOrder,
                            o.embreeRobust ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE);
  auto setRay = [](RTCRay& r, const Ray& ray, float tfar) {
    r.org_x = ray.origin.x;
    r.org_y = ray.origin.y;
    r.org_z = ray.origin.z;
    r.tnear = 0.0f;
    r.dir_x = ray.direction.x;
    r.dir_y = ray.direction.y;
    r.dir_z = ray.direction.z;
    r.time = 0.0f;
    r.tfar = tfar;
    r.mask = 0xFFFFFFFFu;
    r.id = 0;
    r.flags = 0;
  };
  // The lambdas hold the scene alive (shared_ptr) and read its handle from a copy.
  return perRayBackend(
      o.threads,
      [embree, s = embree->scene, setRay](const Ray& ray) {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        RTCRayHit rh;
        setRay(rh.ray, ray, INFINITY);
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(s, &context, &rh);
        return rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? HitRecord{}
                                                        : HitRecord{rh.ray.tfar, rh.hit.primID};
      },
      [embree, s = embree->scene, setRay](const Ray& ray, float tMax) {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        RTCRay r;
        setRay(r, ray, std::nextafter(tMax, 0.0f));
        rtcOccluded1(s, &context, &r);
        return r.tfar < 0.0f;  // Embree sets tfar to -inf when it finds a hit
      });
}
#endif

// The backends, in the order of the tables; "embree" is the reference of the ratios.
struct BackendEntry {
  const char* name;
  const char* description;
  // Sets the backend up for a scene (acceleration structure built; not timed). Throws when
  // it cannot run here (NoDeviceError: no Vulkan device), and the backend is skipped.
  std::function<std::unique_ptr<TraversalBackend>(const BenchScene&, const Options&)> make;
};

const std::vector<BackendEntry> kBackends = {
    {"cpu", "CPU binary traversal (host/bvh/traverse.h) over the renderer's BVH", makeCpuBackend},
    {"cpu-wide", "CPU 8-wide SIMD traversal (host/bvh/wide_bvh.h), what the CPU renderer uses",
     makeWideBackend},
    {"vulkan", "GPU ray-query shader (shaders/raycast.comp) via traceRaysVulkan",
     makeVulkanBackend},
#ifdef PT_HAVE_EMBREE
    {"embree", "Embree 3 rtcIntersect1 / rtcOccluded1, Embree's own BVH", makeEmbreeBackend},
#endif
};
constexpr const char* kReference = "embree";

// ---- Brute force and the agreement check -------------------------------------------------------

// Every triangle against the ray in double precision (Moller and Trumbore 1997), shared by
// none of the backends: with 53-bit arithmetic the only misjudged rays are those within about
// 1e-16 of an edge.
struct BruteForce {
  const std::vector<Triangle>& triangles;

  // The nearest t > 0 (and below tMax), or a miss; stops at the first hit when anyHit.
  HitRecord trace(const Ray& ray, double tMax, bool anyHit) const {
    const dvec3 o(ray.origin), d(ray.direction);
    HitRecord best;
    double bestT = tMax;
    for (const Triangle& tri : triangles) {
      const dvec3 v0(tri.v0), e1 = dvec3(tri.v1) - v0, e2 = dvec3(tri.v2) - v0;
      const dvec3 pv = cross(d, e2);
      const double det = dot(e1, pv);
      if (det == 0.0) continue;
      const double inv = 1.0 / det;
      const dvec3 tv = o - v0;
      const double u = dot(tv, pv) * inv;
      if (u < 0.0 || u > 1.0) continue;
      const dvec3 qv = cross(tv, e1);
      const double v = dot(d, qv) * inv;
      if (v < 0.0 || u + v > 1.0) continue;
      const double t = dot(e2, qv) * inv;
      if (!(t > 0.0 && t < bestT)) continue;
      bestT = t;
      best = HitRecord{float(t), tri.primitive};
      if (anyHit) break;
    }
    return best;
  }
};

struct Comparison {
  std::string a, b;
  size_t compared = 0, differ = 0;
  std::vector<std::string> examples;  // the first few differences, spelled out
};

// Two closest hits agree when both miss, or when their distances agree to 1e-5 relative to
// the larger of the distance and the largest coordinate of the ray's origin (times |direction|
// to make it a distance): a hit computed in float is only as exact as the coordinates it is
// computed from, so a short ray in a corner of the Cornell box (coordinates near 550) cannot
// be held to 1e-5 of its own length.
bool sameClosest(const Ray& ray, const HitRecord& a, const HitRecord& b) {
  if (a.missed() || b.missed()) return a.missed() == b.missed();
  const vec3 o = abs(ray.origin);
  const float scale = std::max({a.t, b.t, std::max({o.x, o.y, o.z}) / length(ray.direction)});
  return std::abs(a.t - b.t) <= 1e-5f * scale;
}

std::string describe(const HitRecord& h, bool anyHit) {
  if (anyHit) return h.missed() ? "clear" : "occluded";
  if (h.missed()) return "miss";
  char s[64];
  std::snprintf(s, sizeof s, "t=%.9g tri %u", double(h.t), h.primitive);
  return s;
}

// What one backend found for one ray set (closest hits, or occlusion as a hit or a miss).
struct Outcome {
  std::string backend;
  std::vector<HitRecord> hits;
  std::vector<uint32_t> subset;  // brute force only: the rays it traced (indices), else empty
  uint64_t truncated = 0;
};

// Counts the rays on which a and b differ (b may be the brute force, on its subset) and spells
// out the first three.
Comparison compare(const RaySet& set, const Outcome& a, const Outcome& b, const BruteForce& brute) {
  Comparison c{a.backend, b.backend, 0, 0, {}};
  auto check = [&](size_t ia, size_t ib, size_t ray) {
    ++c.compared;
    const HitRecord& ha = a.hits[ia];
    const HitRecord& hb = b.hits[ib];
    const bool same = set.anyHit ? ha.missed() == hb.missed() : sameClosest(set.rays[ray], ha, hb);
    if (same) return;
    ++c.differ;
    if (c.examples.size() < 3) {
      const Ray& r = set.rays[ray];
      char s[320];
      // Against another backend, the brute force's answer says which of the two was right.
      const bool withTruth = b.subset.empty();
      const HitRecord truth = withTruth ? brute.trace(r, set.tMax, set.anyHit) : HitRecord{};
      std::snprintf(s, sizeof s, "ray %zu (o=%.9g %.9g %.9g d=%.9g %.9g %.9g): %s %s, %s %s%s%s",
                    ray, double(r.origin.x), double(r.origin.y), double(r.origin.z),
                    double(r.direction.x), double(r.direction.y), double(r.direction.z),
                    a.backend.c_str(), describe(ha, set.anyHit).c_str(), b.backend.c_str(),
                    describe(hb, set.anyHit).c_str(), withTruth ? "; brute " : "",
                    withTruth ? describe(truth, set.anyHit).c_str() : "");
      c.examples.push_back(s);
    }
  };
  if (!b.subset.empty()) {  // b is the brute force
    for (size_t j = 0; j < b.subset.size(); ++j) check(b.subset[j], j, b.subset[j]);
  } else {
    for (size_t i = 0; i < set.rays.size(); ++i) check(i, i, i);
  }
  return c;
}

// ---- Timing ------------------------------------------------------------------------------------

// Collects every repetition's rate (rays per second of the benchmark's own time per iteration)
// while Google Benchmark prints its usual table.
class RateReporter : public benchmark::ConsoleReporter {
 public:
  // Colours only on a terminal (the base class's default would put escapes in a log).
  RateReporter() : ConsoleReporter(isatty(fileno(stdout)) ? OO_ColorTabular : OO_Tabular) {}
  std::map<std::string, std::vector<double>> rates;  // by benchmark name
  void ReportRuns(const std::vector<Run>& runs) override {
    benchmark::ConsoleReporter::ReportRuns(runs);
    for (const Run& run : runs) {
      if (run.run_type != Run::RT_Iteration || run.error_occurred || run.iterations == 0) continue;
      const auto rays = run.counters.find("rays");
      if (rays == run.counters.end()) continue;
      const double secondsPerIteration = run.real_accumulated_time / double(run.iterations);
      rates[run.run_name.function_name].push_back(rays->second.value / secondsPerIteration);
    }
  }
};

struct SummaryRow {
  std::string scene, type;
  size_t triangles = 0, rays = 0;
  std::map<std::string, double> mraysPerSecond;  // by backend: median over repetitions
};

// One timed benchmark: the set traced by the backend once per iteration; the iteration's time
// is the backend's own tracing time where it has one (Vulkan), else the call's wall time.
void traceBenchmark(benchmark::State& state, TraversalBackend& backend, const RaySet& set) {
  std::vector<HitRecord> hits;
  std::vector<uint8_t> occluded;
  for (auto _ : state) {
    const auto start = Clock::now();
    try {
      if (set.anyHit) {
        backend.any(set.rays, set.tMax, occluded);
      } else {
        backend.closest(set.rays, hits);
      }
    } catch (const std::exception& e) {  // e.g. the device lost: this one fails, not the run
      state.SkipWithError(e.what());
      break;
    }
    const double wall = secondsSince(start);
    state.SetIterationTime(backend.lastTraceSeconds().value_or(wall));
  }
  const double rays = double(backend.raysPerCall(set.rays.size()));
  state.counters["rays"] = rays;  // per iteration: what RateReporter reads
  state.counters["rays/s"] =
      benchmark::Counter(rays * double(state.iterations()), benchmark::Counter::kIsRate);
}

void timeScene(const BenchScene& scene, const std::vector<RaySet>& sets,
               std::vector<std::pair<std::string, std::unique_ptr<TraversalBackend>>>& backends,
               const Options& o, std::vector<SummaryRow>& summary) {
  for (auto& [name, backend] : backends) backend->prepareForTiming();
  for (const RaySet& set : sets) {
    for (auto& [name, backend] : backends) {
      benchmark::RegisterBenchmark((scene.name + "/" + set.type + "/" + name).c_str(),
                                   traceBenchmark, std::ref(*backend), std::cref(set))
          ->UseManualTime()
          ->MinTime(o.minTime)
          ->Repetitions(o.repetitions)
          ->Unit(benchmark::kMillisecond);
    }
  }
  RateReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::ClearRegisteredBenchmarks();
  for (const RaySet& set : sets) {
    SummaryRow row{scene.name, set.type, scene.sceneOrder.size(), set.rays.size(), {}};
    for (auto& [name, backend] : backends) {
      const auto it = reporter.rates.find(scene.name + "/" + set.type + "/" + name);
      if (it != reporter.rates.end() && !it->second.empty()) {
        row.mraysPerSecond[name] = bench::median(it->second) * 1e-6;
      }
    }
    summary.push_back(row);
  }
}

// ---- Export for Embree's tutorials -----------------------------------------------------------

// Writes PREFIX.obj / PREFIX.mtl (every triangle, Kd = the material's reflectance, emitters
// black) and PREFIX.ecs, a command-line file for Embree's tutorials (pathtracer -c PREFIX.ecs):
// the scene, the camera, and a point light standing in for the emitters. Embree's path
// tracer samples only its light list (point, directional, ambient; its area lights are not
// implemented in the tutorial scene code), so the emitters become one point light at their
// area-weighted centroid, just off the surface on the emitting side, with the emitters'
// intensity along their normal (sum of area x radiance); the brightness does not change the
// work, only one shadow ray per vertex, as ours.
void exportForEmbree(const BenchScene& scene, const std::string& prefix) {
  const std::filesystem::path base(prefix);
  const std::string stem = base.filename().string();
  std::ofstream mtl(prefix + ".mtl"), obj(prefix + ".obj"), ecs(prefix + ".ecs");
  PT_CHECK(mtl && obj && ecs, "cannot write " + prefix + ".{obj,mtl,ecs}");
  const std::vector<Material>& materials = scene.data.materials;
  for (size_t m = 0; m < materials.size(); ++m) {
    const vec3 kd = materials[m].reflectance;
    mtl << "newmtl m" << m << "\nKd " << kd.x << ' ' << kd.y << ' ' << kd.z << "\nKs 0 0 0\n";
  }
  obj << "# " << scene.description << ", as ray_bench --export-embree wrote it\nmtllib " << stem
      << ".mtl\n";
  obj.precision(9);
  uint32_t current = ~0u;
  vec3 centroid(0.0f), normal(0.0f), intensity(0.0f);
  double area = 0.0;
  for (size_t i = 0; i < scene.sceneOrder.size(); ++i) {
    const Triangle& t = scene.sceneOrder[i];
    if (t.material != current) obj << "usemtl m" << (current = t.material) << '\n';
    for (const vec3& v : {t.v0, t.v1, t.v2}) obj << "v " << v.x << ' ' << v.y << ' ' << v.z << '\n';
    obj << "f " << 3 * i + 1 << ' ' << 3 * i + 2 << ' ' << 3 * i + 3 << '\n';
    if (t.emitter == kNoEmitter) continue;
    const vec3 c = cross(t.v1 - t.v0, t.v2 - t.v0);
    const float a = 0.5f * length(c);
    centroid += a * (t.v0 + t.v1 + t.v2) / 3.0f;
    normal += c;
    intensity += a * materials[t.material].emission;
    area += a;
  }
  const Camera& cam = scene.data.params.camera;
  const vec3 target = cam.position + cam.forward;
  const double fov = 2.0 * std::atan(double(cam.tanHalfFovY)) * 180.0 / kPi;
  ecs.precision(9);
  ecs << "-i " << stem << ".obj\n";
  if (area > 0.0) {
    vec3 lo(INFINITY), hi(-INFINITY);
    for (const Triangle& t : scene.sceneOrder) {
      lo = min(lo, min(t.v0, min(t.v1, t.v2)));
      hi = max(hi, max(t.v0, max(t.v1, t.v2)));
    }
    const vec3 p = centroid / float(area) + 1e-3f * length(hi - lo) * normalize(normal);
    ecs << "-pointlight " << p.x << ' ' << p.y << ' ' << p.z << ' ' << intensity.x << ' '
        << intensity.y << ' ' << intensity.z << '\n';
  }
  ecs << "-vp " << cam.position.x << ' ' << cam.position.y << ' ' << cam.position.z << " -vi "
      << target.x << ' ' << target.y << ' ' << target.z << " -vu " << cam.up.x << ' ' << cam.up.y
      << ' ' << cam.up.z << " -fov " << fov << '\n'
      << "--size " << cam.width << ' ' << cam.height << '\n';
  std::printf("wrote %s.obj, %s.mtl, %s.ecs (%zu triangles)\n", prefix.c_str(), prefix.c_str(),
              prefix.c_str(), scene.sceneOrder.size());
}

// ---- Main
// ----------------------------------------------------------------------------------------

std::string vulkanDeviceName(const Options& o, std::string& whyNot) {
  try {
    VulkanContext context(ContextOptions{.device = o.device});
    return context.info().name + " (" + context.info().driver + ")";
  } catch (const std::exception& e) {
    whyNot = e.what();
    return "";
  }
}

int run(Options& o) {
  if (o.threads <= 0) o.threads = availableCpus();
  for (const std::string& b : o.backends) {
    if (std::none_of(kBackends.begin(), kBackends.end(),
                     [&](const BackendEntry& e) { return b == e.name; })) {
      throw InputError("--backends: no backend '" + b + "' in this build");
    }
  }
  auto wanted = [&](const char* name) {
    return o.backends.empty() ||
           std::find(o.backends.begin(), o.backends.end(), name) != o.backends.end();
  };
  if (o.scenes.empty()) throw InputError("--scenes: no scene given");
  if (!o.exportEmbree.empty()) {
    const std::optional<BenchScene> scene = loadBenchScene(o.scenes.front(), o);
    if (!scene) return kExitInputError;
    exportForEmbree(*scene, o.exportEmbree);
    return kExitOk;
  }

  std::string whyNoVulkan;
  const std::string vulkanDevice = wanted("vulkan") ? vulkanDeviceName(o, whyNoVulkan) : "";
  std::printf("ray_bench: %d CPU threads, Vulkan device: %s, BVH: %s (leaf size %d)\n", o.threads,
              !vulkanDevice.empty() ? vulkanDevice.c_str()
              : wanted("vulkan")    ? ("none, skipped: " + whyNoVulkan).c_str()
                                    : "not asked for",
              o.builder.c_str(), o.leafSize);
#ifdef PT_HAVE_EMBREE
  std::printf("Embree %d.%d.%d%s\n", RTC_VERSION_MAJOR, RTC_VERSION_MINOR, RTC_VERSION_PATCH,
              o.embreeRobust ? ", RTC_SCENE_FLAG_ROBUST" : ", default scene flags");
#else
  std::printf("Embree: not built in (libembree-dev not found at configure time)\n");
#endif
  std::printf("backends:\n");
  for (const BackendEntry& e : kBackends) {
    if (wanted(e.name)) std::printf("  %-8s %s\n", e.name, e.description);
  }

  std::vector<SummaryRow> summary;
  std::vector<std::pair<std::string, std::vector<Comparison>>> agreement;  // by "scene/type"
  size_t totalDiffer = 0, scenesDone = 0;
  for (const std::string& name : o.scenes) {
    const auto loadStart = Clock::now();
    std::optional<BenchScene> scene = loadBenchScene(name, o);
    if (!scene) continue;
    ++scenesDone;
    const std::vector<RaySet> sets = makeRaySets(scene->data);
    std::printf("\n== %s (%s): %zu triangles, %zu emitters, loaded in %.1f s; rays:", name.c_str(),
                scene->description.c_str(), scene->sceneOrder.size(), scene->data.emitters.size(),
                secondsSince(loadStart));
    for (const RaySet& s : sets) std::printf(" %s %zu", s.type.c_str(), s.rays.size());
    std::printf("\n");

    std::vector<std::pair<std::string, std::unique_ptr<TraversalBackend>>> backends;
    for (const BackendEntry& e : kBackends) {
      if (!wanted(e.name)) continue;
      if (std::string(e.name) == "vulkan" && vulkanDevice.empty()) continue;
      try {
        const auto start = Clock::now();
        backends.emplace_back(e.name, e.make(*scene, o));
        std::printf("%s: set up in %.2f s\n", e.name, secondsSince(start));
      } catch (const std::exception& ex) {
        std::printf("%s: skipped (%s)\n", e.name, ex.what());
      }
    }

    // Agreement: each backend once per set, then every pair, then the brute force.
    // A backend that throws (say, a buffer beyond the device's limits) is dropped from the
    // scene with a message.
    const BruteForce brute{scene->sceneOrder};
    std::vector<std::string> failed;
    for (const RaySet& set : sets) {
      std::vector<Outcome> outcomes;
      for (auto& [bname, backend] : backends) {
        if (std::find(failed.begin(), failed.end(), bname) != failed.end()) continue;
        Outcome out{bname, {}, {}, 0};
        try {
          if (set.anyHit) {
            std::vector<uint8_t> occluded;
            backend->any(set.rays, set.tMax, occluded);
            out.hits.resize(occluded.size());
            for (size_t i = 0; i < occluded.size(); ++i) {
              if (occluded[i]) out.hits[i] = HitRecord{0.0f, 0};
            }
          } else {
            backend->closest(set.rays, out.hits);
          }
        } catch (const std::exception& e) {
          std::printf("%s: dropped for %s (%s)\n", bname.c_str(), name.c_str(), e.what());
          failed.push_back(bname);
          continue;
        }
        out.truncated = backend->lastTruncated();
        outcomes.push_back(std::move(out));
      }
      const size_t n = set.rays.size();
      const double tests = double(n) * double(scene->sceneOrder.size());
      const size_t stride = size_t(std::max(1.0, std::ceil(tests / o.bruteBudget)));
      Outcome bruteOut{"brute", {}, {}, 0};
      for (size_t i = 0; i < n; i += stride) bruteOut.subset.push_back(uint32_t(i));
      bruteOut.hits.resize(bruteOut.subset.size());
      parallelChunks(bruteOut.subset.size(), o.threads, [&](size_t begin, size_t end) {
        for (size_t j = begin; j < end; ++j) {
          bruteOut.hits[j] = brute.trace(set.rays[bruteOut.subset[j]], set.tMax, set.anyHit);
        }
      });
      std::vector<Comparison> comparisons;
      for (size_t a = 0; a < outcomes.size(); ++a) {
        for (size_t b = a + 1; b < outcomes.size(); ++b) {
          comparisons.push_back(compare(set, outcomes[a], outcomes[b], brute));
        }
        comparisons.push_back(compare(set, outcomes[a], bruteOut, brute));
      }
      for (const Outcome& out : outcomes) {
        if (out.truncated > 0) {
          std::printf("%s/%s: %s gave up on %llu rays (truncated by the loop cap)\n", name.c_str(),
                      set.type.c_str(), out.backend.c_str(), (unsigned long long)out.truncated);
        }
      }
      for (const Comparison& c : comparisons) totalDiffer += c.differ;
      agreement.emplace_back(name + "/" + set.type, std::move(comparisons));
    }

    std::erase_if(backends, [&](const auto& b) {
      return std::find(failed.begin(), failed.end(), b.first) != failed.end();
    });
    std::printf(
        "\nagreement, %s: rays whose closest hits (one misses, or t differs by more than 1e-5 of\n"
        "max(t, origin's largest coordinate / |d|)) or occlusion differ / rays compared\n",
        name.c_str());
    for (size_t i = agreement.size() - sets.size(); i < agreement.size(); ++i) {
      for (const Comparison& c : agreement[i].second) {
        std::printf("  %-22s %-8s vs %-8s %8zu / %zu\n", agreement[i].first.c_str(), c.a.c_str(),
                    c.b.c_str(), c.differ, c.compared);
        for (const std::string& e : c.examples) std::printf("      %s\n", e.c_str());
      }
    }
    std::fflush(stdout);
    if (!o.checkOnly) timeScene(*scene, sets, backends, o, summary);
  }

  std::vector<std::string> names;  // the table's columns, in kBackends order
  for (const BackendEntry& e : kBackends) {
    if (wanted(e.name)) names.push_back(e.name);
  }
  if (!summary.empty()) {
    std::printf("\nMrays/s (median of %d; %d CPU threads); ratio to %s in the same run\n",
                o.repetitions, o.threads, kReference);
    std::printf("%-14s %-8s %9s", "scene", "type", "rays");
    for (const std::string& n : names) std::printf(" %10s", n.c_str());
    for (const std::string& n : names) {
      if (n != kReference) std::printf(" %15s", (n + "/" + kReference).c_str());
    }
    std::printf("\n");
    for (const SummaryRow& row : summary) {
      std::printf("%-14s %-8s %9zu", row.scene.c_str(), row.type.c_str(), row.rays);
      for (const std::string& n : names) {
        const auto it = row.mraysPerSecond.find(n);
        if (it == row.mraysPerSecond.end()) {
          std::printf(" %10s", "-");
        } else {
          std::printf(" %10.3f", it->second);
        }
      }
      const auto ref = row.mraysPerSecond.find(kReference);
      for (const std::string& n : names) {
        if (n == kReference) continue;
        const auto it = row.mraysPerSecond.find(n);
        if (it == row.mraysPerSecond.end() || ref == row.mraysPerSecond.end()) {
          std::printf(" %15s", "-");
        } else {
          std::printf(" %15.3f", it->second / ref->second);
        }
      }
      std::printf("\n");
    }
  }
  if (!o.csv.empty()) {
    std::ofstream csv(o.csv);
    csv << "scene,triangles,ray_type,rays,backend,mrays_per_s\n";
    for (const SummaryRow& row : summary) {
      for (const std::string& backend : names) {
        const auto it = row.mraysPerSecond.find(backend);
        if (it == row.mraysPerSecond.end()) continue;
        csv << row.scene << ',' << row.triangles << ',' << row.type << ',' << row.rays << ','
            << backend << ',' << it->second << '\n';
      }
    }
    PT_CHECK(bool(csv), "cannot write " + o.csv);
  }
  if (!o.agreementCsv.empty()) {
    std::ofstream csv(o.agreementCsv);
    csv << "scene,ray_type,backend_a,backend_b,compared,differ\n";
    for (const auto& [key, comparisons] : agreement) {
      const size_t slash = key.find('/');
      for (const Comparison& c : comparisons) {
        csv << key.substr(0, slash) << ',' << key.substr(slash + 1) << ',' << c.a << ',' << c.b
            << ',' << c.compared << ',' << c.differ << '\n';
      }
    }
    PT_CHECK(bool(csv), "cannot write " + o.agreementCsv);
  }
  if (scenesDone == 0) {  // a test must not pass on nothing
    std::fprintf(stderr, "ray_bench: none of the scenes could be loaded\n");
    return kExitInputError;
  }
  std::printf("\nagreement: %zu differing results in all\n", totalDiffer);
  if (o.requireAgreement && totalDiffer > 0) return kExitFailure;
  return kExitOk;
}

}  // namespace
}  // namespace pt

int main(int argc, char** argv) {
  // Google Benchmark takes its --benchmark_* flags first; random interleaving (the
  // repetitions of all backends of a scene in random order) unless the command line says
  // otherwise, so that a slow spell of the shared machine falls on all of them alike.
  std::vector<char*> args(argv, argv + argc);
  std::string interleave = "--benchmark_enable_random_interleaving=true";
  args.insert(args.begin() + 1, interleave.data());
  int count = int(args.size());
  // Google Benchmark would answer --help with its own flags only and exit: ours first, with
  // a pointer to its flags.
  const bool help = std::any_of(args.begin() + 1, args.end(), [](const char* a) {
    return std::string_view(a) == "--help" || std::string_view(a) == "-h";
  });
  const bool benchmarkHelp = std::any_of(args.begin() + 1, args.end(), [](const char* a) {
    return std::string_view(a) == "--help_benchmark";
  });
  if (benchmarkHelp) {
    char* usage[] = {args[0], const_cast<char*>("--help")};
    int two = 2;
    benchmark::Initialize(&two, usage);  // prints Google Benchmark's flags and exits
  }
  if (!help) benchmark::Initialize(&count, args.data());

  pt::Options o;
  CLI::App app{
      "Ray benchmark: CPU traversal, GPU ray queries and Embree on fixed ray sets. Google\n"
      "Benchmark's --benchmark_* flags are taken too (e.g. --benchmark_filter=sphere/.*);\n"
      "--help_benchmark lists them."};
  app.add_option("--scenes", o.scenes,
                 "Scenes: names in --configs (cornell-box, bunny-box, bunny-dragon) or sphere")
      ->delimiter(',');
  app.add_option("--configs", o.configDir, "Directory of the scene files");
  app.add_option("--backends", o.backends, "Backends to run (default: all built in)")
      ->delimiter(',');
  app.add_option("--size", o.size, "Primary rays: one per pixel of a SIZE x SIZE film")
      ->check(CLI::Range(1, 4096));
  app.add_option("--threads", o.threads, "CPU threads for the CPU backends (default: all)");
  app.add_option("--device", o.device, "Vulkan device: index or part of the name");
  app.add_option("--builder", o.builder,
                 "BVH builder of our tree (default: the renderer's, " +
                     std::string(pt::nameOf(pt::kBuilderNames, pt::kDefaultBuilder)) + ")")
      ->check(CLI::IsMember(pt::namesOf(pt::kBuilderNames)));
  app.add_option("--leaf-size", o.leafSize,
                 "Maximum triangles per leaf of our tree (default: the CPU renderer's, " +
                     std::to_string(pt::kDefaultLeafSizeCpu) + ")")
      ->check(CLI::Range(1, 64));
  app.add_option("--min-time", o.minTime, "Least seconds per timed repetition");
  app.add_option("--repetitions", o.repetitions, "Timed repetitions (the median is reported)")
      ->check(CLI::Range(1, 100));
  app.add_option("--gpu-min-rays", o.gpuMinRays,
                 "Vulkan: trace copies of a smaller batch up to this many rays per call");
  app.add_option("--brute-budget", o.bruteBudget,
                 "Brute force: triangle tests per ray set (a subset of the rays beyond)");
  app.add_option("--embree-config", o.embreeConfig,
                 "Embree: rtcNewDevice's configuration string (\"verbose=2\" prints its tree's "
                 "node and leaf counts and SAH cost)");
  app.add_flag("--embree-robust", o.embreeRobust,
               "Embree: RTC_SCENE_FLAG_ROBUST (watertight, slower) instead of the default");
  bool quick = false;
  app.add_flag("--quick", quick,
               "Tiny ray sets (32 x 32 film), one short repetition, no GPU copies: seconds");
  app.add_flag("--check-only", o.checkOnly, "Only the agreement check, no timing");
  app.add_flag("--require-agreement", o.requireAgreement,
               "Exit with status 1 if any two results differ (a test)");
  app.add_option("--csv", o.csv, "Write the Mrays/s table as CSV");
  app.add_option("--agreement-csv", o.agreementCsv, "Write the agreement counts as CSV");
  app.add_option("--export-embree", o.exportEmbree,
                 "Write the first scene as PREFIX.obj/.mtl/.ecs for Embree's tutorials, then stop");
  CLI11_PARSE(app, count, args.data());
  if (quick) {
    // Explicit options given after --quick still win where CLI11 saw them.
    if (app.count("--size") == 0) o.size = 32;
    if (app.count("--min-time") == 0) o.minTime = 0.01;
    if (app.count("--repetitions") == 0) o.repetitions = 1;
    if (app.count("--gpu-min-rays") == 0) o.gpuMinRays = 0;
  }
  try {
    return pt::run(o);
  } catch (const pt::InputError& e) {
    std::fprintf(stderr, "ray_bench: %s\n", e.what());
    return pt::kExitInputError;
  }
}
