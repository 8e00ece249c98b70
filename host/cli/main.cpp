// The `pt` command line: render a scene, compare two images. Input errors print one line
// and exit with kExitInputError; see `pt --help` and README.md.
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli/progress.h"
#include "common/check.h"
#include "cpu/integrator.h"
#include "image/image.h"
#include "render/prepare.h"
#include "scene/scene.h"

namespace pt {
namespace {

struct RenderArgs {
  std::string scene;
  std::string backend = "cpu";
  int spp = 0, width = 0, height = 0, maxDepth = -1, threads = 0, leafSize = 4;
  long long seed = -1;
  std::vector<std::string> outputs;
};

struct DiffArgs {
  std::string a, b, heatmap;
  double threshold = 1e-3;
  double maxFraction = 0.005;
  double heatmapScale = 0.0;
};

int runRender(const RenderArgs& args) {
  const Scene scene = loadScene(args.scene);
  for (const std::string& w : scene.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());

  RenderSettings settings;
  settings.width = args.width;
  settings.height = args.height;
  settings.spp = args.spp;
  settings.seed = args.seed;
  settings.maxDepth = args.maxDepth;
  settings.maxLeafSize = args.leafSize;
  const SceneData data = prepareScene(scene, settings);

  std::vector<std::filesystem::path> outputs(args.outputs.begin(), args.outputs.end());
  if (outputs.empty()) outputs.push_back(std::filesystem::path(args.scene).stem() += ".png");
  // Check every output before spending time on the render.
  for (const auto& path : outputs) {
    std::string ext = path.extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (ext != ".png" && ext != ".exr" && ext != ".pfm") {
      throw InputError(path.string() + ": unknown image format '" + ext +
                       "' (use .png, .exr or .pfm)");
    }
    const auto dir = path.parent_path();
    if (!dir.empty() && !std::filesystem::is_directory(dir)) {
      throw InputError(path.string() + ": directory '" + dir.string() + "' does not exist");
    }
  }

  if (args.backend != "cpu") {
    throw InputError("--backend: '" + args.backend + "' is not available in this build (cpu)");
  }
  const Camera& cam = data.params.camera;
  Film film(int(cam.width), int(cam.height));
  CpuRenderOptions options;
  options.threads = args.threads;
  options.spp = data.spp;
  Progress progress("rendering");
  options.progress = [&progress](double f) { progress.update(f); };
  const RenderStats stats = renderCpu(data, options, film);
  progress.finish();

  const Image image = film.resolve();
  for (const auto& path : outputs) writeImage(image, path);

  std::printf(
      "backend=cpu threads=%d resolution=%ux%u spp=%d seconds=%.3f Mrays/s=%.3f effects=%s "
      "bvh_nodes=%zu bvh_build_s=%.4f invalid_samples=%llu\n",
      stats.threads, cam.width, cam.height, data.spp, stats.seconds,
      double(stats.rays) / stats.seconds * 1e-6, data.effects.toString().c_str(),
      data.bvh.nodes.size(), data.bvh.buildSeconds, (unsigned long long)stats.invalidSamples);
  if (stats.invalidSamples > 0) {
    std::fprintf(stderr, "error: %llu samples were NaN or Inf and were left out of the image\n",
                 (unsigned long long)stats.invalidSamples);
    return kExitFailure;
  }
  return kExitOk;
}

int runDiff(const DiffArgs& args) {
  const Image a = readImage(args.a);
  const Image b = readImage(args.b);
  const DiffStats d = diffImages(a, b, args.threshold);
  const double fraction = d.pixelCount ? double(d.pixelsOverThreshold) / double(d.pixelCount) : 0;
  std::printf(
      "rmse=%.6g relmse=%.6g max_abs=%.6g over_threshold=%zu/%zu (%.4f%%) non_finite=%zu\n",
      d.rmse, d.relMse, d.maxAbsError, d.pixelsOverThreshold, d.pixelCount, 100.0 * fraction,
      d.nonFinitePixels);
  if (!args.heatmap.empty()) {
    const double scale = args.heatmapScale > 0 ? args.heatmapScale
                                               : (d.maxAbsError > 0 ? d.maxAbsError : 1.0);
    writeImage(diffHeatmap(a, b, scale), args.heatmap);
  }
  const bool agree = d.nonFinitePixels == 0 && fraction <= args.maxFraction;
  std::printf("%s\n", agree ? "images agree" : "images differ");
  return agree ? kExitOk : kExitFailure;
}

}  // namespace
}  // namespace pt

int main(int argc, char** argv) {
  using namespace pt;
  CLI::App app{"pt: a physically based path tracer (CPU reference)"};
  app.require_subcommand(1);

  RenderArgs r;
  CLI::App* render = app.add_subcommand("render", "Render a scene to one or more images");
  render->add_option("scene", r.scene, "Scene file (JSON)")->required();
  render->add_option("--backend", r.backend, "cpu")->capture_default_str();
  render->add_option("--spp", r.spp, "Samples per pixel (default: the scene's)")
      ->check(CLI::PositiveNumber);
  render->add_option("--seed", r.seed, "Random seed (default: the scene's)")
      ->check(CLI::Range(0LL, 4294967295LL));
  render->add_option("--width", r.width, "Image width (default: the scene's)")
      ->check(CLI::PositiveNumber);
  render->add_option("--height", r.height, "Image height (default: the scene's)")
      ->check(CLI::PositiveNumber);
  render->add_option("--max-depth", r.maxDepth, "Maximum scattering events per path")
      ->check(CLI::Range(0, 100000));
  render->add_option("--threads", r.threads, "CPU threads (default: all)")
      ->check(CLI::PositiveNumber);
  render->add_option("--leaf-size", r.leafSize, "Maximum triangles per BVH leaf")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
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
  } catch (const InputError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return kExitInputError;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pt: error: %s\n", e.what());
    return kExitInternal;
  }
  return kExitOk;
}
