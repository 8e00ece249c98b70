// The `pt` command line: render a scene, compare two images. Input errors print one line
// and exit with kExitInputError; see `pt --help` and README.md.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include <sys/resource.h>

#include <CLI/CLI.hpp>

#include "cli/converge.h"
#include "cli/film_states.h"
#include "cli/interrupt.h"
#include "cli/overrides.h"
#include "cli/progress.h"
#include "common/check.h"
#include "common/named_values.h"
#include "cpu/bdpt.h"
#include "cpu/integrator.h"
#include "cpu/sppm.h"
#include "image/film_state.h"
#include "image/image.h"
#include "render/prepare.h"
#include "render/render_options.h"
#include "scene/load_scene.h"
#include "scene/scene.h"
#include "vulkan/backend.h"
#include "vulkan/device_info.h"

namespace pt {
namespace {

struct RenderArgs {
  std::string scene;
  std::string backend = "vulkan";
  std::string device;
  bool validation = false;
  bool noSpecialize = false;
  bool strict = false;      // pbrt-v4 and glTF files: warnings are errors
  std::string camera;       // glTF files: the camera, by index or name
  std::string environment;  // glTF files: an environment image
  std::string debugPixel;   // "X,Y"
  SceneOverrides overrides;
  std::optional<int> spp;
  int threads = 0;
  int samplesPerPass = 0;            // 0: the Vulkan backend chooses
  std::vector<std::string> outputs;  // images, or film states (.ptstate)
  // Film states: written every checkpointEvery seconds, when interrupted and at the end.
  std::string checkpoint;
  double checkpointEvery = 60.0;
  std::string resume;                       // a film state to continue
  std::string samples;                      // "FIRST:COUNT": one slice of sample indices
  std::optional<int> taskIndex, taskCount;  // slice taskIndex of taskCount equal slices
};

struct DiffArgs {
  std::string a, b, heatmap;
  double threshold = 1e-3;
  double maxFraction = 0.005;
  double heatmapScale = 0.0;
};

// Peak resident memory of this process so far, in MiB (getrusage: Linux reports KiB).
double peakResidentMiB() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return double(usage.ru_maxrss) / 1024.0;
}

// The slice of the job's samples that `--task-index`/`--task-count` (or a Slurm array task's
// SLURM_ARRAY_TASK_ID) choose, if any.
std::optional<std::pair<int, int>> chosenTask(const RenderArgs& args) {
  std::optional<int> index = args.taskIndex;
  if (!index && args.taskCount) {
    const char* env = std::getenv("SLURM_ARRAY_TASK_ID");
    if (!env) {
      throw InputError(
          "--task-count: give --task-index, or run as a Slurm array task "
          "(SLURM_ARRAY_TASK_ID)");
    }
    char extra = 0;
    int value = -1;
    if (std::sscanf(env, "%d%c", &value, &extra) != 1 || value < 0) {
      throw InputError(std::string("SLURM_ARRAY_TASK_ID: expected a task index, got '") + env +
                       "'");
    }
    index = value;
  }
  if (!index) return std::nullopt;
  if (!args.taskCount) throw InputError("--task-index: give --task-count too");
  if (*index >= *args.taskCount) {
    throw InputError("task index " + std::to_string(*index) + " is not below --task-count " +
                     std::to_string(*args.taskCount));
  }
  return std::make_pair(*index, *args.taskCount);
}

// Refuses outputs that cannot be written before any time is spent on the render.
void checkOutputPath(const std::filesystem::path& path, bool state) {
  if (!state) imageFormatOf(path);
  const auto dir = path.parent_path();
  if (!dir.empty() && !std::filesystem::is_directory(dir)) {
    throw InputError(path.string() + ": directory '" + dir.string() + "' does not exist");
  }
  if (std::filesystem::is_directory(path)) throw InputError(path.string() + ": is a directory");
}

int runRender(const RenderArgs& args) {
  if (args.backend == "cpu" && args.samplesPerPass != 0) {
    throw InputError("--samples-per-pass applies to the Vulkan backend only");
  }
  const std::optional<std::pair<int, int>> task = chosenTask(args);
  std::optional<SampleRange> sliceArg;
  if (!args.samples.empty()) sliceArg = parseSampleRange(args.samples, "--samples");

  // Outputs: images and film states. A render that keeps a film state writes no default image.
  std::vector<std::filesystem::path> images;
  std::vector<std::filesystem::path> states;
  for (const std::string& out : args.outputs) (isStatePath(out) ? states : images).push_back(out);
  std::string checkpoint = args.checkpoint;
  if (checkpoint.empty()) checkpoint = args.resume;  // a resumed render keeps its state file
  if (!checkpoint.empty()) states.push_back(checkpoint);
  if ((sliceArg || task) && states.empty()) {
    throw InputError(std::string(sliceArg ? "--samples" : "--task-index") +
                     ": give --checkpoint FILE: a slice's film state is what `pt merge` combines");
  }
  if (images.empty() && states.empty()) {
    images.push_back(std::filesystem::path(args.scene).stem() += ".png");
  }
  for (const auto& path : images) checkOutputPath(path, false);
  for (const auto& path : states) checkOutputPath(path, true);
  // A film state to continue is read before the scene, so that a bad one is refused at once.
  std::optional<FilmState> resumed;
  if (!args.resume.empty()) resumed = readFilmState(args.resume);

  const auto loadStart = std::chrono::steady_clock::now();
  Scene scene = loadScene(args.scene, SceneLoadOptions{.strict = args.strict,
                                                       .camera = args.camera,
                                                       .environment = args.environment});
  const double loadSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - loadStart).count();
  for (const std::string& w : scene.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());

  args.overrides.applySppm(scene);
  RenderSettings settings = args.overrides.toSettings(args.backend);
  settings.spp = args.spp;  // unset: the scene's
  // A film too large for memory is refused before the BVH build and the device start-up, with
  // the file (or the options) it came from.
  const int width = settings.width.value_or(scene.camera.width);
  const int height = settings.height.value_or(scene.camera.height);
  const std::string sizeFrom =
      args.scene + (settings.width || settings.height ? ": with --width/--height, " : ": ");
  Film::checkFitsInMemory(width, height, sizeFrom);
  if (settings.integrator.value_or(scene.integrator.integrator) == kIntegratorSppm) {
    checkSppmFitsInMemory(width, height, sizeFrom);  // the film and sppm's state together
  }
  const SceneData data = prepareScene(std::move(scene), settings);

  // The integrators besides the path tracer, for what they render: bidirectional path tracing
  // (cpu/bdpt.h, vulkan/bdpt.h) and photon mapping (cpu/sppm.h, vulkan/sppm.h), whose photons
  // start as BDPT's light subpaths.
  const std::optional<BdptStrategy> bdptStrategy = parseBdptStrategy(args.overrides.strategy);
  const std::string integrator(nameOf(kIntegratorNames, data.integrator));
  if (data.integrator != kIntegratorPath) {
    checkBdptScene(data, args.scene, integrator);
    if (!args.debugPixel.empty()) throw InputError("--debug-pixel: the path integrator's only");
  }
  if (data.integrator == kIntegratorBdpt) {
    if (bdptMaxDepth(data) < data.params.maxDepth) {
      std::fprintf(stderr,
                   "warning: %s: maximum depth %u is above the bdpt integrator's limit: %u\n",
                   args.scene.c_str(), data.params.maxDepth, bdptMaxDepth(data));
    }
  } else if (bdptStrategy) {
    throw InputError("--strategy " + args.overrides.strategy +
                     ": one strategy of the bdpt integrator (give --integrator bdpt)");
  }
  if (data.integrator != kIntegratorSppm &&
      (args.overrides.sppmRadius || args.overrides.sppmPhotons)) {
    throw InputError(std::string(args.overrides.sppmRadius ? "--sppm-radius" : "--sppm-photons") +
                     ": a parameter of the sppm integrator (give --integrator sppm)");
  }
  // Photon mapping's iterations build on each other: a render is continued from its state
  // (--checkpoint, --resume), never split.
  if (data.integrator == kIntegratorSppm && (sliceArg || task)) {
    throw InputError(std::string(sliceArg ? "--samples" : "--task-index") +
                     ": the sppm integrator's pixels depend on every iteration before, so its "
                     "render cannot be split or merged (render it in one job; --checkpoint and "
                     "--resume continue it)");
  }

  const Camera& cam = data.params.camera;
  int debugX = -1, debugY = -1;
  if (!args.debugPixel.empty()) {
    char extra = 0;
    if (std::sscanf(args.debugPixel.c_str(), "%d,%d%c", &debugX, &debugY, &extra) != 2 ||
        debugX < 0 || debugY < 0 || debugX >= int(cam.width) || debugY >= int(cam.height)) {
      throw InputError("--debug-pixel: expected X,Y inside the " + std::to_string(cam.width) + "x" +
                       std::to_string(cam.height) + " image, got '" + args.debugPixel + "'");
    }
  }

  VulkanRenderOptions vulkan;
  vulkan.context.device = args.device;
  // PT_VALIDATION=1 turns the validation layers on without changing command lines (tests).
  const char* env = std::getenv("PT_VALIDATION");
  vulkan.context.validation = args.validation || (env && std::string(env) == "1");
  vulkan.samplesPerPass = args.samplesPerPass;
  vulkan.specialize = !args.noSpecialize;
  vulkan.context.debugPrintf = debugX >= 0;
  vulkan.debugPixelX = debugX;
  vulkan.debugPixelY = debugY;
  const bool onCpu = args.backend == "cpu";

  // The sample indices this render covers: the job's [0, spp), or one slice of it. On Vulkan
  // a slice starts at a batch boundary, or it would not merge to the one-run image's bits.
  const SampleRange job{0, uint32_t(data.spp)};
  SampleRange target = job;
  // BDPT's device film is exact, folded whole passes at a time: any sample starts a slice.
  const uint32_t unit = onCpu || data.integrator == kIntegratorBdpt ? 1u : vulkanBatchSize(vulkan);
  if (sliceArg) {
    target = *sliceArg;
    if (target.first % unit != 0) {
      throw InputError("--samples " + args.samples + ": on the Vulkan backend FIRST must be a " +
                       "multiple of " + std::to_string(unit) +
                       " (the samples per fold), so that slices merge to the one-run image");
    }
  } else if (task) {
    target = taskSlice(job, task->first, task->second, unit);
    if (target.count() == 0) {
      throw InputError("--task-count " + std::to_string(task->second) + ": task " +
                       std::to_string(task->first) + " gets no samples of " + job.toString() +
                       (unit > 1 ? " (slices are whole batches of " + std::to_string(unit) + ")"
                                 : std::string()));
    }
  }

  // The film state: resumed, or new. (Its settings hash the scene: only when kept.)
  FilmState state;
  if (!states.empty()) {
    state.settings = imageSettings(data, settings, args.backend,
                                   onCpu ? KeyValues{} : vulkanImageSettings(vulkan));
  }
  state.film = Film(int(cam.width), int(cam.height));
  if (resumed) {
    const std::string diff = settingsDifference(resumed->settings, state.settings);
    if (!diff.empty()) {
      throw InputError(args.resume + ": rendered with other settings (there vs here): " + diff);
    }
    const std::vector<SampleRange>& have = resumed->ranges;
    if (have.size() > 1) {
      throw InputError(args.resume + ": holds samples with a gap; only a state of one range of " +
                       "samples can be continued (merge it instead)");
    }
    if (!have.empty() && have[0].first != target.first) {
      throw InputError(args.resume + ": holds samples " + have[0].toString() +
                       ", but this render's samples start at " + std::to_string(target.first) +
                       " (give the --samples or task it was rendered with)");
    }
    if (!have.empty() && have[0].end > target.end) {
      throw InputError(args.resume + ": holds samples " + have[0].toString() +
                       ", more than this render's " + target.toString() + " (give a larger --spp)");
    }
    state.film = std::move(resumed->film);
    state.ranges = resumed->ranges;
    state.open = std::move(resumed->open);
    state.sppm = std::move(resumed->sppm);
    state.info = resumed->info;
  }
  auto setInfo = [&](const std::string& key, const std::string& value) {
    for (auto& [k, v] : state.info) {
      if (k == key) {
        v = value;
        return;
      }
    }
    state.info.emplace_back(key, value);
  };
  setInfo("scene", args.scene);
  if (task) {
    setInfo("job", job.toString());
    setInfo("task", std::to_string(task->first) + "/" + std::to_string(task->second));
  }
  const uint32_t start = state.ranges.empty() ? target.first : state.ranges[0].end;
  if (resumed) {
    std::fprintf(stderr, "resuming %s: %u of %u samples per pixel done\n", args.resume.c_str(),
                 start - target.first, target.count());
  }

  if (debugX >= 0) {
    // The CPU reference's paths first; the shader's follow from the validation layer.
    uint64_t rays = 0;
    for (uint32_t s = start; s < target.end; ++s) {
      sampleRadiance(data, uvec2(debugX, debugY), s, rays, /*debugPrint=*/true);
    }
  }

  // Stop cleanly at SIGINT or SIGTERM; write the film state every checkpointEvery seconds.
  const InterruptGuard interrupt;
  auto stateAt = [&](uint32_t end) {
    state.ranges.clear();
    if (end > target.first) state.ranges.push_back(SampleRange{target.first, end});
  };
  auto writeStates = [&] {
    for (const auto& path : states) writeFilmState(state, path);
  };
  auto lastCheckpoint = std::chrono::steady_clock::now();
  auto checkpointDue = [&](int done) {
    if (checkpoint.empty()) return;
    const auto now = std::chrono::steady_clock::now();
    if (std::chrono::duration<double>(now - lastCheckpoint).count() < args.checkpointEvery) return;
    stateAt(start + uint32_t(done));
    writeFilmState(state, checkpoint);
    lastCheckpoint = std::chrono::steady_clock::now();
  };

  Progress progress("rendering");
  RenderStats stats;  // what both backends report
  std::string backendInfo;
  std::string effects = data.effects.toString();
  uint32_t validationErrors = 0;
  OpenBatch carried = std::move(state.open);  // the film absorbs it at the first fold
  state.open = OpenBatch{};
  if (onCpu) {
    CpuRenderOptions options;
    options.threads = args.threads;
    options.firstSample = start;
    options.spp = int(target.end - start);
    options.progress = [&progress](double f) { progress.update(f); };
    options.stop = &interrupt.stopFlag();
    options.checkpoint = checkpointDue;
    options.sppmPixels = &state.sppm;
    if (bdptStrategy) options.bdptStrategy = *bdptStrategy;
    const CpuRenderStats cpu = renderCpu(data, options, state.film);
    stats = cpu;
    backendInfo = "backend=cpu threads=" + std::to_string(cpu.threads);
  } else {
    VulkanRenderOptions& options = vulkan;
    options.firstSample = start;
    options.spp = int(target.end - start);
    options.progress = [&progress](double f) { progress.update(f); };
    options.stop = &interrupt.stopFlag();
    options.checkpoint = checkpointDue;
    options.sppmPixels = &state.sppm;
    if (bdptStrategy) options.bdptStrategy = *bdptStrategy;
    options.openBatch = &carried;
    options.keepOpenBatch = !states.empty();
    VulkanRenderStats gpu = renderVulkan(data, options, state.film);
    stats = gpu;
    state.open = std::move(gpu.open);
    validationErrors = gpu.validationErrors;
    // Throughput from the device's timestamps; wall time also counts set-up and upload.
    backendInfo = "backend=vulkan device=\"" + gpu.device +
                  "\" wall_seconds=" + std::to_string(gpu.wallSeconds) +
                  " max_loop_iterations=" + std::to_string(gpu.maxLoopIterations);
    if (args.noSpecialize) effects = "all(unspecialized)";
    const std::string* before = resumed ? resumed->infoValue("device") : nullptr;
    if (before && *before != gpu.device) {
      std::fprintf(stderr,
                   "warning: %s was rendered on \"%s\", continued on \"%s\": the image is as "
                   "valid, but its bits differ from a render on one device\n",
                   args.resume.c_str(), before->c_str(), gpu.device.c_str());
    }
    setInfo("device", gpu.device);
  }
  progress.finish();

  // What the film holds now: whole passes (and on Vulkan perhaps an open batch).
  const uint32_t reached = start + uint32_t(stats.samplesDone);
  stateAt(reached);
  const uint32_t spp = reached - target.first;
  const bool interrupted = stats.stopped;
  if (spp > 0) {
    writeStates();  // first: it is what a later resume or merge needs
    const Image image = state.combinedFilm().resolve();
    for (const auto& path : images) writeImage(image, path);
  }

  // Photon mapping's estimate is consistent (it converges as its radii shrink), not unbiased.
  std::string integratorInfo = integrator;
  if (data.integrator == kIntegratorSppm) {
    char radius[32];
    std::snprintf(radius, sizeof radius, "%g", double(data.sppm.radius));
    integratorInfo += " estimator=consistent(biased) photons_per_iteration=" +
                      std::to_string(sppmPhotonsPerIteration(data)) + " radius=" + radius;
  }
  std::printf(
      "%s integrator=%s resolution=%ux%u spp=%u seconds=%.3f Mrays/s=%.3f effects=%s "
      "triangles=%zu "
      "load_s=%.3f bvh_builder=%s bvh_nodes=%zu bvh_build_s=%.4f bvh_sah_cost=%.2f "
      "peak_rss_mib=%.0f invalid_samples=%llu\n",
      backendInfo.c_str(), integratorInfo.c_str(), cam.width, cam.height, spp, stats.seconds,
      stats.seconds > 0.0 ? double(stats.rays) / stats.seconds * 1e-6 : 0.0, effects.c_str(),
      data.bvh.triangles.size(), loadSeconds,
      std::string(nameOf(kBuilderNames, settings.builder)).c_str(), data.bvh.nodes.size(),
      data.bvh.buildSeconds, data.bvh.sahCost, peakResidentMiB(),
      (unsigned long long)stats.invalidSamples);
  std::fflush(stdout);
  if (interrupted) {
    std::string what = spp == 0 ? "before a pass was complete: nothing written"
                                : "after " + std::to_string(spp) + " of " +
                                      std::to_string(target.count()) + " samples per pixel";
    if (spp > 0) {
      what += states.empty() ? " (no --checkpoint: it cannot be continued)"
                             : "; continue with --resume " + states.back().string();
    }
    std::fprintf(stderr, "pt: stopped by %s %s\n", interrupt.signalName(), what.c_str());
    return kExitInterrupted;
  }
  int status = kExitOk;
  if (stats.invalidSamples > 0) {
    printInvalidSamples(stats.invalidSamples, stats.truncatedSamples);
    status = kExitFailure;
  }
  if (validationErrors > 0) {
    std::fprintf(stderr, "error: %u Vulkan validation errors\n", validationErrors);
    status = kExitFailure;
  }
  return status;
}

int runDevices() {
  const std::vector<DeviceInfo> devices = listVulkanDevices();
  if (devices.empty()) throw NoDeviceError("no Vulkan device found");
  for (const DeviceInfo& d : devices) {
    std::printf("%u: %s (%s; %s)%s%s\n", d.index, d.name.c_str(), d.type.c_str(), d.driver.c_str(),
                d.suitable ? "" : " unsuitable: ", d.whyNot.c_str());
  }
  return kExitOk;
}

int runDiff(const DiffArgs& args) {
  const Image a = readImage(args.a);
  const Image b = readImage(args.b);
  const DiffStats d = diffImages(a, b, args.threshold);
  const double fraction = d.pixelCount ? double(d.pixelsOverThreshold) / double(d.pixelCount) : 0;
  std::printf("rmse=%.6g relmse=%.6g max_abs=%.6g over_threshold=%zu/%zu (%.4f%%) non_finite=%zu\n",
              d.rmse, d.relMse, d.maxAbsError, d.pixelsOverThreshold, d.pixelCount,
              100.0 * fraction, d.nonFinitePixels);
  if (!args.heatmap.empty()) {
    const double scale =
        args.heatmapScale > 0 ? args.heatmapScale : (d.maxAbsError > 0 ? d.maxAbsError : 1.0);
    writeImage(diffHeatmap(a, b, scale), args.heatmap);
  }
  const bool agree = d.nonFinitePixels == 0 && fraction <= args.maxFraction;
  std::printf("%s\n", agree ? "images agree" : "images differ");
  return agree ? kExitOk : kExitFailure;
}

// CLI11's PositiveNumber, with a message a user can read ("must be a positive number, not 0")
// rather than its range up to the largest double.
const CLI::Validator kPositive(
    [](std::string& value) -> std::string {
      double number = 0.0;
      if (!CLI::detail::lexical_cast(value, number) || !(number > 0.0)) {
        return "must be a positive number, not " + value;
      }
      return {};
    },
    "POSITIVE");

// Options both `render` and `converge` take: overrides of the scene's settings.
void addOverrideOptions(CLI::App* cmd, SceneOverrides& o) {
  cmd->add_option("--seed", o.seed, "Random seed (default: the scene's)")
      ->check(CLI::Range(0LL, 4294967295LL));
  cmd->add_option("--width", o.width, "Image width (default: the scene's)")->check(kPositive);
  cmd->add_option("--height", o.height, "Image height (default: the scene's)")->check(kPositive);
  cmd->add_option("--max-depth", o.maxDepth, "Maximum scattering events per path")
      ->check(CLI::Range(0, 100000));
  cmd->add_option(
         "--leaf-size", o.leafSize,
         "Maximum triangles per BVH leaf (default: " + std::to_string(kDefaultLeafSizeCpu) +
             " on the CPU, " + std::to_string(kDefaultLeafSizeVulkan) + " with Vulkan)")
      ->check(CLI::Range(1, 64));
  cmd->add_option("--integrator", o.integrator,
                  "Light transport: " + describeNames(kIntegratorNames) + "; default: the scene's")
      ->check(CLI::IsMember(namesOf(kIntegratorNames)));
  cmd->add_option("--strategy", o.strategy,
                  "Direct light: " + describeNames(kStrategyNames) +
                      "; default: the scene's. With --integrator bdpt, S,T renders strategy "
                      "(S light vertices, T camera vertices) alone, without its MIS weight")
      ->check(CLI::Validator(
          [](std::string& value) -> std::string {
            if (valueNamed(kStrategyNames, value) || parseBdptStrategy(value)) return {};
            return "expected " + quotedNames(kStrategyNames) +
                   " or S,T (S >= 0, T >= 1, not 1,1), not " + value;
          },
          "STRATEGY"));
  cmd->add_option("--rr", o.roulette, "Russian roulette: on or off; default: the scene's")
      ->check(CLI::IsMember(namesOf(kRouletteNames)));
  cmd->add_option("--builder", o.builder, "BVH builder: " + describeNames(kBuilderNames))
      ->check(CLI::IsMember(namesOf(kBuilderNames)))
      ->capture_default_str();
  cmd->add_option("--intersection", o.intersection,
                  "Ray/triangle test: " + describeNames(kIntersectionNames))
      ->check(CLI::IsMember(namesOf(kIntersectionNames)))
      ->capture_default_str();
  cmd->add_option("--sampler", o.sampler,
                  "Random numbers: " + describeNames(kSamplerNames) + "; default: the scene's")
      ->check(CLI::IsMember(namesOf(kSamplerNames)));
  cmd->add_option("--light-sampler", o.lightSampler,
                  "How light sampling chooses a light: " + describeNames(kLightSamplerNames) +
                      "; default: the scene's (pbrt-v4's: bvh)")
      ->check(CLI::IsMember(namesOf(kLightSamplerNames)));
  cmd->add_option("--sppm-radius", o.sppmRadius,
                  "The sppm integrator's initial search radius, in scene units (default: the "
                  "scene's, else pbrt-v4's 1)")
      ->check(kPositive);
  cmd->add_option("--sppm-photons", o.sppmPhotons,
                  "Photons per iteration of the sppm integrator (default: the scene's, else one "
                  "per pixel)")
      ->check(CLI::Range(int64_t(1), kSppmMaxPhotonsPerIteration));
}

}  // namespace
}  // namespace pt

int main(int argc, char** argv) {
  using namespace pt;
  CLI::App app{"pt: a physically based path tracer (Vulkan compute, CPU reference)"};
  app.require_subcommand(1);

  RenderArgs r;
  CLI::App* render = app.add_subcommand("render", "Render a scene to one or more images");
  render->add_option("scene", r.scene, "Scene file (JSON, pbrt-v4 or glTF)")->required();
  render->add_option("--backend", r.backend, "vulkan (GPU, or lavapipe without one) or cpu")
      ->check(CLI::IsMember({"vulkan", "cpu"}))
      ->capture_default_str();
  render->add_option("--device", r.device,
                     "Vulkan device: index or part of the name (see `devices`)");
  render->add_flag("--validation", r.validation, "Enable the Vulkan validation layers");
  render->add_flag("--no-specialize", r.noSpecialize,
                   "Compile every effect into the shader (to measure what specialization saves)");
  render->add_flag("--strict", r.strict,
                   "pbrt-v4 and glTF files: what the reader would warn about (ignored or "
                   "rendered otherwise than the format says) is an error, exit status 2");
  render->add_option("--camera", r.camera,
                     "glTF files: the camera to render from, by index in the file's cameras or "
                     "by name (default: the first the scene places)");
  render->add_option(
      "--env", r.environment,
      "glTF files: an environment image (.exr, .pfm, .png or .hdr; latitude-longitude, "
      "+y up) to light the model (default: a white sky where it has no light)");
  render->add_option("--spp", r.spp, "Samples per pixel (default: the scene's)")->check(kPositive);
  render->add_option("--threads", r.threads, "CPU threads (default: all)")->check(kPositive);
  render
      ->add_option("--samples-per-pass", r.samplesPerPass,
                   "Vulkan: samples per pixel in one dispatch (default: as many as keep a "
                   "dispatch to about half a second; lavapipe's loop cap limits it)")
      ->check(kPositive);
  addOverrideOptions(render, r.overrides);
  render->add_option("--debug-pixel", r.debugPixel,
                     "Print pixel X,Y's paths from the CPU reference and from the shader");
  render->add_option("--out", r.outputs,
                     "Output image (.png, .exr, .pfm) or film state (.ptstate); repeatable");
  render->add_option("--checkpoint", r.checkpoint,
                     "Film state file, written every --checkpoint-every seconds, when "
                     "interrupted and at the end (continue it with --resume)");
  render
      ->add_option("--checkpoint-every", r.checkpointEvery,
                   "Seconds between checkpoints of the film state")
      ->check(kPositive)
      ->capture_default_str();
  render->add_option("--resume", r.resume,
                     "Continue the render in this film state to the target spp (checkpoints go "
                     "back to it unless --checkpoint says otherwise)");
  CLI::Option* samples = render->add_option(
      "--samples", r.samples,
      "Render only sample indices FIRST to FIRST+COUNT-1 (a slice for `pt merge`)");
  CLI::Option* taskIndex =
      render
          ->add_option("--task-index", r.taskIndex,
                       "Render slice I of --task-count equal slices of the spp (default: "
                       "SLURM_ARRAY_TASK_ID)")
          ->check(CLI::NonNegativeNumber);
  CLI::Option* taskCount =
      render->add_option("--task-count", r.taskCount, "Number of slices the spp is split into")
          ->check(kPositive);
  samples->excludes(taskIndex)->excludes(taskCount)->excludes("--spp");

  DiffArgs d;
  CLI::App* diff = app.add_subcommand(
      "diff", "Compare image A against reference B; exit 0 when they agree, 1 when not");
  diff->add_option("a", d.a, "Image A (.exr, .pfm, .png)")->required();
  diff->add_option("b", d.b, "Reference image B")->required();
  diff->add_option("--heatmap", d.heatmap, "Write a heatmap of |A - B| (PNG)");
  diff->add_option("--heatmap-scale", d.heatmapScale,
                   "Difference mapped to the top of the heatmap (default: the max)");
  diff->add_option("--threshold", d.threshold,
                   "A pixel differs when a channel's |A - B| > threshold * max(1, |B|)")
      ->capture_default_str();
  diff->add_option("--max-fraction", d.maxFraction,
                   "The images agree when at most this fraction of pixels differ")
      ->capture_default_str();

  // ---- converge: error against a reference as samples double (host/converge) ----
  ConvergeArgs c;
  CLI::App* converge = app.add_subcommand(
      "converge",
      "Render at 1, 2, 4, ... N spp, writing the error against a reference and the time");
  converge->add_option("scene", c.scene, "Scene file (JSON)")->required();
  converge->add_option("--reference", c.reference, "Reference image (.exr, .pfm), same size")
      ->required();
  converge->add_option("--csv", c.csv, "CSV output, one row per level")->required();
  converge->add_option("--label", c.label, "First CSV column, names the configuration")
      ->capture_default_str();
  converge->add_option("--backend", c.backend, "vulkan or cpu")
      ->check(CLI::IsMember({"vulkan", "cpu"}))
      ->capture_default_str();
  converge->add_option("--device", c.device, "Vulkan device: index or part of the name");
  converge->add_option("--max-spp", c.maxSpp, "Largest samples per pixel")
      ->check(kPositive)
      ->capture_default_str();
  converge->add_option("--threads", c.threads, "CPU threads (default: all)")->check(kPositive);
  addOverrideOptions(converge, c.overrides);
  converge->add_flag("--no-specialize", c.noSpecialize, "Vulkan: compile every effect in");

  MergeArgs m;
  CLI::App* merge = app.add_subcommand(
      "merge", "Combine film states of disjoint sample ranges into the one-run image");
  merge->add_option("states", m.states, "Film state files (render --checkpoint)")->required();
  merge->add_option("--out", m.outputs,
                    "Output image (.png, .exr, .pfm) or film state (.ptstate); repeatable");
  merge->add_flag("--partial", m.partial,
                  "Merge even when samples are missing (the image has fewer spp)");

  CLI::App* devices = app.add_subcommand("devices", "List Vulkan devices");

  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "pt: %s\n", e.what());
    return kExitInputError;
  }

  try {
    if (*render) return runRender(r);
    if (*merge) return runMerge(m);
    if (*diff) return runDiff(d);
    if (*devices) return runDevices();
    if (*converge) return runConvergeCommand(c);
  } catch (const InputError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return kExitInputError;
  } catch (const NoDeviceError& e) {
    std::fprintf(stderr, "pt: no usable Vulkan device: %s\n", e.what());
    return kExitNoDevice;
  } catch (const std::system_error& e) {
    // Vulkan-Hpp's errors are system errors in the "vk::Result" category.
    const bool vulkan = std::string_view(e.code().category().name()) == "vk::Result";
    std::fprintf(stderr, "pt: %s error: %s\n", vulkan ? "Vulkan" : "system", e.what());
    return kExitInternal;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pt: error: %s\n", e.what());
    return kExitInternal;
  }
  return kExitOk;
}
