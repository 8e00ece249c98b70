// glTF's material extensions as the reader reads them (host/scene/gltf/
// gltf_material_extensions.h, gltf_volume_media.h): KHR_materials_transmission, _volume,
// _clearcoat, _specular and _sheen into the material's fields, the volume's attenuation as an
// absorbing medium inside the mesh, the unsimulated extensions warned (errors with --strict), bad
// values refused with their JSON path.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "gltf_material_fields.h"
#include "scene/gltf/gltf_scene.h"
#include "scene/gltf/gltf_volume_media.h"
#include "tests/gltf_builder.h"

namespace pt {
namespace {

using nlohmann::json;
using test::GltfBuilder;

// Two triangles, each its own mesh and node, of materials 0 and 1 (the second translated).
GltfBuilder twoTriangles(const json& extensions0, const json& extensions1 = json::object()) {
  GltfBuilder b;
  const int p = b.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3", 3);
  b.mesh(json::array({{{"attributes", {{"POSITION", p}}}, {"material", 0}}}));
  b.mesh(json::array({{{"attributes", {{"POSITION", p}}}, {"material", 1}}}));
  json m0 = {{"pbrMetallicRoughness", {{"metallicFactor", 0.0}, {"roughnessFactor", 0.5}}}};
  json m1 = m0;
  if (!extensions0.empty()) m0["extensions"] = extensions0;
  if (!extensions1.empty()) m1["extensions"] = extensions1;
  b.doc["materials"] = json::array({m0, m1});
  b.scene({b.node({{"mesh", 0}}), b.node({{"mesh", 1}, {"translation", {0, 0, 1}}})});
  return b;
}

Scene readExtended(const GltfBuilder& b, bool strict = false) {
  return loadGltfSceneBytes(b.gltf(), "test.gltf", SceneLoadOptions{.strict = strict});
}

std::string extendedErrorOf(const GltfBuilder& b, bool strict = false) {
  try {
    readExtended(b, strict);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(GltfMaterialExtensions, FactorsIntoTheMaterialsFields) {
  const GltfBuilder b = twoTriangles(
      {{"KHR_materials_transmission", {{"transmissionFactor", 0.75}}},
       {"KHR_materials_volume", {{"thicknessFactor", 0.5}}},
       {"KHR_materials_ior", {{"ior", 1.33}}},
       {"KHR_materials_clearcoat", {{"clearcoatFactor", 0.5}, {"clearcoatRoughnessFactor", 0.4}}},
       {"KHR_materials_specular",
        {{"specularFactor", 0.6}, {"specularColorFactor", {1, 2, 0.5}}}}});
  const Scene s = readExtended(b);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
  ASSERT_EQ(s.materials.size(), 2u);
  const Material& m = s.materials[0];
  EXPECT_EQ(m.type, kMaterialGltf);
  EXPECT_EQ(m.nSamples, kGltfTransmission | kGltfVolume | kGltfClearcoat | kGltfSpecular);
  EXPECT_FLOAT_EQ(m.transmittance.x, 0.75f);
  EXPECT_FLOAT_EQ(m.transmittance.y, 0.5f);
  EXPECT_FLOAT_EQ(m.transmittance.z, 0.16f);  // the coat's alpha, roughness squared
  EXPECT_FLOAT_EQ(m.eta.x, 1.33f);
  EXPECT_FLOAT_EQ(m.eta.y, 0.6f);
  EXPECT_EQ(m.k, vec3(1.0f, 2.0f, 0.5f));
  // Without attenuation the volume refracts but absorbs nothing: no media.
  EXPECT_TRUE(s.media.empty());
  EXPECT_TRUE(s.mediumInterfaces.empty());
  // A material without extensions has none of their fields: the material as before them.
  const Material& plain = s.materials[1];
  EXPECT_EQ(plain.nSamples, 0u);
  EXPECT_EQ(plain.transmittance, vec3(0.0f));
  EXPECT_EQ(plain.k, vec3(0.0f));
  EXPECT_EQ(plain.eta, vec3(1.5f, 0.0f, 0.0f));
}

TEST(GltfMaterialExtensions, ThinWalledUnlessTheVolumeHasThickness) {
  const json transmission = {"KHR_materials_transmission", {{"transmissionFactor", 1.0}}};
  // thicknessFactor 0 (the default): thin-walled.
  const Scene thin =
      readExtended(twoTriangles({transmission, {"KHR_materials_volume", json::object()}}));
  EXPECT_EQ(thin.materials[0].nSamples, kGltfTransmission);
  // A volume without transmission changes nothing.
  const Scene opaque =
      readExtended(twoTriangles({{"KHR_materials_volume", {{"thicknessFactor", 1.0}}}}));
  EXPECT_EQ(opaque.materials[0].nSamples, 0u);
  // A clear coat of factor 0 is no coat; KHR_materials_specular at its defaults still marks it.
  const Scene none =
      readExtended(twoTriangles({{"KHR_materials_clearcoat", {{"clearcoatFactor", 0.0}}}}));
  EXPECT_EQ(none.materials[0].nSamples, 0u);
  const Scene specular = readExtended(twoTriangles({{"KHR_materials_specular", json::object()}}));
  EXPECT_EQ(specular.materials[0].nSamples, kGltfSpecular);
  EXPECT_EQ(specular.materials[0].k, vec3(1.0f));
  EXPECT_EQ(specular.materials[0].eta.y, 1.0f);
}

TEST(GltfMaterialExtensions, AttenuationIsAnAbsorbingMediumInsideTheMesh) {
  const GltfBuilder b = twoTriangles({{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}},
                                      {"KHR_materials_volume",
                                       {{"thicknessFactor", 1.0},
                                        {"attenuationColor", {0.5, 0.25, 1.0}},
                                        {"attenuationDistance", 2.0}}}});
  const Scene s = readExtended(b);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
  ASSERT_EQ(s.media.size(), 1u);
  const Medium& m = s.media[0];
  EXPECT_EQ(m.type, kMediumHomogeneous);
  EXPECT_NEAR(m.sigmaA.x, std::log(2.0) / 2.0, 1e-6);
  EXPECT_NEAR(m.sigmaA.y, std::log(4.0) / 2.0, 1e-6);
  EXPECT_EQ(m.sigmaA.z, 0.0f);
  EXPECT_EQ(m.sigmaS, vec3(0.0f));
  ASSERT_EQ(s.mediumInterfaces.size(), s.triangles.size());
  for (size_t t = 0; t < s.triangles.size(); ++t) {
    const bool glass = s.triangles[t].material == 0u;
    EXPECT_EQ(s.mediumInterfaces[t].inside, glass ? 0u : kNoMedium) << t;
    EXPECT_EQ(s.mediumInterfaces[t].outside, kNoMedium) << t;
  }
  EXPECT_EQ(s.cameraMedium, kNoMedium);
  // A colour channel of 0 passes nothing: a finite, large coefficient.
  const vec3 black = gltf::attenuationSigmaA(vec3(0.0f, 1.0f, 1.0f), 0.5);
  EXPECT_NEAR(black.x, -std::log(1e-6) / 0.5, 1e-3);
  EXPECT_EQ(black.y, 0.0f);
  // Thin-walled, the attenuation has nothing to fill.
  const Scene thin = readExtended(
      twoTriangles({{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}},
                    {"KHR_materials_volume",
                     {{"attenuationColor", {0.5, 0.25, 1.0}}, {"attenuationDistance", 2.0}}}}));
  EXPECT_TRUE(thin.media.empty());
}

// KHR_materials_sheen's factors: the colour and the roughness in gltf_material_fields.h's
// fields, flagged; a colour of 0 (the default) is no sheen.
TEST(GltfMaterialExtensions, SheenFactorsIntoTheMaterialsFields) {
  const GltfBuilder b =
      twoTriangles({{"KHR_materials_sheen",
                     {{"sheenColorFactor", {0.9, 0.5, 0.25}}, {"sheenRoughnessFactor", 0.3}}}},
                   {{"KHR_materials_sheen", {{"sheenRoughnessFactor", 0.3}}}});
  const Scene s = readExtended(b);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
  ASSERT_EQ(s.materials.size(), 2u);
  const Material& m = s.materials[0];
  EXPECT_EQ(m.nSamples & 0xFFFFu, kGltfSheen);
  EXPECT_EQ(gltfSheenColour(m), vec3(0.9f, 0.5f, 0.25f));
  EXPECT_NEAR(gltfSheenRoughness(m), 0.3f, 1e-5f);
  EXPECT_EQ(s.materials[1].nSamples, 0u);  // no colour: no sheen, the plain material
}

TEST(GltfMaterialExtensions, UnsimulatedExtensionsWarnOnceAndAreErrorsWithStrict) {
  GltfBuilder b = twoTriangles({{"KHR_materials_clearcoat", {{"clearcoatFactor", 1.0}}},
                                {"KHR_materials_iridescence", {{"iridescenceFactor", 1}}},
                                {"KHR_materials_anisotropy", {{"anisotropyStrength", 1}}}},
                               {{"KHR_materials_anisotropy", {{"anisotropyStrength", 1}}}});
  b.doc["extensionsUsed"] = {"KHR_materials_clearcoat", "KHR_materials_iridescence"};
  const Scene s = readExtended(b);
  // One warning per kind: the iridescence's (in extensionsUsed, so not again for the material)
  // and the anisotropy's (not again for the second material).
  ASSERT_EQ(s.warnings.size(), 2u);
  EXPECT_EQ(s.warnings[0],
            "test.gltf: extensionsUsed[1]: KHR_materials_iridescence is not simulated (rendered "
            "without it)");
  EXPECT_EQ(s.warnings[1],
            "test.gltf: materials[0].extensions.KHR_materials_anisotropy: not simulated (the "
            "material renders without it)");
  EXPECT_EQ(s.materials[0].transmittance.y, 1.0f);  // the factor is read
  EXPECT_EQ(extendedErrorOf(b, true),
            "test.gltf: extensionsUsed[1]: KHR_materials_iridescence is not simulated (rendered "
            "without it) (an error with --strict)");
}

TEST(GltfMaterialExtensions, BadValuesNameTheirJsonPath) {
  const std::vector<std::pair<json, std::string>> cases = {
      {{{"KHR_materials_transmission", {{"transmissionFactor", 2}}}},
       "materials[0].extensions.KHR_materials_transmission.transmissionFactor: 2 is not in [0, 1]"},
      {{{"KHR_materials_volume", {{"attenuationDistance", 0}}}},
       "materials[0].extensions.KHR_materials_volume.attenuationDistance: must be greater than 0"},
      {{{"KHR_materials_volume", {{"attenuationColor", {1, 2, 0}}}}},
       "materials[0].extensions.KHR_materials_volume.attenuationColor[1]: expected a number in "
       "[0, 1]"},
      {{{"KHR_materials_volume", {{"thicknessFactor", -1}}}},
       "materials[0].extensions.KHR_materials_volume.thicknessFactor: must be at least 0"},
      {{{"KHR_materials_clearcoat", {{"clearcoatRoughnessFactor", "rough"}}}},
       "materials[0].extensions.KHR_materials_clearcoat.clearcoatRoughnessFactor: expected a "
       "number"},
      {{{"KHR_materials_specular", {{"specularColorFactor", {1, 1}}}}},
       "materials[0].extensions.KHR_materials_specular.specularColorFactor: expected 3 numbers"},
      {{{"KHR_materials_specular", {{"specularColorFactor", {1, -1, 1}}}}},
       "materials[0].extensions.KHR_materials_specular.specularColorFactor[1]: expected a "
       "non-negative number"},
      {{{"KHR_materials_transmission",
         {{"transmissionFactor", 1}, {"transmissionTexture", {{"index", "a"}}}}}},
       "materials[0].extensions.KHR_materials_transmission.transmissionTexture.index: expected a "
       "non-negative integer"},
      {{{"KHR_materials_specular", {{"specularTexture", {{"index", 0}, {"texCoord", -1}}}}}},
       "materials[0].extensions.KHR_materials_specular.specularTexture.texCoord: expected a "
       "non-negative integer"},
      {{{"KHR_materials_clearcoat",
         {{"clearcoatFactor", 1}, {"clearcoatTexture", {{"index", 3}}}}}},
       "materials[0].extensions.KHR_materials_clearcoat.clearcoatTexture.index: texture 3 out of "
       "range (the file has 0)"},
      {{{"KHR_materials_clearcoat",
         {{"clearcoatFactor", 1}, {"clearcoatNormalTexture", {{"index", 0}, {"scale", "x"}}}}}},
       "materials[0].extensions.KHR_materials_clearcoat.clearcoatNormalTexture.scale: expected a "
       "finite number"},
      {{{"KHR_materials_sheen", {{"sheenColorFactor", {1, 2, 0}}}}},
       "materials[0].extensions.KHR_materials_sheen.sheenColorFactor[1]: expected a number in "
       "[0, 1]"},
      {{{"KHR_materials_sheen", {{"sheenRoughnessFactor", -0.5}}}},
       "materials[0].extensions.KHR_materials_sheen.sheenRoughnessFactor: -0.5 is not in [0, 1]"},
  };
  for (const auto& [extensions, expected] : cases) {
    EXPECT_EQ(extendedErrorOf(twoTriangles(extensions)), "test.gltf: " + expected);
  }
}

}  // namespace
}  // namespace pt
