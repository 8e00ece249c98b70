// glTF scenes rendered: a grid of spheres of glTF's material, metallic by row and roughness by
// column, read by the glTF reader and rendered on both backends, which must agree as for every
// other scene (render_compare.h).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "image/image.h"
#include "render/prepare.h"
#include "render_compare.h"
#include "scene/gltf/gltf_scene.h"
#include "tests/gltf_builder.h"

namespace pt {
namespace {

using nlohmann::json;
using test::GltfBuilder;

TEST(GltfRender, MetallicRoughnessGridAgreesOnBothBackends) {
  GltfBuilder b;
  const GltfBuilder::SphereAccessors sphere = b.sphere(12, 24, false);
  std::vector<int> roots;
  const std::vector<float> metallic = {0.0f, 0.5f, 1.0f};
  const std::vector<float> roughness = {0.0f, 0.3f, 0.6f, 1.0f};
  for (size_t r = 0; r < metallic.size(); ++r) {
    for (size_t c = 0; c < roughness.size(); ++c) {
      b.doc["materials"].push_back({{"pbrMetallicRoughness",
                                     {{"baseColorFactor", {0.9, 0.5, 0.2, 1.0}},
                                      {"metallicFactor", metallic[r]},
                                      {"roughnessFactor", roughness[c]}}}});
      const int material = int(b.doc["materials"].size()) - 1;
      const int mesh = b.mesh(json::array(
          {{{"attributes", {{"POSITION", sphere.positions}, {"NORMAL", sphere.normals}}},
            {"indices", sphere.indices},
            {"material", material}}}));
      roots.push_back(b.node(
          {{"mesh", mesh}, {"translation", {2.2 * double(c) - 3.3, 2.2 * double(r) - 2.2, 0.0}}}));
    }
  }
  // A rough dielectric floor with a base colour texture (a 2 x 2 checkerboard PNG repeated 8
  // times by KHR_texture_transform), and a lamp above.
  const int quad =
      b.floats({-10, -1.2f, -10, -10, -1.2f, 10, 10, -1.2f, 10, 10, -1.2f, -10}, "VEC3", 3);
  const std::vector<std::uint16_t> quadIndices = {0, 1, 2, 0, 2, 3};
  const int qi = b.accessor(b.view(quadIndices), GltfBuilder::kUShort, 6, "SCALAR");
  const test::TempDir dir;
  Image checker(2, 2);
  checker.at(0, 0) = checker.at(1, 1) = vec3(0.8f, 0.7f, 0.6f);
  checker.at(1, 0) = checker.at(0, 1) = vec3(0.1f, 0.2f, 0.3f);
  writeImage(checker, dir / "checker.png");
  b.doc["images"] = json::array({{{"uri", (dir / "checker.png").string()}}});
  b.doc["textures"] = json::array({{{"source", 0}}});
  b.doc["materials"].push_back(
      {{"pbrMetallicRoughness",
        {{"metallicFactor", 0.0},
         {"roughnessFactor", 0.5},
         {"baseColorTexture",
          {{"index", 0}, {"extensions", {{"KHR_texture_transform", {{"scale", {8.0, 8.0}}}}}}}}}}});
  const int quadUvs = b.floats({0, 0, 0, 1, 1, 1, 1, 0}, "VEC2", 2);
  roots.push_back(b.node(
      {{"mesh", b.mesh(json::array({{{"attributes", {{"POSITION", quad}, {"TEXCOORD_0", quadUvs}}},
                                     {"indices", qi},
                                     {"material", 12}}}))}}));
  b.doc["materials"].push_back(
      {{"emissiveFactor", {1, 1, 1}},
       {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 4}}}}}});
  roots.push_back(b.node(
      {{"mesh", b.mesh(json::array(
                    {{{"attributes", {{"POSITION", quad}}}, {"indices", qi}, {"material", 13}}}))},
       {"translation", {0, 8, 0}},
       {"scale", {0.2, 1, 0.2}},
       {"rotation", {1, 0, 0, 0}}}));
  b.doc["cameras"] = json::array(
      {{{"type", "perspective"},
        {"perspective", {{"yfov", 0.6}, {"aspectRatio", 48.0 / 36.0}, {"znear", 0.1}}}}});
  roots.push_back(b.node({{"camera", 0}, {"translation", {0, 0.5, 12}}}));
  b.scene(roots);
  Scene scene = loadGltfSceneBytes(b.gltf(), "grid.gltf");
  EXPECT_TRUE(scene.warnings.empty()) << scene.warnings.front();
  const SceneData data = prepareScene(std::move(scene), RenderSettings{.width = 48, .height = 36});
  EXPECT_NE(data.effects.toString().find("gltf"), std::string::npos) << data.effects.toString();
  EXPECT_NE(data.effects.toString().find("textures"), std::string::npos);
  const Comparison cmp = renderBoth(data, 8);
  expectAgreement(cmp);
}

}  // namespace
}  // namespace pt
