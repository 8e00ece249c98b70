// BVH build benchmark (not a test; tools/bvh-bench.sh builds and runs it): build times of
// our builders next to Embree 3's own BVH build on the same triangles in the same run, and
// the SAH cost and CPU trace speed of our trees, on a generated UV sphere of about 1.05M
// triangles, the Stanford bunny and the Stanford dragon. Embree is timed as its authors time
// it (its buildbench tool: shared vertices, only rtcCommitScene in the clock, after a warm-up
// build), and buildbench itself runs on the same files in the same run, so that the figure
// can be checked against Embree's own. Ours are timed warm (repeated builds in this process)
// and cold (one build in a fresh process, as `pt render` builds), since a user waits for
// the cold one and the warm one flatters us.
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
#include <utility>
#include <vector>

#include <unistd.h>

#include "bench_util.h"
#include "bvh/bvh.h"
#include "bvh/traverse.h"
#include "bvh/wide_bvh.h"
#include "common/check.h"
#include "embree_scene.h"
#include "render/prepare.h"
#include "scene/load_scene.h"
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

// Embree's own BVH build as its authors time it (buildbench's create_static_static): the
// shared-vertex mesh and a scene over it are set up before the clock starts, and only
// rtcCommitScene is timed. Embree's defaults otherwise (bench/embree_scene.h), on `threads`
// threads: the count our all-thread builds use.
class EmbreeBuild {
 public:
  explicit EmbreeBuild(int threads) : device_(("threads=" + std::to_string(threads)).c_str()) {}

  double commitSeconds(const bench::IndexedMesh& mesh) {
    RTCScene scene = bench::newUncommittedEmbreeScene(device_.get(), mesh);
    const auto start = Clock::now();
    rtcCommitScene(scene);
    const double seconds = secondsSince(start);
    rtcReleaseScene(scene);
    return seconds;
  }

 private:
  bench::EmbreeDevice device_;
};

// What the benchmark reads: mesh files, repetitions, and the tree it builds.
struct Options {
  std::string bunny = "/usr/share/glmark2/models/bunny.obj", dragon;
  int runs = 5;
  size_t rays = 200000;
  // The CPU renderer's leaf size: the tree `pt render --backend cpu` builds and collapses.
  int leafSize = kDefaultLeafSizeCpu;
  std::string buildbench;  // Embree's buildbench (embree-tools); empty: not run
};

int hardwareThreads() {
  return int(std::max(1u, std::thread::hardware_concurrency()));
}

// The triangles of mesh `name` (sphere, bunny, dragon), generated or loaded; nothing when its
// file is absent.
std::optional<std::vector<Triangle>> meshTriangles(const std::string& name, const Options& o) {
  if (name == "sphere") return uvSphere(726, 725);
  if (name == "bunny") return loadMesh("obj", o.bunny);
  if (name == "dragon") return loadMesh("ply", o.dragon);
  return std::nullopt;
}

// `s` as one word for the shell.
std::string quoted(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// What a shell command writes to its standard output; nothing (and the output on stderr)
// when it fails.
std::optional<std::string> commandOutput(const std::string& command) {
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return std::nullopt;
  std::string out;
  char buffer[4096];
  for (size_t n; (n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0;) out.append(buffer, n);
  if (::pclose(pipe) != 0) {
    std::fprintf(stderr, "bvh_build_bench: failed: %s\n%s", command.c_str(), out.c_str());
    return std::nullopt;
  }
  return out;
}

// Seconds of one build in a process of its own (this program again, --cold) and of the
// collapse of that tree to the CPU's wide tree right after it: every page the build writes
// is fresh, as in `pt render`, whose bvh_build_s is the first figure (the wall time of
// buildBvh here, which also frees the input; bvh_build_s stops just before that). `kind`: a
// builder's name, or "embree" for Embree's first rtcCommitScene in the process (no wide
// tree). NaN where the process failed.
std::pair<double, double> coldSeconds(const std::string& kind, const std::string& mesh,
                                      const Options& o) {
  const std::string command = quoted(std::filesystem::read_symlink("/proc/self/exe").string()) +
                              " --cold " + kind + " --mesh " + mesh + " --bunny " +
                              quoted(o.bunny) + " --dragon " + quoted(o.dragon) + " --leaf-size " +
                              std::to_string(o.leafSize);
  double build = NAN, wide = NAN;
  if (const auto out = commandOutput(command)) {
    const size_t at = out->find("cold build_s=");
    if (at == std::string::npos ||
        std::sscanf(out->c_str() + at, "cold build_s=%lf wide_s=%lf", &build, &wide) != 2) {
      std::fprintf(stderr, "bvh_build_bench: unexpected output of %s:\n%s", command.c_str(),
                   out->c_str());
    }
  }
  return {build, wide};
}

// The process that coldSeconds starts: loads the mesh as `pt render` would, builds once and
// prints the seconds.
int coldBuild(const std::string& kind, const std::string& meshName, const Options& o) {
  std::optional<std::vector<Triangle>> triangles = meshTriangles(meshName, o);
  PT_CHECK(triangles.has_value(), "no such mesh, or its file is missing");
  if (kind == "embree") {
    // The mesh and the device are made before the clock starts; Embree starts its worker
    // threads at the first commit (start_threads=0, its default), inside the clock, as our
    // builders start theirs in buildBvh.
    const bench::IndexedMesh mesh = bench::weldVertices(*triangles);
    EmbreeBuild embree(hardwareThreads());
    std::printf("cold build_s=%.9f wide_s=nan\n", embree.commitSeconds(mesh));
    return 0;
  }
  const std::optional<BvhBuilder> builder = valueNamed(kBuilderNames, kind);
  PT_CHECK(builder.has_value(), "unknown builder");
  BvhBuildOptions options;
  options.builder = *builder;
  options.maxLeafSize = o.leafSize;
  options.threads = 0;  // all, as pt render builds
  auto start = Clock::now();
  const Bvh bvh = buildBvh(std::move(*triangles), options);
  const double build = secondsSince(start);
  start = Clock::now();
  const WideBvh wide = buildWideBvh(bvh);
  const double collapse = secondsSince(start);
  std::printf("cold build_s=%.9f wide_s=%.9f bvh_build_s=%.9f wide_nodes=%zu\n", build, collapse,
              bvh.buildSeconds, wide.nodes.size());
  return 0;
}

// Embree's own build benchmark (embree-tools' buildbench) on a mesh file, in a process of its
// own: its create_static_static case, a scene with RTC_SCENE_FLAG_NONE and
// RTC_BUILD_QUALITY_MEDIUM over the file's shared vertex and index buffers, only
// rtcCommitScene timed. `--benchmark 1 1`: Debian's buildbench is built without Google
// Benchmark, so this is its "legacy" mode, one warm-up build, then the mean of one timed
// build. It reads OBJ and PLY files. `verbose=1` makes Embree print its configuration, whose
// thread count is read back.
struct BuildbenchResult {
  double seconds = NAN;
  int threads = 0;
  size_t primitives = 0;
};

std::optional<BuildbenchResult> runBuildbench(const std::string& buildbench,
                                              const std::string& file, int threads) {
  const std::string command = quoted(buildbench) + " -i " + quoted(file) + " --threads " +
                              std::to_string(threads) +
                              " --rtcore verbose=1 --benchmark_type create_static_static"
                              " --benchmark 1 1 2>&1";
  const auto out = commandOutput(command);
  if (!out) return std::nullopt;
  BuildbenchResult result;
  const size_t at = out->find("BENCHMARK_CREATE_STATIC_STATIC");
  size_t iterations = 0, objects = 0;
  // The CPU's block says "Threads  : N" (the hardware's), the configuration's "Threads : N"
  // (what the device uses).
  const size_t threadsAt = out->rfind("Threads :");
  if (at == std::string::npos ||
      std::sscanf(out->c_str() + at,
                  "BENCHMARK_CREATE_STATIC_STATIC %zu iterations, %zu primitives, %zu objects, "
                  "%lf s",
                  &iterations, &result.primitives, &objects, &result.seconds) != 4 ||
      threadsAt == std::string::npos ||
      std::sscanf(out->c_str() + out->find(':', threadsAt), ": %d", &result.threads) != 1) {
    std::fprintf(stderr, "bvh_build_bench: unexpected output of %s:\n%s", command.c_str(),
                 out->c_str());
    return std::nullopt;
  }
  return result;
}

// `mesh` as an OBJ file (v and f lines), for buildbench; 9 significant digits read back as
// the same floats.
void writeObj(const bench::IndexedMesh& mesh, const std::filesystem::path& file) {
  FILE* f = std::fopen(file.c_str(), "w");
  PT_CHECK(f != nullptr, "cannot write the sphere's OBJ");
  for (const auto& p : mesh.positions) std::fprintf(f, "v %.9g %.9g %.9g\n", p.x, p.y, p.z);
  for (const auto& t : mesh.indices) std::fprintf(f, "f %u %u %u\n", t[0] + 1, t[1] + 1, t[2] + 1);
  PT_CHECK(std::fclose(f) == 0, "cannot write the sphere's OBJ");
}
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
  BvhBuilder builder;
  int threads;  // 0: all hardware threads
  // Also built cold and collapsed to the CPU's wide tree: the builds `pt render` makes (all
  // threads; the binned-SAH builder is serial).
  bool asPtRenders;
  std::string name() const { return std::string(nameOf(kBuilderNames, builder)); }
};

// A mesh of the table: `name` as --mesh names it in the cold processes, `file` the file
// buildbench reads (for the generated sphere, an OBJ written for it).
struct Mesh {
  std::string name, title;
  std::vector<Triangle> triangles;
  std::string file;
};

void benchmarkMesh(const Mesh& mesh, const Options& o) {
  const int hardware = hardwareThreads();
  const std::vector<Triangle>& triangles = mesh.triangles;
  const bench::IndexedMesh indexed = bench::weldVertices(triangles);
  std::printf("\n%s: %zu triangles, %zu shared vertices\n", mesh.title.c_str(), triangles.size(),
              indexed.positions.size());
  const std::vector<Contender> contenders = {
      {BvhBuilder::kLbvh, 1, false},     {BvhBuilder::kLbvh, 0, true},
      {BvhBuilder::kPloc, 1, false},     {BvhBuilder::kPloc, 0, true},
      {BvhBuilder::kBinnedSah, 1, true},
  };
  EmbreeBuild embree(hardware);
  // Runs interleaved (one build of each, `runs` times over, after a warm-up round that is not
  // counted), so that a change in the machine's load falls on all of them alike. Per
  // contender: warm builds (this process, memory touched by the builds before), cold builds
  // (a fresh process each), and the collapse to the wide tree, warm and cold.
  const size_t n = contenders.size();
  std::vector<std::vector<double>> warm(n), cold(n), wideWarm(n), wideCold(n);
  std::vector<double> embreeWarm, embreeCold, buildbench;
  std::optional<BuildbenchResult> buildbenchLast;
  std::vector<Bvh> trees(n);
  for (int run = -1; run < o.runs; ++run) {
    for (size_t c = 0; c < n; ++c) {
      BvhBuildOptions options;
      options.builder = contenders[c].builder;
      options.threads = contenders[c].threads;
      options.maxLeafSize = o.leafSize;
      std::vector<Triangle> input = triangles;
      auto start = Clock::now();
      Bvh bvh = buildBvh(std::move(input), options);
      const double s = secondsSince(start);
      if (run >= 0) warm[c].push_back(s);
      if (contenders[c].asPtRenders) {
        start = Clock::now();
        const WideBvh wide = buildWideBvh(bvh);
        if (run >= 0) wideWarm[c].push_back(secondsSince(start));
      }
      trees[c] = std::move(bvh);
    }
    const double s = embree.commitSeconds(indexed);
    if (run < 0) continue;
    embreeWarm.push_back(s);
    for (size_t c = 0; c < n; ++c) {
      if (!contenders[c].asPtRenders) continue;
      const auto [build, wide] = coldSeconds(contenders[c].name(), mesh.name, o);
      // A failed process is left out (its message is on stderr).
      if (!std::isnan(build)) cold[c].push_back(build);
      if (!std::isnan(wide)) wideCold[c].push_back(wide);
    }
    const double embreeFirst = coldSeconds("embree", mesh.name, o).first;
    if (!std::isnan(embreeFirst)) embreeCold.push_back(embreeFirst);
    if (!o.buildbench.empty()) {
      if (const auto result = runBuildbench(o.buildbench, mesh.file, hardware)) {
        buildbench.push_back(result->seconds);
        buildbenchLast = result;
      }
    }
  }
  const double commit = median(embreeWarm);

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
  auto sameAsBefore = [&](size_t c) {
    return c > 0 && contenders[c - 1].builder == contenders[c].builder;
  };
  const RaySets rays = makeRays(triangles, o.rays);
  constexpr int kSets = 3;
  std::vector<std::array<std::vector<double>, kSets>> traceTimes(n);
  std::vector<std::array<size_t, kSets>> hits(n);
  for (int run = 0; run < o.runs; ++run) {
    for (size_t c = 0; c < n; ++c) {
      if (sameAsBefore(c)) continue;
      const Bvh& bvh = trees[c];
      auto closest = [&](const Ray& r) { return closestHit(bvh, r).has_value(); };
      traceTimes[c][0].push_back(traceSeconds(rays.primary, hits[c][0], closest));
      traceTimes[c][1].push_back(traceSeconds(rays.surface, hits[c][1], closest));
      traceTimes[c][2].push_back(traceSeconds(
          rays.shadow, hits[c][2], [&](const Ray& r) { return anyHit(bvh, r, kShadowRange); }));
    }
  }

  // Milliseconds, or "-" where there is no figure; NaN (a failed process) prints as nan.
  auto ms = [](const std::vector<double>& seconds) {
    char text[32] = "-";
    if (!seconds.empty()) std::snprintf(text, sizeof text, "%.1f", median(seconds) * 1e3);
    return std::string(text);
  };
  auto ratio = [commit](const std::vector<double>& seconds) {
    char text[32] = "-";
    if (!seconds.empty()) std::snprintf(text, sizeof text, "%.2f", median(seconds) / commit);
    return std::string(text);
  };
  std::printf("%-17s %7s %8s %7s %8s %7s %9s %9s %8s %5s %8s %8s %8s %8s\n", "build", "threads",
              "warm_ms", "/commit", "cold_ms", "/commit", "wide_warm", "wide_cold", "nodes",
              "depth", "sah_cost", "primary", "surface", "shadow");
  for (size_t c = 0; c < n; ++c) {
    const Bvh& bvh = trees[c];
    const int threads = contenders[c].threads > 0 ? contenders[c].threads : hardware;
    std::printf("%-17s %7d %8s %7s %8s %7s %9s %9s %8zu %5d %8.2f", contenders[c].name().c_str(),
                threads, ms(warm[c]).c_str(), ratio(warm[c]).c_str(), ms(cold[c]).c_str(),
                ratio(cold[c]).c_str(), ms(wideWarm[c]).c_str(), ms(wideCold[c]).c_str(),
                bvh.nodes.size(), bvh.maxDepth, bvh.sahCost);
    if (sameAsBefore(c)) {
      std::printf("  %s\n", sameTree(trees[c - 1], bvh) ? "(the same tree as on 1 thread)"
                                                        : "(NOT THE SAME TREE AS ON 1 THREAD)");
      continue;
    }
    for (int set = 0; set < kSets; ++set) {
      std::printf(" %8.3f", double(o.rays) / median(traceTimes[c][size_t(set)]) * 1e-6);
    }
    std::printf("   hits %zu %zu %zu\n", hits[c][0], hits[c][1], hits[c][2]);
  }
  std::printf("%-17s %7d %8s %7s %8s %7s\n", "embree commit", hardware, ms(embreeWarm).c_str(),
              ratio(embreeWarm).c_str(), ms(embreeCold).c_str(), ratio(embreeCold).c_str());
  if (o.buildbench.empty()) {
    std::printf("%-17s   (not run: no --buildbench)\n", "embree buildbench");
  } else if (buildbench.empty()) {
    std::printf("%-17s   (failed: see the messages above)\n", "embree buildbench");
  } else {
    // Our loader drops zero-area triangles (the dragon's PLY has 108); buildbench keeps them.
    std::printf("%-17s %7d %8s %7s   %s: %zu primitives%s\n", "embree buildbench",
                buildbenchLast->threads, ms(buildbench).c_str(), ratio(buildbench).c_str(),
                mesh.file.c_str(), buildbenchLast->primitives,
                buildbenchLast->primitives == triangles.size()
                    ? ""
                    : " (more than ours: the scene loader drops zero-area triangles)");
  }
  // The default builder's figures in a sentence, with the wide collapse that the CPU backend
  // adds to them.
  for (size_t c = 0; c < n; ++c) {
    if (contenders[c].builder != kDefaultBuilder || !contenders[c].asPtRenders || cold[c].empty() ||
        wideCold[c].empty()) {
      continue;
    }
    std::printf(
        "default (%s, %d threads) / Embree's rtcCommitScene: warm %s, cold %s; with the CPU's "
        "wide collapse: warm %.2f, cold %.2f\n",
        contenders[c].name().c_str(), hardware, ratio(warm[c]).c_str(), ratio(cold[c]).c_str(),
        (median(warm[c]) + median(wideWarm[c])) / commit,
        (median(cold[c]) + median(wideCold[c])) / commit);
  }
  // The Morton-based trees next to the binned-SAH tree (the last contender).
  const size_t sah = n - 1;
  for (size_t c = 0; c < sah; c += 2) {
    std::printf("%s / sah: sah_cost %.3f, trace speed", contenders[c].name().c_str(),
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
  pt::Options o;
  CLI::App app{"BVH build benchmark: our builders against Embree 3, SAH cost, trace speed"};
  app.add_option("--dragon", o.dragon, "Stanford dragon PLY (dragon_vrip.ply); skipped if absent");
  app.add_option("--bunny", o.bunny, "Stanford bunny OBJ; skipped if absent");
  app.add_option("--runs", o.runs, "Timed runs per measurement (the median is shown)")
      ->check(CLI::Range(1, 100));
  app.add_option("--rays", o.rays, "Rays per ray set")->check(CLI::Range(1, 100000000));
  app.add_option("--leaf-size", o.leafSize,
                 "Maximum triangles per leaf (default: the CPU renderer's, " +
                     std::to_string(pt::kDefaultLeafSizeCpu) + ")")
      ->check(CLI::Range(1, 64));
  app.add_option("--buildbench", o.buildbench,
                 "Embree's buildbench (embree-tools), run on each mesh file in every run");
  bool quick = false;
  app.add_flag("--quick", quick, "Only one-thread PLOC and binned-SAH build times (least of runs)");
  std::string cold, coldMesh = "sphere";
  app.add_option("--cold", cold,
                 "Internal: build once with this builder (or embree) in this fresh process and "
                 "print the seconds");
  app.add_option("--mesh", coldMesh, "Internal: the mesh of --cold (sphere, bunny, dragon)");
  CLI11_PARSE(app, argc, argv);
  if (!cold.empty()) return pt::coldBuild(cold, coldMesh, o);
  if (quick) {
    pt::quickMesh("sphere", pt::uvSphere(726, 725), o.runs);
    for (const auto& [name, type, file] :
         {std::tuple{"bunny", "obj", o.bunny}, std::tuple{"dragon", "ply", o.dragon}}) {
      if (const auto mesh = pt::loadMesh(type, file)) pt::quickMesh(name, *mesh, o.runs);
    }
    return 0;
  }

  const int threads = pt::hardwareThreads();
  std::printf(
      "BVH build benchmark: medians of %d runs, leaves of at most %d triangles.\n"
      "warm_ms: wall time of buildBvh in this process, after earlier builds touched the memory;\n"
      "cold_ms: the same in a fresh process per build (one build each: every page fresh, as in\n"
      "`pt render`); wide_warm, wide_cold: ms of buildWideBvh on that tree, the CPU backend's\n"
      "collapse to its 8-wide tree, after the warm or cold build; /commit: ratio to Embree's\n"
      "rtcCommitScene (warm) in the same run.\n"
      "embree commit: Embree %d.%d.%d as its buildbench times it: an indexed mesh with shared\n"
      "vertices (welded from the loaded triangles), buffers shared and filled and the scene made\n"
      "before the clock, only rtcCommitScene timed, after one warm-up build (warm) or as the\n"
      "first commit of a fresh process (cold); RTC_BUILD_QUALITY_MEDIUM, RTC_SCENE_FLAG_NONE\n"
      "(Embree's defaults), threads=%d.\n"
      "embree buildbench: Embree's own tool on the same mesh file, create_static_static, one\n"
      "warm-up and one timed build per process, --threads %d (the threads it reports).\n"
      "sah_cost: Bvh::sahCost (traversal 1, triangle 1, per root area); primary, surface,\n"
      "shadow: CPU traversal of the binary tree on 1 thread, Mrays/s, %zu rays each (closest\n"
      "hit, closest hit, any hit).\n",
      o.runs, o.leafSize, RTC_VERSION_MAJOR, RTC_VERSION_MINOR, RTC_VERSION_PATCH, threads, threads,
      o.rays);
  // buildbench reads the bunny's OBJ and the dragon's PLY as they are; the generated sphere
  // is written for it as an OBJ of its shared vertices.
  const std::filesystem::path temp =
      std::filesystem::temp_directory_path() / ("bvh-bench-" + std::to_string(::getpid()));
  std::filesystem::create_directories(temp);
  {
    pt::Mesh sphere{"sphere", "sphere (UV, 726 rings x 725 segments)", pt::uvSphere(726, 725),
                    (temp / "sphere.obj").string()};
    if (!o.buildbench.empty()) pt::writeObj(pt::bench::weldVertices(sphere.triangles), sphere.file);
    pt::benchmarkMesh(sphere, o);
  }
  std::filesystem::remove_all(temp);
  for (const auto& [name, file] : {std::pair{"bunny", o.bunny}, std::pair{"dragon", o.dragon}}) {
    auto triangles = pt::meshTriangles(name, o);
    if (!triangles) {
      std::printf("\n%s: skipped (no file%s%s)\n", name, file.empty() ? "" : " at ", file.c_str());
      continue;
    }
    pt::benchmarkMesh({name, std::string(name) + " (" + file + ")", std::move(*triangles), file},
                      o);
  }
  return 0;
}
