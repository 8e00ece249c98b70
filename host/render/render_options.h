// What every backend takes and gives back: which sample indices to render, a progress
// callback, and the statistics of a render. The CPU reference (host/cpu) and the Vulkan
// backend (host/vulkan) extend these with their own knobs; neither includes the other.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>

#include "image/sppm_pixels.h"

namespace pt {

// One strategy of bidirectional path tracing rendered alone, without its MIS weight (pbrt-v4's
// visualizestrategies, for debugging; cpu/bdpt.h): s light vertices joined to t camera vertices.
// Unset (-1): all of them, weighed.
struct BdptStrategy {
  int s = -1;
  int t = -1;
  bool all() const { return s < 0; }
};

struct RenderOptions {
  uint32_t firstSample = 0;  // sample indices [firstSample, firstSample + spp) are taken
  int spp = 1;
  // Called now and then from one thread with the fraction of work done, in [0, 1].
  std::function<void(double)> progress;
  // When it reads true (set by a signal handler, say) the render stops early: the CPU drops
  // the pass under way, the Vulkan backend stops after the dispatch under way. The film then
  // holds whole passes; RenderStats::samplesDone says how many.
  const std::atomic<bool>* stop = nullptr;
  // Called on the rendering thread whenever the film holds exactly the samples [firstSample,
  // firstSample + done) of this call (after every pass on the CPU, after every fold of a batch
  // on Vulkan), so that a checkpoint of the film can be written from it.
  std::function<void(int done)> checkpoint;
  // Photon mapping (kIntegratorSppm): every pixel's state between iterations. Empty, or not
  // given, the render starts from iteration 0 (firstSample 0); otherwise it continues from
  // its state after firstSample iterations. A given one is left at the state of the last
  // whole iteration (at every checkpoint call too, when the film holds that iteration's
  // estimate).
  SppmPixels* sppmPixels = nullptr;
  BdptStrategy bdptStrategy;  // scenes rendered with kIntegratorBdpt
};

struct RenderStats {
  double seconds = 0.0;           // render time: wall clock on the CPU, device time on a GPU
  double wallSeconds = 0.0;       // wall clock of the whole call, set-up and upload included
  uint64_t rays = 0;              // every ray traced: camera, bounce and shadow rays
  uint64_t invalidSamples = 0;    // samples left out of the film: NaN/Inf, or cut short
  uint64_t truncatedSamples = 0;  // of those, paths given up at lavapipe's loop-iteration cap
  int samplesDone = 0;            // samples per pixel rendered: spp, or fewer when stopped
  bool stopped = false;           // RenderOptions::stop ended the render early
};

}  // namespace pt
