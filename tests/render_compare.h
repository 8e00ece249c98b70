// Renders a scene on both backends and compares them: the harness of the Vulkan and the
// robustness tests.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

#include "cpu/integrator.h"
#include "render/prepare.h"
#include "test_util.h"
#include "vulkan/backend.h"

namespace pt {

// Validation layers on (a validation error fails the tests), unless PT_NO_VALIDATION is set:
// for machines without the layers, such as a lent GPU machine (tools/gpu-check.sh).
inline bool validationWanted() {
  return std::getenv("PT_NO_VALIDATION") == nullptr;
}

inline VulkanRenderOptions validatedOptions(int spp) {
  VulkanRenderOptions options;
  options.context.validation = validationWanted();
  options.spp = spp;
  options.samplesPerFold = 3;  // exercise several folds into the film
  return options;
}

struct Comparison {
  DiffStats diff;
  RenderStats cpu;
  VulkanRenderStats gpu;
  Image cpuImage, gpuImage;
  vec3 gpuMean{0.0f}, cpuMean{0.0f};
};

inline Comparison renderBoth(const SceneData& data, int spp, bool specialize = true) {
  const Camera& cam = data.params.camera;
  Film cpu(int(cam.width), int(cam.height)), gpu(int(cam.width), int(cam.height));
  Comparison c;
  c.cpu = renderCpu(data, test::cpuOptions(2, spp), cpu);
  EXPECT_EQ(c.cpu.invalidSamples, 0u);
  VulkanRenderOptions options = validatedOptions(spp);
  options.specialize = specialize;
  c.gpu = renderVulkan(data, options, gpu);
  c.gpuImage = gpu.resolve();
  c.cpuImage = cpu.resolve();
  const Image& a = c.gpuImage;
  const Image& b = c.cpuImage;
  c.diff = diffImages(a, b, 1e-3);
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    c.gpuMean += a.pixels[i] / float(a.pixels.size());
    c.cpuMean += b.pixels[i] / float(b.pixels.size());
  }
  return c;
}

// The acceptance rule: within 1e-3 relative on at least 99.5 % of pixels, no validation
// errors, nothing invalid or cut short, and image means equal to 1e-3 (diverged paths are
// rare and unbiased, so they cannot move the mean).
inline void expectAgreement(const Comparison& c) {
  EXPECT_EQ(c.gpu.validationErrors, 0u);
  EXPECT_EQ(c.gpu.invalidSamples, 0u);
  EXPECT_EQ(c.gpu.truncatedSamples, 0u);
  EXPECT_EQ(c.diff.nonFinitePixels, 0u);
  EXPECT_LE(double(c.diff.pixelsOverThreshold), 0.005 * double(c.diff.pixelCount))
      << "rmse " << c.diff.rmse << " max " << c.diff.maxAbsError;
  for (int ch = 0; ch < 3; ++ch) {
    EXPECT_GT(c.cpuMean[ch], 0.0f);
    EXPECT_NEAR(c.gpuMean[ch], c.cpuMean[ch], 1e-3f * c.cpuMean[ch]) << "channel " << ch;
  }
  EXPECT_GT(c.gpu.rays, 0u);
}

// Both backends' images against `expected` (a closed form), channel by channel: every value
// within absolute + relative * expected of it.
inline void expectNearClosedForm(const Comparison& cmp, const Image& expected, double absolute,
                                 double relative) {
  for (const Image* image : {&cmp.cpuImage, &cmp.gpuImage}) {
    size_t off = 0;
    double worst = 0.0;  // the largest error beyond what is allowed (negative: all inside)
    for (size_t i = 0; i < expected.pixels.size(); ++i) {
      for (int c = 0; c < 3; ++c) {
        const double e = expected.pixels[i][c];
        const double excess = std::fabs(double(image->pixels[i][c]) - e) - absolute - relative * e;
        worst = i == 0 && c == 0 ? excess : std::max(worst, excess);
        if (excess > 0.0) ++off;
      }
    }
    EXPECT_EQ(off, 0u) << (image == &cmp.cpuImage ? "cpu" : "vulkan")
                       << ": worst error beyond the bound " << worst;
  }
}

// The image of radiance(ray), averaged over each pixel's box-filter square (16 x 16 camera
// rays): closed forms to compare renders with.
template <typename Radiance>
Image pixelAverages(const Camera& cam, const Radiance& radiance) {
  Image image(int(cam.width), int(cam.height));
  constexpr int kSub = 16;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      glm::dvec3 sum(0.0);
      for (int j = 0; j < kSub; ++j) {
        for (int i = 0; i < kSub; ++i) {
          const vec2 film(float(x) + (float(i) + 0.5f) / kSub, float(y) + (float(j) + 0.5f) / kSub);
          sum += radiance(cameraRay(cam, film));
        }
      }
      image.at(x, y) = vec3(sum / double(kSub * kSub));
    }
  }
  return image;
}

}  // namespace pt
