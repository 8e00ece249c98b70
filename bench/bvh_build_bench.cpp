// BVH build benchmark (not a test; tools/bvh-bench.sh builds and runs it): build times of
// our builders next to Embree 3's own BVH build on the same triangles in the same run, and
// the SAH cost and CPU trace speed of our trees, on a generated UV sphere of about 1.05M
// triangles, the Stanford bunny and the Stanford dragon.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <random>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include <unistd.h>

#include "bench_util.h"
#include "bvh/bvh.h"
#include "bvh/traverse.h"
#include "common/check.h"
#include "embree_scene.h"
#include "scene/scene.h"

namespace pt {
namespace {

using bench::Clock;
using bench::median;
using bench::secondsSince;
using bench::uvSphere;

// The triangles of a mesh file, through the scene loader (which drops zero-area triangles);
// nothing when the file is absent.
std::optional<std::vector<Triangle>> loadMesh(const std::string& type, const std::string& file) {
  if (file.empty() || !std::filesystem::exists(file)) return std::nullopt;
  const std::filesystem::path scene = std::filesystem::temp_directory_path() /
                                      ("bvh-bench-" + std::to_string(::getpid()) + ".json");
  std::ofstream(scene) << R"({"materials": [{"name": "m", "reflectance": [0.5, 0.5, 0.5]}],)"
                       << R"("shapes": [{"type": ")" << type << R"(", "material": "m", "file": )"
                       << '"' << std::filesystem::absolute(file).string() << "\"}]}";
  std::vector<Triangle> triangles = loadScene(scene).triangles;
  std::filesystem::remove(scene);
  return triangles;
}

// Embree's own BVH build (bench/embree_scene.h): one triangle geometry, Embree's defaults.
class EmbreeBuild {
 public:
  // Seconds from creating the scene to the end of rtcCommitScene (filling the buffers
  // included, as our builders' time includes reading the triangles).
  double build(const std::vector<Triangle>& triangles) {
    const auto start = Clock::now();
    RTCScene scene = bench::newEmbreeScene(device_.get(), triangles);
    const double seconds = secondsSince(start);
    rtcReleaseScene(scene);
    return seconds;
  }

 private:
  bench::EmbreeDevice device_;
};

// Shadow rays end this far along their direction, short of the point they aim at.
constexpr float kShadowRange = 0.999f;

// Fixed ray sets over a mesh. Primary: from points on a sphere around the mesh's bounding
// box towards random points inside it (most hit, some miss, as camera rays). Surface: from
// random points on random triangles in uniformly random directions (as bounce rays). Shadow:
// from a surface point to another (t < 1 in units of the unnormalised direction).
struct RaySets {
  std::vector<Ray> primary, surface, shadow;
};

RaySets makeRays(const std::vector<Triangle>& triangles, size_t count) {
  vec3 lo(INFINITY), hi(-INFINITY);
  for (const Triangle& t : triangles) {
    for (vec3 v : {t.v0, t.v1, t.v2}) {
      lo = min(lo, v);
      hi = max(hi, v);
    }
  }
  const vec3 center = 0.5f * (lo + hi);
  const float radius = length(hi - lo);  // twice the box's circumradius
  std::mt19937 rng(20240611);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  auto direction = [&] {
    const float z = 2.0f * uni(rng) - 1.0f, phi = 2.0f * kPi * uni(rng);
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    return vec3(r * std::cos(phi), r * std::sin(phi), z);
  };
  auto surfacePoint = [&] {
    const Triangle& t =
        triangles[std::min(size_t(uni(rng) * float(triangles.size())), triangles.size() - 1)];
    const vec2 b = sampleTriangleBarycentrics(vec2(uni(rng), uni(rng)));
    return (1.0f - b.x - b.y) * t.v0 + b.x * t.v1 + b.y * t.v2;
  };
  // Surface origins step off the surface by a hair so that they do not hit their own triangle.
  const float offset = 1e-5f * radius;
  RaySets rays;
  for (size_t i = 0; i < count; ++i) {
    const vec3 origin = center + radius * direction();
    const vec3 target = lo + (hi - lo) * vec3(uni(rng), uni(rng), uni(rng));
    rays.primary.push_back(Ray{origin, normalize(target - origin)});
    const vec3 d = direction();
    rays.surface.push_back(Ray{surfacePoint() + offset * d, d});
    const vec3 from = surfacePoint(), to = surfacePoint();
    const vec3 along = to - from;
    const float l = length(along);
    rays.shadow.push_back(Ray{from + (l > 0 ? offset / l : 0.0f) * along, along});
  }
  return rays;
}

// Seconds to trace `rays` on one thread; `hits` counts the hits (so that the work cannot be
// optimised away, and as a cross-check between trees).
double traceSeconds(const std::vector<Ray>& rays, size_t& hits,
                    const std::function<bool(const Ray&)>& trace) {
  const auto start = Clock::now();
  hits = 0;
  for (const Ray& ray : rays) hits += trace(ray);
  return secondsSince(start);
}

struct Contender {
  std::string name;
  BvhBuilder builder;
  int threads;  // 0: all hardware threads
};

void benchmarkMesh(const std::string& title, const std::vector<Triangle>& triangles, int runs,
                   size_t rayCount, EmbreeBuild& embree) {
  const int hardware = int(std::max(1u, std::thread::hardware_concurrency()));
  std::printf("\n%s: %zu triangles\n", title.c_str(), triangles.size());
  const std::vector<Contender> contenders = {
      {"lbvh", BvhBuilder::kLbvh, 1},     {"lbvh", BvhBuilder::kLbvh, 0},
      {"ploc", BvhBuilder::kPloc, 1},     {"ploc", BvhBuilder::kPloc, 0},
      {"sah", BvhBuilder::kBinnedSah, 1},
  };
  // Runs interleaved (one build of each, `runs` times over, after a warm-up round), so that
  // a change in the machine's load falls on all of them alike.
  std::vector<std::vector<double>> seconds(contenders.size() + 1);
  std::vector<Bvh> trees(contenders.size());
  for (int run = -1; run < runs; ++run) {
    for (size_t c = 0; c < contenders.size(); ++c) {
      BvhBuildOptions options;
      options.builder = contenders[c].builder;
      options.threads = contenders[c].threads;
      std::vector<Triangle> input = triangles;
      const auto start = Clock::now();
      Bvh bvh = buildBvh(std::move(input), options);
      const double s = secondsSince(start);
      if (run >= 0) seconds[c].push_back(s);
      trees[c] = std::move(bvh);
    }
    const double s = embree.build(triangles);
    if (run >= 0) seconds.back().push_back(s);
  }
  const double embreeSeconds = median(seconds.back());

  // Trace speed, interleaved too: each run traces every set through every distinct tree.
  // The one-thread and all-thread trees of a builder must be the same tree; the first one
  // is traced.
  auto sameTree = [](const Bvh& a, const Bvh& b) {
    return a.nodes.size() == b.nodes.size() &&
           std::equal(a.nodes.begin(), a.nodes.end(), b.nodes.begin(),
                      [](const BvhNode& x, const BvhNode& y) {
                        return x.boundsMin == y.boundsMin && x.offset == y.offset &&
                               x.boundsMax == y.boundsMax && x.count == y.count;
                      });
  };
  const RaySets rays = makeRays(triangles, rayCount);
  constexpr int kSets = 3;
  std::vector<std::array<std::vector<double>, kSets>> traceTimes(contenders.size());
  std::vector<std::array<size_t, kSets>> hits(contenders.size());
  for (int run = 0; run < runs; ++run) {
    for (size_t c = 0; c < contenders.size(); ++c) {
      if (c > 0 && contenders[c - 1].builder == contenders[c].builder) continue;
      const Bvh& bvh = trees[c];
      auto closest = [&](const Ray& r) { return closestHit(bvh, r).has_value(); };
      traceTimes[c][0].push_back(traceSeconds(rays.primary, hits[c][0], closest));
      traceTimes[c][1].push_back(traceSeconds(rays.surface, hits[c][1], closest));
      traceTimes[c][2].push_back(traceSeconds(
          rays.shadow, hits[c][2], [&](const Ray& r) { return anyHit(bvh, r, kShadowRange); }));
    }
  }

  std::printf("%-6s %7s %9s %8s %8s %5s %8s %9s %9s %9s\n", "build", "threads", "build_ms",
              "/embree", "nodes", "depth", "sah_cost", "primary", "surface", "shadow");
  for (size_t c = 0; c < contenders.size(); ++c) {
    const Bvh& bvh = trees[c];
    const int threads = contenders[c].threads > 0 ? contenders[c].threads : hardware;
    const double ms = median(seconds[c]) * 1e3;
    std::printf("%-6s %7d %9.1f %8.2f %8zu %5d %8.2f", contenders[c].name.c_str(), threads, ms,
                ms * 1e-3 / embreeSeconds, bvh.nodes.size(), bvh.maxDepth, bvh.sahCost);
    if (c > 0 && contenders[c - 1].builder == contenders[c].builder) {
      std::printf("   %s\n", sameTree(trees[c - 1], bvh) ? "(the same tree as on 1 thread)"
                                                         : "(NOT THE SAME TREE AS ON 1 THREAD)");
      continue;
    }
    for (int set = 0; set < kSets; ++set) {
      std::printf(" %9.3f", double(rayCount) / median(traceTimes[c][size_t(set)]) * 1e-6);
    }
    std::printf("   hits %zu %zu %zu\n", hits[c][0], hits[c][1], hits[c][2]);
  }
  std::printf("%-6s %7d %9.1f %8.2f   (RTC_BUILD_QUALITY_MEDIUM)\n", "embree", hardware,
              embreeSeconds * 1e3, 1.0);
  // The Morton-based trees next to the binned-SAH tree (the last contender).
  const size_t sah = contenders.size() - 1;
  for (size_t c = 0; c < sah; c += 2) {
    std::printf("%s / sah: sah_cost %.3f, trace speed", contenders[c].name.c_str(),
                trees[c].sahCost / trees[sah].sahCost);
    for (int set = 0; set < kSets; ++set) {
      std::printf(" %.3f",
                  median(traceTimes[sah][size_t(set)]) / median(traceTimes[c][size_t(set)]));
    }
    std::printf(" (primary, surface, shadow)\n");
  }
}

// --quick: only the one-thread PLOC and binned-SAH builds, alternated `runs` times; the
// least wall time of each and their ratio (for comparing changes to the builders quickly).
void quickMesh(const std::string& title, const std::vector<Triangle>& triangles, int runs) {
  double best[2] = {INFINITY, INFINITY};
  const BvhBuilder builders[2] = {BvhBuilder::kPloc, BvhBuilder::kBinnedSah};
  double sah[2] = {0, 0};
  for (int run = 0; run < runs; ++run) {
    for (int b = 0; b < 2; ++b) {
      BvhBuildOptions options;
      options.builder = builders[b];
      options.threads = 1;
      std::vector<Triangle> input = triangles;
      const auto start = Clock::now();
      Bvh bvh = buildBvh(std::move(input), options);
      best[b] = std::min(best[b], secondsSince(start));
      sah[b] = bvh.sahCost;
    }
  }
  std::printf("%-8s ploc %8.2f ms  sah %8.2f ms  ploc/sah %.3f  sah_cost ratio %.4f\n",
              title.c_str(), best[0] * 1e3, best[1] * 1e3, best[0] / best[1], sah[0] / sah[1]);
}

}  // namespace
}  // namespace pt

int main(int argc, char** argv) {
  std::string bunny = "/usr/share/glmark2/models/bunny.obj", dragon;
  int runs = 5;
  size_t rays = 200000;
  CLI::App app{"BVH build benchmark: our builders against Embree 3, SAH cost, trace speed"};
  app.add_option("--dragon", dragon, "Stanford dragon PLY (dragon_vrip.ply); skipped if absent");
  app.add_option("--bunny", bunny, "Stanford bunny OBJ; skipped if absent");
  app.add_option("--runs", runs, "Timed runs per measurement (the median is shown)")
      ->check(CLI::Range(1, 100));
  app.add_option("--rays", rays, "Rays per ray set")->check(CLI::Range(1, 100000000));
  bool quick = false;
  app.add_flag("--quick", quick, "Only one-thread PLOC and binned-SAH build times (least of runs)");
  CLI11_PARSE(app, argc, argv);
  if (quick) {
    pt::quickMesh("sphere", pt::uvSphere(726, 725), runs);
    for (const auto& [name, type, file] :
         {std::tuple{"bunny", "obj", bunny}, std::tuple{"dragon", "ply", dragon}}) {
      if (const auto mesh = pt::loadMesh(type, file)) pt::quickMesh(name, *mesh, runs);
    }
    return 0;
  }

  std::printf(
      "BVH build benchmark: median of %d runs; build_ms is wall time of buildBvh (or of\n"
      "Embree's scene setup and commit), /embree its ratio to Embree's in the same run;\n"
      "sah_cost: Bvh::sahCost (traversal 1, triangle 1, per root area); primary,\n"
      "surface, shadow: CPU traversal on 1 thread, Mrays/s, %zu rays each (closest hit,\n"
      "closest hit, any hit).\n"
      "Embree %d.%d.%d, default device: all %u hardware threads, build quality medium.\n",
      runs, rays, RTC_VERSION_MAJOR, RTC_VERSION_MINOR, RTC_VERSION_PATCH,
      std::max(1u, std::thread::hardware_concurrency()));
  pt::EmbreeBuild embree;
  pt::benchmarkMesh("sphere (UV, 726 rings x 725 segments)", pt::uvSphere(726, 725), runs, rays,
                    embree);
  for (const auto& [name, type, file] :
       {std::tuple{"bunny", "obj", bunny}, std::tuple{"dragon", "ply", dragon}}) {
    const auto mesh = pt::loadMesh(type, file);
    if (!mesh) {
      std::printf("\n%s: skipped (no file%s%s)\n", name, file.empty() ? "" : " at ", file.c_str());
      continue;
    }
    pt::benchmarkMesh(std::string(name) + " (" + file + ")", *mesh, runs, rays, embree);
  }
  return 0;
}
