// bsdf.h's materials in whole renders: the Cornell box with its two blocks made of each type,
// on both backends (they must agree as for diffuse scenes), with nothing invalid, and the
// effect set naming exactly the types used. The BSDFs themselves are tested in bsdf_test.cpp.
#include <gtest/gtest.h>

#include <string>

#include "bsdf.h"
#include "cpu/integrator.h"
#include "render/prepare.h"
#include "render_compare.h"
#include "scene/scene.h"
#include "test_util.h"

namespace pt {
namespace {

// The types' parameters, as the scene reader would fill them (alphas already remapped).
Material conductor(float alpha) {
  Material m{};
  m.type = kMaterialConductor;
  m.eta = vec3(0.2f, 0.92f, 1.1f);  // copper-like
  m.k = vec3(3.9f, 2.45f, 2.14f);
  m.alphaX = m.alphaY = alpha;
  return m;
}
Material dielectric(float eta, float alpha) {
  Material m{};
  m.type = kMaterialDielectric;
  m.eta = vec3(eta);
  m.alphaX = m.alphaY = alpha;
  return m;
}
Material thinDielectric(float eta) {
  Material m{};
  m.type = kMaterialThinDielectric;
  m.eta = vec3(eta);
  return m;
}
Material diffuseTransmission() {
  Material m{};
  m.type = kMaterialDiffuseTransmission;
  m.reflectance = vec3(0.5f, 0.4f, 0.3f);
  m.transmittance = vec3(0.3f, 0.4f, 0.5f);
  return m;
}
Material coatedDiffuse(float alpha, vec3 albedo) {
  Material m{};
  m.type = kMaterialCoatedDiffuse;
  m.reflectance = vec3(0.6f, 0.3f, 0.2f);
  m.eta = vec3(1.5f);
  m.alphaX = m.alphaY = alpha;
  m.thickness = 0.01f;
  m.transmittance = albedo;
  m.g = 0.3f;
  m.maxDepth = 10;
  m.nSamples = 1;
  return m;
}

// The Cornell box (configs/cornell-box.json) with the short block made of `a` and the tall
// one of `b`: triangles 10-19 and 20-29 in its load order.
SceneData cornellWith(const Material& a, const Material& b, int size) {
  Scene scene = loadScene(test::kConfigs / "cornell-box.json");
  const uint ia = uint(scene.materials.size());
  scene.materials.push_back(a);
  scene.materialNames.push_back("a");
  scene.materials.push_back(b);
  scene.materialNames.push_back("b");
  for (size_t t = 10; t < 30; ++t) scene.triangles[t].material = t < 20 ? ia : ia + 1;
  return prepareScene(std::move(scene), RenderSettings{.width = size, .height = size});
}

struct Case {
  const char* name;
  Material a, b;
  const char* effects;  // the material types the effect string must list
};

class MaterialsAgree : public ::testing::TestWithParam<Case> {};

TEST_P(MaterialsAgree, OnBothBackends) {
  const Case& c = GetParam();
  const SceneData data = cornellWith(c.a, c.b, 32);
  EXPECT_NE(data.effects.toString().find(c.effects), std::string::npos)
      << data.effects.toString();
  EXPECT_TRUE(data.effects.hasBsdfMaterials());
  const Comparison cmp = renderBoth(data, 8);
  expectAgreement(cmp);
  EXPECT_EQ(cmp.cpu.invalidSamples, 0u);
}

INSTANTIATE_TEST_SUITE_P(
    Types, MaterialsAgree,
    ::testing::Values(
        Case{"conductors", conductor(0.0f), conductor(0.3f), "conductor"},
        Case{"anisotropicConductor", conductor(0.05f),
             [] {
               Material m = conductor(0.05f);
               m.alphaY = 0.5f;
               return m;
             }(),
             "conductor"},
        Case{"glass", dielectric(1.5f, 0.0f), dielectric(1.5f, 0.3f), "dielectric"},
        Case{"glassBelowOne", dielectric(1.0f / 1.33f, 0.2f), dielectric(1.0f, 0.0f),
             "dielectric"},
        Case{"thinAndTranslucent", thinDielectric(1.5f), diffuseTransmission(),
             "thindielectric+diffusetransmission"},
        Case{"coated", coatedDiffuse(0.0f, vec3(0.0f)), coatedDiffuse(0.3f, vec3(0.5f)),
             "coateddiffuse"}),
    [](const ::testing::TestParamInfo<Case>& info) { return std::string(info.param.name); });

TEST(Materials, DiffuseOnlySceneUsesNone) {
  const SceneData data = prepareScene(loadScene(test::kConfigs / "cornell-box.json"),
                                      RenderSettings{.width = 16, .height = 16});
  EXPECT_FALSE(data.effects.hasBsdfMaterials());
  EXPECT_EQ(data.effects.toString().find("conductor"), std::string::npos);
}

TEST(Materials, SmoothOnlySceneNeedsNoLightSampling) {
  // Only delta lobes besides the black light: nothing for next-event estimation to do.
  Scene scene = loadScene(test::kConfigs / "cornell-box.json");
  scene.materials[0] = conductor(0.0f);
  scene.materials[1] = dielectric(1.5f, 0.0f);
  scene.materials[2] = thinDielectric(1.5f);
  const SceneData data =
      prepareScene(std::move(scene), RenderSettings{.width = 16, .height = 16});
  EXPECT_FALSE(data.effects.lightSampling);
  EXPECT_TRUE(data.effects.conductor && data.effects.dielectric && data.effects.thinDielectric);
}

}  // namespace
}  // namespace pt
