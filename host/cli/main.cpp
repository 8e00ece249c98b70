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
#include "cli/overrides.h"
#include "cli/progress.h"
#include "common/check.h"
#include "common/named_values.h"
#include "cpu/integrator.h"
#include "image/image.h"
#include "render/prepare.h"
#include "render/render_options.h"
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
  std::string debugPixel;  // "X,Y"
  SceneOverrides overrides;
  std::optional<int> spp;
  int threads = 0;
  int samplesPerPass = 1;
  std::vector<std::string> outputs;
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

int runRender(const RenderArgs& args) {
  if (args.backend == "cpu" && args.samplesPerPass != 1) {
    throw InputError("--samples-per-pass applies to the Vulkan backend only");
  }
  const auto loadStart = std::chrono::steady_clock::now();
  Scene scene = loadScene(args.scene);
  const double loadSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - loadStart).count();
  for (const std::string& w : scene.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());

  RenderSettings settings = args.overrides.toSettings();
  settings.spp = args.spp;  // unset: the scene's
  const SceneData data = prepareScene(std::move(scene), settings);

  std::vector<std::filesystem::path> outputs(args.outputs.begin(), args.outputs.end());
  if (outputs.empty()) outputs.push_back(std::filesystem::path(args.scene).stem() += ".png");
  // Check every output before spending time on the render.
  for (const auto& path : outputs) {
    imageFormatOf(path);
    const auto dir = path.parent_path();
    if (!dir.empty() && !std::filesystem::is_directory(dir)) {
      throw InputError(path.string() + ": directory '" + dir.string() + "' does not exist");
    }
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
    // The CPU reference's paths first; the shader's follow from the validation layer.
    uint64_t rays = 0;
    for (int s = 0; s < data.spp; ++s) {
      sampleRadiance(data, uvec2(debugX, debugY), uint32_t(s), rays, /*debugPrint=*/true);
    }
  }
  Film film(int(cam.width), int(cam.height));
  Progress progress("rendering");
  RenderStats stats;  // what both backends report
  std::string backendInfo;
  std::string effects = data.effects.toString();
  uint32_t validationErrors = 0;
  if (args.backend == "cpu") {
    CpuRenderOptions options;
    options.threads = args.threads;
    options.spp = data.spp;
    options.progress = [&progress](double f) { progress.update(f); };
    const CpuRenderStats cpu = renderCpu(data, options, film);
    stats = cpu;
    backendInfo = "backend=cpu threads=" + std::to_string(cpu.threads);
  } else {
    VulkanRenderOptions options;
    options.context.device = args.device;
    // PT_VALIDATION=1 turns the validation layers on without changing command lines (tests).
    const char* env = std::getenv("PT_VALIDATION");
    options.context.validation = args.validation || (env && std::string(env) == "1");
    options.spp = data.spp;
    options.samplesPerPass = args.samplesPerPass;
    options.specialize = !args.noSpecialize;
    options.context.debugPrintf = debugX >= 0;
    options.debugPixelX = debugX;
    options.debugPixelY = debugY;
    options.progress = [&progress](double f) { progress.update(f); };
    const VulkanRenderStats gpu = renderVulkan(data, options, film);
    stats = gpu;
    validationErrors = gpu.validationErrors;
    // Throughput from the device's timestamps; wall time also counts set-up and upload.
    backendInfo = "backend=vulkan device=\"" + gpu.device +
                  "\" wall_seconds=" + std::to_string(gpu.wallSeconds) +
                  " max_loop_iterations=" + std::to_string(gpu.maxLoopIterations);
    if (args.noSpecialize) effects = "all(unspecialized)";
  }
  progress.finish();

  const Image image = film.resolve();
  for (const auto& path : outputs) writeImage(image, path);

  std::printf(
      "%s resolution=%ux%u spp=%d seconds=%.3f Mrays/s=%.3f effects=%s triangles=%zu "
      "load_s=%.3f bvh_builder=%s bvh_nodes=%zu bvh_build_s=%.4f peak_rss_mib=%.0f "
      "invalid_samples=%llu\n",
      backendInfo.c_str(), cam.width, cam.height, data.spp, stats.seconds,
      double(stats.rays) / stats.seconds * 1e-6, effects.c_str(), data.bvh.triangles.size(),
      loadSeconds, std::string(nameOf(kBuilderNames, settings.builder)).c_str(),
      data.bvh.nodes.size(), data.bvh.buildSeconds, peakResidentMiB(),
      (unsigned long long)stats.invalidSamples);
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

// Options both `render` and `converge` take: overrides of the scene's settings.
void addOverrideOptions(CLI::App* cmd, SceneOverrides& o) {
  cmd->add_option("--seed", o.seed, "Random seed (default: the scene's)")
      ->check(CLI::Range(0LL, 4294967295LL));
  cmd->add_option("--width", o.width, "Image width (default: the scene's)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--height", o.height, "Image height (default: the scene's)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--max-depth", o.maxDepth, "Maximum scattering events per path")
      ->check(CLI::Range(0, 100000));
  cmd->add_option("--leaf-size", o.leafSize, "Maximum triangles per BVH leaf")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  cmd->add_option("--strategy", o.strategy,
                  "Direct light: " + describeNames(kStrategyNames) + "; default: the scene's")
      ->check(CLI::IsMember(namesOf(kStrategyNames)));
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
}

}  // namespace
}  // namespace pt

int main(int argc, char** argv) {
  using namespace pt;
  CLI::App app{"pt: a physically based path tracer (Vulkan compute, CPU reference)"};
  app.require_subcommand(1);

  RenderArgs r;
  CLI::App* render = app.add_subcommand("render", "Render a scene to one or more images");
  render->add_option("scene", r.scene, "Scene file (JSON)")->required();
  render->add_option("--backend", r.backend, "vulkan (GPU, or lavapipe without one) or cpu")
      ->check(CLI::IsMember({"vulkan", "cpu"}))
      ->capture_default_str();
  render->add_option("--device", r.device,
                     "Vulkan device: index or part of the name (see `devices`)");
  render->add_flag("--validation", r.validation, "Enable the Vulkan validation layers");
  render->add_flag("--no-specialize", r.noSpecialize,
                   "Compile every effect into the shader (to measure what specialization saves)");
  render->add_option("--spp", r.spp, "Samples per pixel (default: the scene's)")
      ->check(CLI::PositiveNumber);
  render->add_option("--threads", r.threads, "CPU threads (default: all)")
      ->check(CLI::PositiveNumber);
  render
      ->add_option("--samples-per-pass", r.samplesPerPass,
                   "Vulkan: samples per pixel in one dispatch (fewer dispatches for small "
                   "images; lavapipe's loop cap limits it)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  addOverrideOptions(render, r.overrides);
  render->add_option("--debug-pixel", r.debugPixel,
                     "Print pixel X,Y's paths from the CPU reference and from the shader");
  render->add_option("--out", r.outputs, "Output image (.png, .exr, .pfm); repeatable");

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
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  converge->add_option("--threads", c.threads, "CPU threads (default: all)")
      ->check(CLI::PositiveNumber);
  addOverrideOptions(converge, c.overrides);
  converge->add_flag("--no-specialize", c.noSpecialize, "Vulkan: compile every effect in");

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
