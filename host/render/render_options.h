// What every backend takes and gives back: which sample indices to render, a progress
// callback, and the statistics of a render. The CPU reference (host/cpu) and the Vulkan
// backend (host/vulkan) extend these with their own knobs; neither includes the other.
#pragma once

#include <cstdint>
#include <functional>

namespace pt {

struct RenderOptions {
  uint32_t firstSample = 0;  // sample indices [firstSample, firstSample + spp) are taken
  int spp = 1;
  // Called now and then from one thread with the fraction of work done, in [0, 1].
  std::function<void(double)> progress;
};

struct RenderStats {
  double seconds = 0.0;           // render time: wall clock on the CPU, device time on a GPU
  double wallSeconds = 0.0;       // wall clock of the whole call, set-up and upload included
  uint64_t rays = 0;              // every ray traced: camera, bounce and shadow rays
  uint64_t invalidSamples = 0;    // samples left out of the film: NaN/Inf, or cut short
  uint64_t truncatedSamples = 0;  // of those, paths given up at lavapipe's loop-iteration cap
};

}  // namespace pt
