// glTF's material extensions rendered: spheres of thin-walled and refracting transmission, a
// clear coat and KHR_materials_specular, a glass of absorbing volume (a medium: the volume
// integrator), KHR_materials_sheen, and a clear coat with a normal map of its own, each scene
// read by the glTF reader and rendered on both backends, which must agree as for every other
// scene (render_compare.h).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "render/prepare.h"
#include "render_compare.h"
#include "scene/gltf/gltf_scene.h"
#include "tests/gltf_builder.h"
#include "tests/gltf_texture_scene.h"

namespace pt {
namespace {

using nlohmann::json;
using test::GltfBuilder;

// A row of unit spheres, one per material, over a diffuse floor, under the white sky a glTF file
// without lights gets, seen by a camera from +z.
SceneData sphereRow(const std::vector<json>& materials, RenderSettings settings) {
  GltfBuilder b;
  const GltfBuilder::SphereAccessors sphere = b.sphere(16, 32, false);
  std::vector<int> roots;
  const double spacing = 2.3, first = -spacing * double(materials.size() - 1) / 2.0;
  for (size_t i = 0; i < materials.size(); ++i) {
    b.doc["materials"].push_back(materials[i]);
    const int mesh = b.mesh(
        json::array({{{"attributes", {{"POSITION", sphere.positions}, {"NORMAL", sphere.normals}}},
                      {"indices", sphere.indices},
                      {"material", int(i)}}}));
    roots.push_back(b.node({{"mesh", mesh}, {"translation", {first + spacing * double(i), 0, 0}}}));
  }
  b.doc["materials"].push_back(
      {{"pbrMetallicRoughness",
        {{"baseColorFactor", {0.7, 0.3, 0.2, 1}}, {"metallicFactor", 0}, {"roughnessFactor", 1}}}});
  const int floor = b.floats({-20, -1, -20, -20, -1, 20, 20, -1, 20, 20, -1, -20}, "VEC3", 3);
  const std::vector<std::uint16_t> quad = {0, 1, 2, 0, 2, 3};
  const int indices = b.accessor(b.view(quad), GltfBuilder::kUShort, 6, "SCALAR");
  roots.push_back(b.node({{"mesh", b.mesh(json::array({{{"attributes", {{"POSITION", floor}}},
                                                        {"indices", indices},
                                                        {"material", int(materials.size())}}}))}}));
  b.doc["cameras"] = json::array(
      {{{"type", "perspective"},
        {"perspective", {{"yfov", 0.5}, {"aspectRatio", 48.0 / 24.0}, {"znear", 0.1}}}}});
  roots.push_back(b.node({{"camera", 0}, {"translation", {0, 1.2, 12}}}));
  b.scene(roots);
  Scene scene = loadGltfSceneBytes(b.gltf(), "extensions.gltf");
  EXPECT_TRUE(scene.warnings.empty()) << scene.warnings.front();
  return prepareScene(std::move(scene), settings);
}

json layeredMaterial(vec3 base, double metallic, double roughness, const json& extensions) {
  return {{"pbrMetallicRoughness",
           {{"baseColorFactor", {base.x, base.y, base.z, 1.0}},
            {"metallicFactor", metallic},
            {"roughnessFactor", roughness}}},
          {"extensions", extensions}};
}

TEST(GltfExtensionsRender, TransmissionClearcoatSpecularAgreeOnBothBackends) {
  const std::vector<json> materials = {
      // Thin-walled transmission, smooth and rough.
      layeredMaterial(vec3(0.9f, 0.9f, 0.6f), 0, 0,
                      {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}}}),
      layeredMaterial(vec3(0.6f, 0.9f, 0.9f), 0, 0.4,
                      {{"KHR_materials_transmission", {{"transmissionFactor", 0.8}}}}),
      // A refracting glass ball, smooth and rough.
      layeredMaterial(vec3(1.0f), 0, 0,
                      {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}},
                       {"KHR_materials_volume", {{"thicknessFactor", 1.0}}},
                       {"KHR_materials_ior", {{"ior", 1.5}}}}),
      layeredMaterial(vec3(0.9f, 1.0f, 0.9f), 0, 0.3,
                      {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}},
                       {"KHR_materials_volume", {{"thicknessFactor", 2.0}}}}),
      // A clear coat over rough red plastic, and KHR_materials_specular's coloured f0.
      layeredMaterial(vec3(0.8f, 0.1f, 0.1f), 0, 0.7,
                      {{"KHR_materials_clearcoat",
                        {{"clearcoatFactor", 1.0}, {"clearcoatRoughnessFactor", 0.1}}}}),
      layeredMaterial(vec3(0.2f, 0.2f, 0.8f), 0, 0.3,
                      {{"KHR_materials_specular",
                        {{"specularFactor", 0.8}, {"specularColorFactor", {2.0, 1.0, 0.5}}}}}),
  };
  const SceneData data = sphereRow(materials, RenderSettings{.width = 48, .height = 24});
  EXPECT_NE(data.effects.toString().find("gltf-layers"), std::string::npos)
      << data.effects.toString();
  EXPECT_FALSE(data.effects.media);
  expectAgreement(renderBoth(data, 16));
}

// KHR_materials_volume's attenuation: the glass ball is an absorbing medium, rendered by the
// volume integrator on both backends, and darker than the same ball without attenuation.
TEST(GltfExtensionsRender, AbsorbingVolumeAgreesOnBothBackends) {
  const auto glass = [](bool absorbs) {
    json volume = {{"thicknessFactor", 1.0}};
    if (absorbs) {
      volume["attenuationColor"] = {0.9, 0.5, 0.2};
      volume["attenuationDistance"] = 1.0;
    }
    return layeredMaterial(vec3(1.0f), 0, 0.1,
                           {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}},
                            {"KHR_materials_volume", volume}});
  };
  const SceneData data = sphereRow({glass(true)}, RenderSettings{.width = 32, .height = 16});
  EXPECT_TRUE(data.effects.media) << data.effects.toString();
  const Comparison absorbing = renderBoth(data, 16);
  expectAgreement(absorbing);
  const SceneData clear = sphereRow({glass(false)}, RenderSettings{.width = 32, .height = 16});
  EXPECT_FALSE(clear.effects.media);
  const Comparison c = renderBoth(clear, 16);
  // The blue channel loses most (attenuation colour 0.2 per unit length).
  EXPECT_LT(absorbing.cpuMean.z, 0.97f * c.cpuMean.z);
  EXPECT_LT(absorbing.cpuMean.z / absorbing.cpuMean.x, c.cpuMean.z / c.cpuMean.x);
}

// KHR_materials_sheen over a dark base, a tinted rough sheen under a clear coat, and a sheen over
// glass: the same on both backends; and a white sheen shows (brighter than the dark base alone).
TEST(GltfExtensionsRender, SheenAgreesOnBothBackends) {
  const auto sheen = [](double r, double g, double b, double roughness) {
    return json{{"sheenColorFactor", {r, g, b}}, {"sheenRoughnessFactor", roughness}};
  };
  const std::vector<json> materials = {
      layeredMaterial(vec3(0.05f), 0, 0.8, {{"KHR_materials_sheen", sheen(1, 1, 1, 0.3)}}),
      layeredMaterial(vec3(0.2f, 0.1f, 0.4f), 0, 0.5,
                      {{"KHR_materials_sheen", sheen(0.9, 0.5, 0.2, 0.8)},
                       {"KHR_materials_clearcoat",
                        {{"clearcoatFactor", 0.7}, {"clearcoatRoughnessFactor", 0.2}}}}),
      layeredMaterial(vec3(0.9f), 0, 0.1,
                      {{"KHR_materials_sheen", sheen(0.3, 0.6, 1.0, 0.5)},
                       {"KHR_materials_transmission", {{"transmissionFactor", 1.0}}}}),
  };
  const SceneData data = sphereRow(materials, RenderSettings{.width = 32, .height = 16});
  EXPECT_NE(data.effects.toString().find("gltf-sheen"), std::string::npos)
      << data.effects.toString();
  const Comparison c = renderBoth(data, 8);
  expectAgreement(c);
  const SceneData bare = sphereRow({layeredMaterial(vec3(0.05f), 0, 0.8, json::object())},
                                   RenderSettings{.width = 32, .height = 16});
  // A white sheen of roughness 1 (seen head-on, a sheen of low roughness reflects almost nothing:
  // E(1) is 0.001 at roughness 0.3, 0.16 at roughness 1).
  const SceneData sheened = sphereRow(
      {layeredMaterial(vec3(0.05f), 0, 0.8, {{"KHR_materials_sheen", sheen(1, 1, 1, 1)}})},
      RenderSettings{.width = 32, .height = 16});
  EXPECT_EQ(bare.effects.toString().find("gltf-sheen"), std::string::npos);
  Film a(32, 16), b(32, 16);
  renderCpu(bare, test::cpuOptions(2, 8), a);
  renderCpu(sheened, test::cpuOptions(2, 8), b);
  // The sphere: about 5 pixels across, its centre about 3 pixels below the image's (the camera
  // is 1.2 above it, 12 away, yfov 0.5).
  const vec3 withSheen = test::meanOf(b.resolve(), 15, 10, 17, 13);
  const vec3 without = test::meanOf(a.resolve(), 15, 10, 17, 13);
  EXPECT_GT(withSheen.x, 2.0f * without.x) << withSheen.x << " vs " << without.x;
}

// A clear coat with its own normal map (clearcoatNormalTexture) on a square under a directional
// light and the white sky: tilted, it agrees on both backends and changes the image where the
// coat's normal decides (its Fresnel weight and highlight); a flat one (scale 0) renders as no
// coat normal at all, on both backends.
TEST(GltfExtensionsRender, CoatNormalTextureAgreesOnBothBackends) {
  const auto scene = [](int kind) {  // 0: no coat normal map, 1: flat (scale 0), 2: tilted
    GltfBuilder b;
    json clearcoat = {{"clearcoatFactor", 1.0}, {"clearcoatRoughnessFactor", 0.15}};
    if (kind > 0) {
      clearcoat["clearcoatNormalTexture"] = {{"index", test::addUniformTexture(b, {230, 150, 200})},
                                             {"scale", kind == 1 ? 0.0 : 1.0}};
    }
    const int m = test::addMaterial(b, {{"pbrMetallicRoughness",
                                         {{"baseColorFactor", {0.1, 0.3, 0.1, 1.0}},
                                          {"metallicFactor", 0.0},
                                          {"roughnessFactor", 0.9}}},
                                        {"extensions", {{"KHR_materials_clearcoat", clearcoat}}}});
    b.scene({test::addSquare(b, m, {{"rotation", test::rotationTaking({0, 0, 1}, {0, 0.3, 1})}}),
             test::addCamera(b, 3.0, 0.7),
             test::addDirectionalLight(b, glm::dvec3(-0.3, -0.2, -1), 3.0)});
    Scene s = loadGltfSceneBytes(b.gltf(), "coat.gltf");
    EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
    return prepareScene(std::move(s), RenderSettings{.width = 24, .height = 24});
  };
  const SceneData tilted = scene(2);
  EXPECT_NE(tilted.effects.textureFeatures & kTextureUsesCoatNormal, 0u);
  EXPECT_EQ(scene(0).effects.textureFeatures & kTextureUsesCoatNormal, 0u);
  const Comparison t = renderBoth(tilted, 8);
  expectAgreement(t);
  const Comparison flat = renderBoth(scene(1), 8);
  const Comparison none = renderBoth(scene(0), 8);
  expectAgreement(flat);
  test::expectSameImage(flat.cpuImage, none.cpuImage);
  test::expectSameImage(flat.gpuImage, none.gpuImage);
  // The tilted coat changes the square (pixels about 3 to 20): by more than 5 % of its mean.
  const vec3 tiltedMean = test::meanOf(t.cpuImage, 4, 4, 20, 20);
  const vec3 noneMean = test::meanOf(none.cpuImage, 4, 4, 20, 20);
  EXPECT_GT(std::abs(tiltedMean.x - noneMean.x), 0.05f * noneMean.x)
      << tiltedMean.x << " vs " << noneMean.x;
}

}  // namespace
}  // namespace pt
