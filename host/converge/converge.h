// What accuracy costs in time: renders progressively at 1, 2, 4, ... N samples per pixel,
// each level adding the sample indices [k, 2k) to the film that holds [0, k), and after each
// level compares the image with a reference (RMSE, relMSE) against the cumulative render
// time. `pt converge` (host/cli) and tools/accuracy.sh drive it; docs/accuracy.md shows it.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "image/image.h"
#include "render/prepare.h"

namespace pt {

// One level of a convergence run.
struct ConvergeRow {
  int spp = 0;                    // samples per pixel so far
  double seconds = 0.0;           // cumulative render time (CPU: wall; Vulkan: device timestamps)
  double rmse = 0.0;              // of the resolved film against the reference
  double relMse = 0.0;            // ditto, squared error over reference^2 + 0.01
  double mraysPerSecond = 0.0;    // cumulative rays / cumulative seconds, in millions
  uint64_t invalidSamples = 0;    // NaN/Inf samples so far (left out of the film)
  uint64_t truncatedSamples = 0;  // Vulkan: paths cut short by the shader's loop budget
};

struct ConvergeOptions {
  std::string backend = "vulkan";  // "vulkan" or "cpu"
  std::string device;              // Vulkan device: index or part of the name
  int maxSpp = 256;                // levels 1, 2, 4, ... up to and including maxSpp
  int threads = 0;                 // CPU threads, 0: all
  bool specialize = true;          // Vulkan: false compiles every effect into the shader
  std::function<void(const ConvergeRow&)> onRow;  // called as each level finishes
};

// The spp of each level: powers of two below maxSpp, then maxSpp itself (maxSpp >= 1).
std::vector<int> convergenceLevels(int maxSpp);

// Throws InputError unless `reference` has the camera's resolution and finite pixels only
// (the error would silently leave non-finite pixels out).
void checkReference(const Image& reference, const Camera& camera);

// Runs the levels on `scene`, comparing each resolved film with `reference`. Throws
// InputError when checkReference does.
std::vector<ConvergeRow> runConvergence(const SceneData& scene, const Image& reference,
                                        const ConvergeOptions& options);

}  // namespace pt
