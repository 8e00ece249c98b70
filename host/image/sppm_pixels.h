// Stochastic progressive photon mapping's state of a pixel between iterations (pbrt-v4's
// SPPMPixel less what one iteration gathers): what its next iterations continue from, so what
// a film state of an sppm render keeps besides the image (film_state.h).
#pragma once

#include <vector>

#include <glm/glm.hpp>

namespace pt {

struct SppmPixelRecord {
  float radius = 0.0f;    // the search radius
  float n = 0.0f;         // the photons counted so far (pbrt-v4's N), reduced as it shrinks
  glm::vec3 tau{0.0f};    // their flux, reduced with the radius
  glm::vec3 ldSum{0.0f};  // the direct light of every iteration done, summed
  bool invalid = false;   // a NaN or infinite value reached the pixel: its estimate is invalid

  bool operator==(const SppmPixelRecord&) const = default;
};

using SppmPixels = std::vector<SppmPixelRecord>;  // row-major, one per pixel of the image

}  // namespace pt
