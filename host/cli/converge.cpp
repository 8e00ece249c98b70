// `pt converge`; see converge.h.
#include "cli/converge.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "common/check.h"
#include "cpu/integrator.h"
#include "scene/scene.h"
#include "vulkan/backend.h"

namespace pt {
namespace {

// The reference must have the render's resolution and hold finite values only (diffImages
// would leave non-finite pixels out of the error, hiding a broken reference).
void checkReference(const Image& reference, const Camera& camera) {
  if (reference.width != int(camera.width) || reference.height != int(camera.height)) {
    throw InputError("reference is " + std::to_string(reference.width) + "x" +
                     std::to_string(reference.height) + " but the render is " +
                     std::to_string(camera.width) + "x" + std::to_string(camera.height) +
                     " (render the reference at the same --width and --height)");
  }
  for (const glm::vec3& p : reference.pixels) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      throw InputError("reference has NaN or infinite pixels");
    }
  }
}

}  // namespace

std::vector<int> convergenceLevels(int maxSpp) {
  if (maxSpp < 1) throw InputError("--max-spp must be at least 1");
  std::vector<int> levels;
  for (int spp = 1; spp < maxSpp; spp *= 2) levels.push_back(spp);
  levels.push_back(maxSpp);
  return levels;
}

std::vector<ConvergeRow> runConvergence(const SceneData& scene, const Image& reference,
                                        const ConvergeOptions& options) {
  const Camera& cam = scene.params.camera;
  checkReference(reference, cam);
  Film film(int(cam.width), int(cam.height));
  std::vector<ConvergeRow> rows;
  double seconds = 0.0;
  uint64_t rays = 0, truncated = 0;
  int done = 0;  // samples per pixel already in the film: indices [0, done)
  for (const int spp : convergenceLevels(options.maxSpp)) {
    // Add the sample indices [done, spp); only the render itself is timed.
    if (options.backend == "cpu") {
      CpuRenderOptions o;
      o.threads = options.threads;
      o.firstSample = uint32_t(done);
      o.spp = spp - done;
      const RenderStats s = renderCpu(scene, o, film);
      seconds += s.seconds;
      rays += s.rays;
    } else {
      // A fresh context per level: set-up and shader compilation are outside deviceSeconds.
      VulkanRenderOptions o;
      o.context.device = options.device;
      o.firstSample = uint32_t(done);
      o.spp = spp - done;
      o.specialize = options.specialize;
      const VulkanRenderStats s = renderVulkan(scene, o, film);
      seconds += s.deviceSeconds;
      rays += s.rays;
      truncated += s.truncatedSamples;
    }
    done = spp;

    const DiffStats d = diffImages(film.resolve(), reference, /*threshold=*/1e-3);
    ConvergeRow row;
    row.spp = spp;
    row.seconds = seconds;
    row.rmse = d.rmse;
    row.relMse = d.relMse;
    row.mraysPerSecond = seconds > 0.0 ? double(rays) / seconds * 1e-6 : 0.0;
    row.invalidSamples = film.totalInvalid();
    row.truncatedSamples = truncated;
    rows.push_back(row);
    if (options.onRow) options.onRow(row);
  }
  return rows;
}

int runConvergeCommand(const ConvergeArgs& args) {
  // Everything the user gave is checked before any time is spent rendering.
  if (args.label.find_first_of(",\"\n\r") != std::string::npos) {
    throw InputError("--label: must not contain commas, quotes or line breaks, got '" + args.label +
                     "'");
  }
  if (args.noSpecialize && args.backend != "vulkan") {
    throw InputError("--no-specialize applies to the Vulkan backend only");
  }
  std::string refExt = std::filesystem::path(args.reference).extension().string();
  for (char& ch : refExt) ch = char(std::tolower(static_cast<unsigned char>(ch)));
  if (refExt != ".exr" && refExt != ".pfm") {
    throw InputError(args.reference + ": the reference must be a float image (.exr or .pfm)");
  }
  const Scene scene = loadScene(args.scene);
  for (const std::string& w : scene.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());

  // The same overrides as `pt render`.
  const RenderSettings settings = args.overrides.toSettings();
  const SceneData data = prepareScene(scene, settings);
  const Camera& cam = data.params.camera;

  const Image reference = readImage(args.reference);
  try {
    checkReference(reference, cam);
  } catch (const InputError& e) {
    throw InputError(args.reference + ": " + e.what());
  }
  std::ofstream csv(args.csv, std::ios::trunc);
  if (!csv) throw InputError(args.csv + ": cannot open for writing");
  csv << "label,backend,scene,width,height,spp,seconds,rmse,relmse,mrays_per_s\n" << std::flush;

  const std::string sceneName = std::filesystem::path(args.scene).stem().string();
  std::printf("converge %s backend=%s%s %ux%u label=%s\n", sceneName.c_str(), args.backend.c_str(),
              args.noSpecialize ? " (unspecialized)" : "", cam.width, cam.height,
              args.label.c_str());
  std::printf("%7s %10s %11s %11s %9s\n", "spp", "seconds", "rmse", "relmse", "Mrays/s");

  ConvergeOptions options;
  options.backend = args.backend;
  options.device = args.device;
  options.maxSpp = args.maxSpp;
  options.threads = args.threads;
  options.specialize = !args.noSpecialize;
  options.onRow = [&](const ConvergeRow& r) {
    // Default stream precision: 6 significant digits, like %g.
    csv << args.label << ',' << args.backend << ',' << sceneName << ',' << cam.width << ','
        << cam.height << ',' << r.spp << ',' << r.seconds << ',' << r.rmse << ',' << r.relMse << ','
        << r.mraysPerSecond << '\n'
        << std::flush;  // a run cut short keeps the levels it finished
    std::printf("%7d %10.4f %11.5g %11.5g %9.3f\n", r.spp, r.seconds, r.rmse, r.relMse,
                r.mraysPerSecond);
    std::fflush(stdout);
  };
  const std::vector<ConvergeRow> rows = runConvergence(data, reference, options);
  if (!csv) throw InputError(args.csv + ": write failed");

  const ConvergeRow& last = rows.back();
  if (last.invalidSamples > 0) {
    std::fprintf(stderr, "error: %llu samples were NaN or Inf%s; they were left out of the image\n",
                 (unsigned long long)last.invalidSamples,
                 last.truncatedSamples ? " or cut short by the shader's loop budget" : "");
    return kExitFailure;
  }
  return kExitOk;
}

}  // namespace pt
