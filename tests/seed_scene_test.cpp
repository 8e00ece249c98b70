// The seed's scene (configs/bunny-dragon.json: the Stanford bunny and dragon in the Cornell
// box, about 0.94M triangles) on both backends, and scenes beyond a device's buffer limit.
// The dragon is fetched into assets/ by tools/setup.sh (tools/fetch-assets.sh).
#include <gtest/gtest.h>

#include <filesystem>

#include "render/prepare.h"
#include "render_compare.h"
#include "scene/load_scene.h"
#include "scene/scene.h"
#include "test_util.h"
#include "vulkan/backend.h"
#include "vulkan/device_limits.h"
#include "vulkan/gpu_bvh.h"

namespace pt {
namespace {

TEST(SeedScene, BunnyAndDragonRenderAndAgreeOnBothBackends) {
  const std::filesystem::path dragon =
      std::filesystem::path(PT_SOURCE_DIR) / "assets/dragon_vrip.ply";
  ASSERT_TRUE(std::filesystem::exists(dragon))
      << dragon << " is missing: run tools/fetch-assets.sh";
  const Scene scene = loadScene(test::kConfigs / "bunny-dragon.json");
  // 6 quads of the box, the bunny and the dragon (less its zero-area triangles, with a warning).
  EXPECT_GT(scene.triangles.size(), 12u + 69666u + 871000u);
  EXPECT_LE(scene.triangles.size(), 12u + 69666u + 871414u);
  const SceneData data = prepareScene(scene, RenderSettings{.width = 64, .height = 64});
  const Comparison c = renderBoth(data, /*spp=*/2);
  expectAgreement(c);
}

// A generated mesh whose buffers (the triangles: 3M x 48 bytes = 137 MiB; the traversal's
// nodes and triangles: 188 MiB) are larger than lavapipe's 128 MiB maxStorageBufferRange is
// refused with the sizes and the limit before any buffer is allocated; a device with a
// larger limit renders it instead.
TEST(VulkanLimits, SceneBuffersBeyondTheDeviceLimitAreRefusedWithTheNumbers) {
  constexpr int kSide = 1225;  // 2 * 1225^2 = 3,001,250 triangles
  Scene scene;
  scene.camera.position = vec3(0.5f, 0.5f, -2.0f);
  scene.camera.target = vec3(0.5f, 0.5f, 0.0f);
  scene.camera.width = scene.camera.height = 8;
  scene.materials.push_back(Material{vec3(0.5f), kMaterialDiffuse, vec3(0.0f), 0});
  scene.materials.push_back(Material{vec3(0.0f), kMaterialDiffuse, vec3(1.0f), 0});
  scene.materialNames = {"grey", "light"};
  const float step = 1.0f / kSide;
  for (int y = 0; y < kSide; ++y) {
    for (int x = 0; x < kSide; ++x) {
      const vec3 a(x * step, y * step, 0.0f), b = a + vec3(step, 0, 0), d = a + vec3(0, step, 0);
      const vec3 e = a + vec3(step, step, 0);
      scene.triangles.push_back(Triangle{a, 0, d, kNoEmitter, b, 0});
      scene.triangles.push_back(Triangle{b, 0, d, kNoEmitter, e, 0});
    }
  }
  test::addQuad(scene, vec3(0.5f, 0.5f, -1.0f), vec3(0.2f, 0, 0), vec3(0, 0.2f, 0), 1);
  for (uint i = 0; i < scene.triangles.size(); ++i) scene.triangles[i].primitive = i;
  const SceneData data = prepareScene(scene, RenderSettings{});
  // The largest buffer: the traversal's, nodes and triangles (gpu_bvh.h).
  const uint64_t traversalBytes =
      gpuTraversalTexels(buildGpuBvh(data.bvh), data.bvh.triangles).size() * sizeof(uint32_t);

  const DeviceLimits limits = queryDeviceLimits(ContextOptions{});
  Film film(8, 8);
  if (limits.maxStorageBufferRange >= traversalBytes) {
    const VulkanRenderStats stats = renderVulkan(data, validatedOptions(1), film);
    EXPECT_EQ(stats.invalidSamples, 0u);
    return;
  }
  try {
    renderVulkan(data, validatedOptions(1), film);
    FAIL() << "expected an error";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("the BVH node and triangle buffer is " + std::to_string(traversalBytes >> 20) +
                     " MiB"),
              std::string::npos)
        << m;
    EXPECT_NE(m.find("maxStorageBufferRange is " +
                     std::to_string(limits.maxStorageBufferRange >> 20) + " MiB"),
              std::string::npos)
        << m;
  }
}

}  // namespace
}  // namespace pt
