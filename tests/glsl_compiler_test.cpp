// The path tracer's shader as the Vulkan backend compiles it for a scene (vulkan/
// glsl_compiler.h): the code of the effects the scene does not use is gone from the SPIR-V
// the driver receives, and the code of those it uses is there. No Vulkan driver needed.
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "render/prepare.h"
#include "scene/load_scene.h"
#include "test_util.h"
#include "vulkan/backend.h"
#include "vulkan/glsl_compiler.h"

namespace pt {
namespace {

// Whether the module names a function whose name starts with `name` followed by its
// parameter list: glslang writes each function's name (OpName) with its mangled signature,
// "conductorSample(struct-TrowbridgeReitz...".
bool namesFunction(const std::vector<uint32_t>& spirv, const std::string& name) {
  const std::string bytes(reinterpret_cast<const char*>(spirv.data()), spirv.size() * 4);
  return bytes.find(name + "(") != std::string::npos;
}

std::vector<uint32_t> compiledFor(const char* config, bool specialize) {
  const SceneData data = prepareScene(loadScene(test::kConfigs / config), RenderSettings{});
  VulkanRenderOptions options;
  options.specialize = specialize;
  return compileShader("pathtrace.comp", pathtraceDefinitions(data, options));
}

TEST(GlslCompiler, TheSceneGetsTheCodeOfItsEffectsOnly) {
  // cornell-materials has conductors and dielectrics, no coated or glTF surfaces, no
  // textures, no analytic lights.
  const std::vector<uint32_t> scene = compiledFor("cornell-materials.json", true);
  EXPECT_TRUE(namesFunction(scene, "conductorSample"));
  EXPECT_TRUE(namesFunction(scene, "dielectricSample"));
  EXPECT_FALSE(namesFunction(scene, "coatedDiffuseSample"));
  EXPECT_FALSE(namesFunction(scene, "gltfSample"));
  EXPECT_FALSE(namesFunction(scene, "sampleEnvironmentLight"));
  // Every effect compiled in (--no-specialize): all of them are there, in a larger module.
  const std::vector<uint32_t> all = compiledFor("cornell-materials.json", false);
  for (const char* f : {"conductorSample", "dielectricSample", "coatedDiffuseSample", "gltfSample",
                        "sampleEnvironmentLight"}) {
    EXPECT_TRUE(namesFunction(all, f)) << f;
  }
  EXPECT_LT(scene.size() * 10, all.size() * 8);
}

TEST(GlslCompiler, CompiledOncePerDefinitions) {
  // The second render of a scene in a process reuses the module; other definitions do not.
  const SceneData data =
      prepareScene(loadScene(test::kConfigs / "cornell-box.json"), RenderSettings{});
  VulkanRenderOptions options;
  const std::string definitions = pathtraceDefinitions(data, options);
  const std::vector<uint32_t>& a = compileShader("pathtrace.comp", definitions);
  const std::vector<uint32_t>& b = compileShader("pathtrace.comp", definitions);
  EXPECT_EQ(&a, &b);
  options.specialize = false;
  const std::vector<uint32_t>& c =
      compileShader("pathtrace.comp", pathtraceDefinitions(data, options));
  EXPECT_NE(&a, &c);
  EXPECT_NE(a, c);
  // The diffuse-only box takes the variant without bsdf.h's materials.
  EXPECT_NE(definitions.find("#define PT_NO_BSDF_MATERIALS"), std::string::npos);
  EXPECT_FALSE(namesFunction(a, "conductorSample"));
}

}  // namespace
}  // namespace pt
