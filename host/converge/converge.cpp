// Convergence runs; see converge.h.
#include "converge/converge.h"

#include <cmath>

#include "common/check.h"
#include "cpu/integrator.h"
#include "vulkan/backend.h"

namespace pt {

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
    RenderStats s;
    if (options.backend == "cpu") {
      CpuRenderOptions o;
      o.threads = options.threads;
      o.firstSample = uint32_t(done);
      o.spp = spp - done;
      s = renderCpu(scene, o, film);
    } else {
      // A fresh context per level: set-up and shader compilation are outside s.seconds.
      VulkanRenderOptions o;
      o.context.device = options.device;
      o.firstSample = uint32_t(done);
      o.spp = spp - done;
      o.specialize = options.specialize;
      s = renderVulkan(scene, o, film);
    }
    seconds += s.seconds;
    rays += s.rays;
    truncated += s.truncatedSamples;
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

}  // namespace pt
