// Film states on the command line; see film_states.h.
#include "cli/film_states.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdio>
#include <filesystem>
#include <numeric>
#include <optional>
#include <set>

#include "cli/progress.h"
#include "common/check.h"
#include "common/named_values.h"
#include "cpu/sppm.h"

namespace pt {
namespace {

template <typename T>
std::string hashOf(const std::vector<T>& values, uint64_t seed = 0) {
  return hexHash(hashBytes(values.data(), values.size() * sizeof(T), seed));
}

std::string lowercaseExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

// Task 3 of 4 from an info entry "task=3/4".
bool parseTask(const std::string* text, int& index, int& count) {
  if (!text) return false;
  char extra = 0;
  return std::sscanf(text->c_str(), "%d/%d%c", &index, &count, &extra) == 2 && index >= 0 &&
         index < count;
}

}  // namespace

KeyValues imageSettings(const SceneData& data, const RenderSettings& settings,
                        const std::string& backend, const KeyValues& backendExtra) {
  const RenderParams& p = data.params;
  // The scene's content in load order (what the scene file says), apart from the BVH, so that
  // a changed scene and a changed builder are told apart.
  // (Scene files number primitives 0..n-1; should they not, leaf order has to do.)
  const size_t n = data.bvh.triangles.size();
  std::vector<uint32_t> order(n, UINT32_MAX);
  for (uint32_t i = 0; i < n; ++i) {
    const uint32_t p = data.bvh.triangles[i].primitive;
    if (p >= n || order[p] != UINT32_MAX) {
      std::iota(order.begin(), order.end(), 0u);
      break;
    }
    order[p] = i;
  }
  struct Corners {
    vec3 v0, v1, v2;
    uint material;
  };
  std::vector<Corners> corners;
  corners.reserve(order.size());
  for (uint32_t i : order) {
    const Triangle& t = data.bvh.triangles[i];
    corners.push_back(Corners{t.v0, t.v1, t.v2, t.material});
  }
  static_assert(sizeof(Corners) == 40, "no padding in what is hashed");
  std::vector<uint32_t> leafOrder;
  leafOrder.reserve(order.size());
  for (const Triangle& t : data.bvh.triangles) leafOrder.push_back(t.primitive);
  const std::vector<Camera> camera{p.camera};

  KeyValues s = {
      {"backend", backend},
      {"resolution", std::to_string(p.camera.width) + "x" + std::to_string(p.camera.height)},
      {"seed", std::to_string(p.seed)},
      {"max_depth", std::to_string(p.maxDepth)},
      {"rr", std::string(nameOf(kRouletteNames, p.russianRoulette != 0u))},
      {"rr_start_depth", std::to_string(p.rrStartDepth)},
      {"strategy", std::string(nameOf(kStrategyNames, p.strategy))},
      {"sampler", std::string(nameOf(kSamplerNames, p.samplerType))},
      {"intersection", std::string(nameOf(kIntersectionNames, p.fastIntersection != 0u))},
      {"builder", std::string(nameOf(kBuilderNames, settings.builder))},
      {"leaf_size", std::to_string(settings.maxLeafSize)},
      {"camera", hashOf(camera)},
      {"scene",
       hexHash(hashBytes(corners.data(), corners.size() * sizeof(Corners),
                         hashBytes(data.materials.data(), data.materials.size() * sizeof(Material),
                                   hashBytes(data.normals.data(),
                                             data.normals.size() * sizeof(TriangleNormals)))))},
      {"bvh",
       hexHash(hashBytes(
           leafOrder.data(), leafOrder.size() * sizeof(uint32_t),
           hashBytes(data.emitters.data(), data.emitters.size() * sizeof(Emitter),
                     hashBytes(data.bvh.nodes.data(), data.bvh.nodes.size() * sizeof(BvhNode)))))},
  };
  // Media only where the scene has them (the settings of scenes without stay as they were).
  if (!data.media.empty()) {
    const std::vector<uint32_t> cameraMedium{p.cameraMedium};
    s.emplace_back("media",
                   hexHash(hashBytes(
                       data.media.data(), data.media.size() * sizeof(Medium),
                       hashBytes(data.mediumGrids.data(), data.mediumGrids.size() * sizeof(float),
                                 hashBytes(data.mediumInterfaces.data(),
                                           data.mediumInterfaces.size() * sizeof(MediumInterface),
                                           hashBytes(cameraMedium.data(), sizeof(uint32_t)))))));
  }
  // The integrator where it is not the path tracer (states written before others stay valid).
  if (data.integrator != kIntegratorPath) {
    s.emplace_back("integrator", std::string(nameOf(kIntegratorNames, data.integrator)));
  }
  // Photon mapping's parameters, which every iteration's estimate depends on.
  if (data.integrator == kIntegratorSppm) {
    char radius[32];
    std::snprintf(radius, sizeof radius, "%.9g", double(data.sppm.radius));
    s.emplace_back("sppm_radius", std::string(radius));
    s.emplace_back("sppm_photons", std::to_string(sppmPhotonsPerIteration(data)));
  }
  // The light BVH only where the render uses it: the power and uniform samplers differ in the
  // emitter table, which the states already compare, and states written before it stay valid.
  if (!data.lightBvh.empty()) {
    s.emplace_back("light_sampler", std::string(nameOf(kLightSamplerNames, kLightSamplerBvh)));
  }
  // Ray differentials' scale (pbrt-v4's, from the samples per pixel) where textures read the
  // footprint: samples of another scale filter textures otherwise.
  if (p.footprints != 0u) {
    char scale[32];
    std::snprintf(scale, sizeof scale, "%.9g", double(p.differentialScale));
    s.emplace_back("differential_scale", std::string(scale));
  }
  s.insert(s.end(), backendExtra.begin(), backendExtra.end());
  return s;
}

SampleRange parseSampleRange(const std::string& text, const std::string& option) {
  const size_t colon = text.find(':');
  uint64_t first = 0, count = 0;
  auto number = [](std::string_view t, uint64_t& v) {
    const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
    return ec == std::errc() && end == t.data() + t.size() && !t.empty();
  };
  if (colon == std::string::npos || !number(std::string_view(text).substr(0, colon), first) ||
      !number(std::string_view(text).substr(colon + 1), count) || count == 0 ||
      first + count > UINT32_MAX || count > uint64_t(INT32_MAX)) {
    throw InputError(option + ": expected FIRST:COUNT (sample indices FIRST to FIRST+COUNT-1, " +
                     "COUNT > 0), got '" + text + "'");
  }
  return SampleRange{uint32_t(first), uint32_t(first + count)};
}

bool isStatePath(const std::string& path) {
  return lowercaseExtension(path) == kStateExtension;
}

int runMerge(const MergeArgs& args) {
  // Check every output before reading anything.
  for (const std::string& out : args.outputs) {
    if (!isStatePath(out)) imageFormatOf(out);
    const auto dir = std::filesystem::path(out).parent_path();
    if (!dir.empty() && !std::filesystem::is_directory(dir)) {
      throw InputError(out + ": directory '" + dir.string() + "' does not exist");
    }
  }
  std::set<std::string> seen;
  for (const std::string& path : args.states) {
    if (!seen.insert(std::filesystem::weakly_canonical(path).string()).second) {
      throw InputError(path + ": given twice");
    }
  }
  // One state in memory at a time, its film merged at once; what the checks need is kept.
  FilmStateMerger merger;

  // The samples a complete merge holds: the job the slices came from, when they all say; else
  // the span of the states' samples.
  SampleRange expected{UINT32_MAX, 0};
  std::optional<std::string> job;
  bool firstState = true;
  int taskCount = 0;
  std::set<int> tasks;
  for (const std::string& path : args.states) {
    FilmState state = readFilmState(path);
    for (const SampleRange& r : state.ranges) {
      expected.first = std::min(expected.first, r.first);
      expected.end = std::max(expected.end, r.end);
    }
    const std::string* j = state.infoValue("job");
    if (firstState && j) job = *j;
    if (!j || (job && *j != *job)) job.reset();
    firstState = false;
    int index = 0, count = 0;
    if (parseTask(state.infoValue("task"), index, count) &&
        (taskCount == 0 || taskCount == count)) {
      taskCount = count;
      tasks.insert(index);
    } else {
      taskCount = -1;  // not all from one job's tasks: no task names
    }
    merger.add(NamedFilmState{path, std::move(state)});
  }
  FilmState merged = merger.finish();
  if (job) expected = parseSampleRange(*job, args.states.front() + ": info job");
  if (expected.first > expected.end) expected = SampleRange{};

  const std::vector<SampleRange> missing = missingRanges(merged.ranges, expected);
  if (!missing.empty()) {
    std::string text;
    for (const SampleRange& r : missing) text += (text.empty() ? "" : ", ") + r.toString();
    if (taskCount > 0) {
      std::string absent;
      for (int t = 0; t < taskCount; ++t) {
        if (!tasks.count(t)) absent += (absent.empty() ? "" : ", ") + std::to_string(t);
      }
      if (!absent.empty()) {
        text += " (no state from task" +
                std::string(absent.find(',') != std::string::npos ? "s " : " ") + absent + " of " +
                std::to_string(taskCount) + ")";
      }
    }
    if (!args.partial) {
      throw InputError("missing samples " + text + " of " + expected.toString() +
                       ": render them and merge again, or merge what there is with --partial");
    }
    std::fprintf(stderr,
                 "warning: missing samples %s of %s: the image has %u of %u samples per "
                 "pixel\n",
                 text.c_str(), expected.toString().c_str(), merged.samplesPerPixel(),
                 expected.count());
  }

  // States first: they are what a later merge or resume needs.
  for (const std::string& out : args.outputs) {
    if (isStatePath(out)) writeFilmState(merged, out);
  }
  const Film film = merged.combinedFilm();
  const Image image = film.resolve();
  for (const std::string& out : args.outputs) {
    if (!isStatePath(out)) writeImage(image, out);
  }
  std::string ranges;
  for (const SampleRange& r : merged.ranges) ranges += (ranges.empty() ? "" : ",") + r.toString();
  const uint64_t invalid = film.totalInvalid();
  std::printf("merged=%zu resolution=%dx%d spp=%u samples=%s missing=%u invalid_samples=%llu\n",
              args.states.size(), merged.film.width, merged.film.height, merged.samplesPerPixel(),
              ranges.empty() ? "none" : ranges.c_str(),
              expected.count() - std::min(expected.count(), merged.samplesPerPixel()),
              (unsigned long long)invalid);
  if (invalid > 0) {
    printInvalidSamples(invalid, 0);
    return kExitFailure;
  }
  return kExitOk;
}

}  // namespace pt
