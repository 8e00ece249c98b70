// OBJ materials from MTL files ("materials": "mtl") and PLY shapes, as the scene loader
// maps them: a Cornell-box-style OBJ+MTL, its warnings, and the errors for what is missing;
// then the MTL mapping rule (mtl_materials.h) one rule at a time.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "common/check.h"
#include "image/image.h"
#include "image/texture_image.h"
#include "render/prepare.h"
#include "render_compare.h"
#include "scene/load_scene.h"
#include "scene/mtl_materials.h"
#include "scene/scene.h"
#include "scene/textures.h"
#include "test_util.h"
#include "texture.h"

namespace pt {
namespace {

const std::filesystem::path kMtlData =
    std::filesystem::path(PT_SOURCE_DIR) / "tests/data/scene/mtl";

// The message of the InputError that f() throws, or "(no error)".
template <typename F>
std::string errorOf(const F& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

std::string mtlLoadError(const std::filesystem::path& scene) {
  return errorOf([&] { loadScene(scene); });
}

// The scene material of the first triangle whose material is named `mtlName` in box.mtl.
const Material& materialNamed(const Scene& scene, const std::string& mtlName) {
  for (std::size_t i = 0; i < scene.materialNames.size(); ++i) {
    if (scene.materialNames[i] == "box.mtl:" + mtlName) return scene.materials[i];
  }
  ADD_FAILURE() << "no material " << mtlName;
  return scene.materials[0];
}

TEST(SceneMtl, CornellStyleMaterialsMapByTheDocumentedRule) {
  const Scene scene = loadScene(kMtlData / "box.json");
  // The JSON's own material plus the seven that box.obj uses.
  ASSERT_EQ(scene.materials.size(), 8u);
  ASSERT_EQ(scene.triangles.size(), 2u + 2u + 2u + 5u);

  const Material& floor = materialNamed(scene, "floor");
  EXPECT_EQ(floor.type, kMaterialDiffuse);
  EXPECT_EQ(floor.reflectance, vec3(0.725f, 0.71f, 0.68f));  // Kd
  EXPECT_EQ(floor.emission, vec3(0.0f));
  const Material& light = materialNamed(scene, "light");
  EXPECT_EQ(light.emission, vec3(17.0f, 12.0f, 4.0f));      // Ke
  EXPECT_EQ(light.reflectance, vec3(0.78f));                // Ka is ignored, Kd kept
  const Material& mirror = materialNamed(scene, "mirror");  // illum 3
  EXPECT_EQ(mirror.type, kMaterialMirror);
  EXPECT_EQ(mirror.reflectance, vec3(0.9f));              // Ks
  const Material& shiny = materialNamed(scene, "shiny");  // Ns 5000, Ks brighter than Kd
  EXPECT_EQ(shiny.type, kMaterialMirror);
  EXPECT_EQ(shiny.reflectance, vec3(0.8f));
  // Ns 50 with Kd: plastic, a coated diffuse surface of base Kd and alpha sqrt(2 / (50 + 2)).
  const Material& glossy = materialNamed(scene, "glossy");
  EXPECT_EQ(glossy.type, kMaterialCoatedDiffuse);
  EXPECT_EQ(glossy.reflectance, vec3(0.5f, 0.4f, 0.3f));
  EXPECT_FLOAT_EQ(glossy.alphaX, std::sqrt(2.0f / 52.0f));
  EXPECT_EQ(glossy.alphaY, glossy.alphaX);
  const Material& glass = materialNamed(scene, "glass");  // illum 7, Ni 1.5
  EXPECT_EQ(glass.type, kMaterialDielectric);
  EXPECT_EQ(glass.eta, vec3(1.5f, 0.0f, 0.0f));
  EXPECT_EQ(glass.alphaX, 0.0f);

  // Triangles take their face's usemtl, in file order: floor (2), wall (2), light (2), then
  // one triangle each for mirror, glass, shiny, glossy and floor again.
  EXPECT_EQ(scene.materialNames[scene.triangles[0].material], "box.mtl:floor");
  EXPECT_EQ(scene.materialNames[scene.triangles[3].material], "box.mtl:leftWall");
  EXPECT_EQ(scene.materialNames[scene.triangles[5].material], "box.mtl:light");
  EXPECT_EQ(scene.materialNames[scene.triangles[6].material], "box.mtl:mirror");
  EXPECT_EQ(scene.materialNames[scene.triangles[10].material], "box.mtl:floor");

  // What could not be simulated is a warning naming the material and what it became: here
  // only the diffuse part of the mirror. The glass (d 0.1 is part of it) and the glossy
  // highlight are simulated now.
  std::string warnings;
  for (const std::string& w : scene.warnings) warnings += w + "\n";
  EXPECT_NE(warnings.find("material 'shiny': diffuse part Kd (0.1, 0.1, 0.1)"), std::string::npos)
      << warnings;
  EXPECT_EQ(scene.warnings.size(), 1u) << warnings;
}

// ---- the mapping rule, one rule at a time (scene_detail::loadMtlMaterials directly) ----------

using scene_detail::loadMtlMaterials;
using scene_detail::MtlMaterial;

// The one material of an MTL text; fails the test unless there is exactly one.
MtlMaterial onlyMaterial(const std::string& text) {
  std::vector<MtlMaterial> materials = loadMtlMaterials(text, "m.mtl");
  EXPECT_EQ(materials.size(), 1u);
  return materials.empty() ? MtlMaterial{} : materials[0];
}

std::string mtlError(const std::string& text) {
  try {
    loadMtlMaterials(text, "m.mtl");
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    return m;
  }
  return "(no error)";
}

TEST(MtlMapping, PhongExponentToAlphaIsWaltersMatch) {
  EXPECT_FLOAT_EQ(scene_detail::phongExponentToAlpha(0.0f), 1.0f);
  EXPECT_FLOAT_EQ(scene_detail::phongExponentToAlpha(10.0f), std::sqrt(2.0f / 12.0f));
  EXPECT_FLOAT_EQ(scene_detail::phongExponentToAlpha(998.0f), std::sqrt(0.002f));
  EXPECT_EQ(scene_detail::phongExponentToAlpha(std::numeric_limits<float>::infinity()), 0.0f);
}

TEST(MtlMapping, Illum4To7WithNiIsASmoothDielectric) {
  for (const int illum : {4, 6, 7}) {
    SCOPED_TRACE(illum);
    // Kd, Ks, Ns and d are part of the exporter's glass, not a diffuse or glossy part.
    const MtlMaterial m = onlyMaterial("newmtl water\nillum " + std::to_string(illum) +
                                       "\nNi 1.33\nKd 0.5 0.5 0.5\nKs 0.9 0.9 0.9\nNs 500\n"
                                       "d 0.2\nKe 0.1 0.2 0.3\n");
    EXPECT_EQ(m.material.type, kMaterialDielectric);
    EXPECT_EQ(m.material.eta, vec3(1.33f, 0.0f, 0.0f));
    EXPECT_EQ(m.material.alphaX, 0.0f);
    EXPECT_EQ(m.material.alphaY, 0.0f);
    EXPECT_EQ(m.material.reflectance, vec3(0.0f));
    EXPECT_EQ(m.material.emission, vec3(0.1f, 0.2f, 0.3f));
    EXPECT_TRUE(m.warnings.empty()) << m.warnings[0];
  }
}

// tinyobjloader reads a missing Ni as 1 (no refraction); the mapping takes 1.5 instead, and
// only an Ni line of the material's first definition counts.
TEST(MtlMapping, GlassWithoutNiHasIndex1_5) {
  EXPECT_EQ(onlyMaterial("newmtl g\nillum 7\n").material.eta.x, 1.5f);
  EXPECT_EQ(onlyMaterial("Ni 1.2\nnewmtl g\nillum 4\n").material.eta.x, 1.5f);
  const std::vector<MtlMaterial> twice =
      loadMtlMaterials("newmtl g\r\nillum 6\r\nnewmtl g\r\nNi 2\r\n", "m.mtl");
  ASSERT_EQ(twice.size(), 1u);
  EXPECT_EQ(twice[0].material.eta.x, 1.5f);
  // Names as tinyobjloader reads them (with blanks, \r line ends); Ni 1 is kept: it is
  // glass that does not refract, as written.
  EXPECT_EQ(onlyMaterial("newmtl  my glass \r  Ni 1\rillum 7").material.eta.x, 1.0f);
  EXPECT_EQ(onlyMaterial("newmtl g\n\tNi\t2.4\nillum 7\n").material.eta.x, 2.4f);
}

TEST(MtlMapping, GlassNeedsAPositiveFiniteNi) {
  EXPECT_EQ(mtlError("newmtl g\nillum 7\nNi 0\n"),
            "m.mtl: material 'g': Ni: expected a positive finite index of refraction for a glass "
            "(illum 7), got 0");
  EXPECT_EQ(mtlError("newmtl g\nillum 4\nNi -1.5\n"),
            "m.mtl: material 'g': Ni: expected a positive finite index of refraction for a glass "
            "(illum 4), got -1.5");
  // Ni is not read outside the glass rule.
  EXPECT_EQ(onlyMaterial("newmtl g\nillum 2\nNi 0\nKd 0.5 0.5 0.5\n").material.type,
            kMaterialDiffuse);
}

TEST(MtlMapping, GlossyWithDiffuseIsCoatedDiffuse) {
  const MtlMaterial m = onlyMaterial("newmtl paint\nKd 0.6 0.2 0.1\nKs 0.5 0.5 0.5\nNs 98\n");
  const Material& c = m.material;
  EXPECT_EQ(c.type, kMaterialCoatedDiffuse);
  EXPECT_EQ(c.reflectance, vec3(0.6f, 0.2f, 0.1f));
  EXPECT_FLOAT_EQ(c.alphaX, std::sqrt(2.0f / 100.0f));
  EXPECT_EQ(c.alphaY, c.alphaX);
  // pbrt-v4's coateddiffuse defaults for the rest.
  EXPECT_EQ(c.eta, vec3(1.5f, 0.0f, 0.0f));
  EXPECT_EQ(c.thickness, 0.01f);
  EXPECT_EQ(c.transmittance, vec3(0.0f));  // the medium's albedo
  EXPECT_EQ(c.g, 0.0f);
  EXPECT_EQ(c.maxDepth, 10u);
  EXPECT_EQ(c.nSamples, 1u);
  EXPECT_TRUE(m.warnings.empty());

  // Ns >= 1000 with Ks dimmer than Kd is not the mirror: a nearly smooth coat.
  const Material n = onlyMaterial("newmtl p\nKd 0.8 0.8 0.8\nKs 0.5 0.5 0.5\nNs 1000\n").material;
  EXPECT_EQ(n.type, kMaterialCoatedDiffuse);
  EXPECT_FLOAT_EQ(n.alphaX, std::sqrt(2.0f / 1002.0f));
  // No Ns line: tinyobjloader's Ns 1, a very rough coat.
  const Material r = onlyMaterial("newmtl p\nKd 0.8 0.8 0.8\nKs 0.5 0.5 0.5\n").material;
  EXPECT_EQ(r.type, kMaterialCoatedDiffuse);
  EXPECT_FLOAT_EQ(r.alphaX, std::sqrt(2.0f / 3.0f));
}

TEST(MtlMapping, GlossyWithoutDiffuseIsARoughConductorOfReflectanceKs) {
  const MtlMaterial m = onlyMaterial("newmtl brass\nKd 0 0 0\nKs 0.9 0.6 0.3\nNs 48\n");
  const Material& c = m.material;
  EXPECT_EQ(c.type, kMaterialConductor);
  EXPECT_EQ(c.eta, vec3(1.0f));
  // pbrt-v4's reflectance rule: k = 2 sqrt(r) / sqrt(1 - r).
  EXPECT_FLOAT_EQ(c.k.x, 2.0f * std::sqrt(0.9f) / std::sqrt(0.1f));
  EXPECT_FLOAT_EQ(c.k.y, 2.0f * std::sqrt(0.6f) / std::sqrt(0.4f));
  EXPECT_FLOAT_EQ(c.k.z, 2.0f * std::sqrt(0.3f) / std::sqrt(0.7f));
  EXPECT_FLOAT_EQ(c.alphaX, 0.2f);  // sqrt(2 / 50)
  EXPECT_EQ(c.alphaY, c.alphaX);
  EXPECT_EQ(c.reflectance, vec3(0.0f));
  EXPECT_TRUE(m.warnings.empty());
}

TEST(MtlMapping, MirrorRulesAreKept) {
  // illum 3 and 5 whatever Ns; Ns >= 1000 with Ks at least as bright as Kd.
  for (const char* text :
       {"newmtl m\nillum 3\nKs 0.7 0.7 0.7\nNs 10\n", "newmtl m\nillum 5\nKs 0.7 0.7 0.7\n",
        "newmtl m\nillum 2\nKs 0.7 0.7 0.7\nNs 1000\n"}) {
    SCOPED_TRACE(text);
    const MtlMaterial m = onlyMaterial(text);
    EXPECT_EQ(m.material.type, kMaterialMirror);
    EXPECT_EQ(m.material.reflectance, vec3(0.7f));
    EXPECT_TRUE(m.warnings.empty());
  }
  EXPECT_EQ(onlyMaterial("newmtl m\nillum 3\n").material.reflectance, vec3(1.0f));
}

TEST(MtlMapping, NoHighlightIsLambertian) {
  const MtlMaterial m = onlyMaterial("newmtl d\nKd 0.2 0.3 0.4\nNs 500\nKs 0 0 0\n");
  EXPECT_EQ(m.material.type, kMaterialDiffuse);
  EXPECT_EQ(m.material.reflectance, vec3(0.2f, 0.3f, 0.4f));
  EXPECT_TRUE(m.warnings.empty());
}

TEST(MtlMapping, NsOfAGlossyMaterialMustBeNonNegative) {
  EXPECT_EQ(mtlError("newmtl p\nKd 0.5 0.5 0.5\nKs 0.5 0.5 0.5\nNs -5\n"),
            "m.mtl: material 'p': Ns: expected a non-negative specular exponent, got -5");
  // Not read without a highlight.
  EXPECT_EQ(onlyMaterial("newmtl p\nKd 0.5 0.5 0.5\nNs -5\n").material.type, kMaterialDiffuse);
}

// Warnings remain only for what is not simulated.
TEST(MtlMapping, WarningsForTransparencyOutsideGlassAndTextures) {
  const MtlMaterial veil = onlyMaterial("newmtl veil\nKd 0.5 0.5 0.5\nd 0.5\n");
  EXPECT_EQ(veil.material.type, kMaterialDiffuse);
  ASSERT_EQ(veil.warnings.size(), 1u);
  EXPECT_EQ(veil.warnings[0],
            "m.mtl: material 'veil': transparency (illum 0, d 0.5) is not simulated without "
            "illum 4, 6 or 7; rendered as an opaque diffuse surface");
  const MtlMaterial nine =
      onlyMaterial("newmtl nine\nillum 9\nKd 0.5 0.5 0.5\nKs 0.5 0.5 0.5\nNs 20\n");
  ASSERT_EQ(nine.warnings.size(), 1u);
  EXPECT_EQ(nine.warnings[0],
            "m.mtl: material 'nine': transparency (illum 9, d 1) is not simulated without illum 4, "
            "6 or 7; rendered as an opaque coated diffuse surface");
  const MtlMaterial metal = onlyMaterial("newmtl metal\nKs 0.9 0.9 0.9\nNs 30\nd 0.9\n");
  ASSERT_EQ(metal.warnings.size(), 1u);
  EXPECT_NE(metal.warnings[0].find("rendered as an opaque rough conductor"), std::string::npos);
  // map_Kd is simulated now (mtl_materials_test's map tests); map_Ka is not.
  const MtlMaterial textured = onlyMaterial(
      "newmtl wood\nKd 0.5 0.3 0.1\nKs 0.2 0.2 0.2\nmap_Kd wood.png\nmap_Ka amb.png\n");
  EXPECT_EQ(textured.material.type, kMaterialCoatedDiffuse);
  ASSERT_EQ(textured.maps.size(), 1u);
  ASSERT_EQ(textured.warnings.size(), 1u);
  EXPECT_EQ(textured.warnings[0],
            "m.mtl: material 'wood': map_Ka 'amb.png' is not simulated; the constant values are "
            "used");
}

TEST(SceneMtl, UnknownUsemtlNamesTheObjLine) {
  test::TempDir dir;
  dir.write("m.mtl", "newmtl red\nKd 0.8 0.1 0.1\n");
  dir.write("m.obj",
            "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\nusemtl rad\nf 1 3 2\n");
  const std::string m = mtlLoadError(dir.write("s.json", R"({"materials": [{"name": "w"}],
                    "shapes": [{"type": "obj", "file": "m.obj", "materials": "mtl"}]})"));
  EXPECT_NE(m.find("m.obj: line 7: usemtl 'rad': no such material in its mtllib files (did you "
                   "mean 'red'?)"),
            std::string::npos)
      << m;
  EXPECT_NE(m.find("s.json: shapes[0].file"), std::string::npos) << m;
}

TEST(SceneMtl, MissingMtlFileNamesTheObjLine) {
  test::TempDir dir;
  dir.write("m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nmtllib gone.mtl\nusemtl red\nf 1 2 3\n");
  const std::string m = mtlLoadError(dir.write("s.json", R"({"materials": [{"name": "w"}],
                    "shapes": [{"type": "obj", "file": "m.obj", "materials": "mtl"}]})"));
  EXPECT_NE(m.find("m.obj: line 4: cannot open material library 'gone.mtl'"), std::string::npos)
      << m;
}

TEST(SceneMtl, FacesBeforeAnyUsemtlTakeTheShapesMaterialOrFail) {
  test::TempDir dir;
  dir.write("m.mtl", "newmtl red\nKd 0.8 0.1 0.1\n");
  dir.write("m.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nusemtl red\nf 1 3 2\n");
  const Scene scene = loadScene(dir.write("s.json", R"({"materials": [{"name": "w"}],
                    "shapes": [{"type": "obj", "file": "m.obj", "materials": "mtl",
                                "material": "w"}]})"));
  ASSERT_EQ(scene.triangles.size(), 2u);
  EXPECT_EQ(scene.triangles[0].material, 0u);  // "w"
  EXPECT_EQ(scene.materialNames[scene.triangles[1].material], "m.mtl:red");

  const std::string m = mtlLoadError(dir.write("t.json", R"({"materials": [{"name": "w"}],
                    "shapes": [{"type": "obj", "file": "m.obj", "materials": "mtl"}]})"));
  EXPECT_NE(m.find("t.json: shapes[0]: needs a 'material' for the faces of"), std::string::npos)
      << m;
  EXPECT_NE(m.find("m.obj' that come before any usemtl"), std::string::npos) << m;
}

// MTL materials are appended to the scene's materials; a later shape's misspelled material
// must still get a suggestion from the JSON's names (fuzzing found those views dangling).
TEST(SceneMtl, UnknownMaterialAfterAnMtlShapeStillSuggestsTheRightName) {
  test::TempDir dir;
  dir.write("m.mtl",
            "newmtl a\nKd 0.1 0.1 0.1\nnewmtl b\nKd 0.2 0.2 0.2\nnewmtl c\nKd 0.3 0.3 0.3\n");
  dir.write("m.obj",
            "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\nusemtl b\n"
            "f 1 3 2\nusemtl c\nf 2 1 3\n");
  const std::string m =
      mtlLoadError(dir.write("s.json", R"({"materials": [{"name": "white"}, {"name": "light"}],
                    "shapes": [{"type": "obj", "file": "m.obj", "materials": "mtl"},
                               {"type": "quad", "material": "lihgt",
                                "vertices": [[0,0,0],[1,0,0],[1,1,0],[0,1,0]]}]})"));
  EXPECT_NE(m.find("shapes[1].material: unknown material 'lihgt' (did you mean 'light'?)"),
            std::string::npos)
      << m;
}

TEST(SceneMtl, LongPathsAreNeverCutInMessages) {
  test::TempDir dir;
  const std::string deep = std::string(90, 'd') + "/" + std::string(40, 'e');
  dir.write(deep + "/m.obj", "mtllib missing.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n");
  const std::string m = mtlLoadError(dir.write("s.json", R"({"materials": [{"name": "w"}],
                    "shapes": [{"type": "obj", "file": ")" + deep +
                                                             R"(/m.obj", "materials": "mtl"}]})"));
  const std::string full = (dir.path() / deep / "missing.mtl").string();
  EXPECT_NE(m.find("(looked for '" + full + "': No such file or directory)"), std::string::npos)
      << m;
}

TEST(SceneMtl, BadColoursAndBadKeyAreInputErrors) {
  test::TempDir dir;
  dir.write("m.mtl", "newmtl hot\nKd 1.5 0.1 0.1\n");
  dir.write("m.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl hot\nf 1 2 3\n");
  const std::string m = mtlLoadError(dir.write("s.json", R"({"materials": [{"name": "w"}],
                    "shapes": [{"type": "obj", "file": "m.obj", "materials": "mtl"}]})"));
  EXPECT_NE(m.find("m.mtl: material 'hot': Kd: expected colour components in [0, 1], got (1.5, "
                   "0.1, 0.1)"),
            std::string::npos)
      << m;

  const std::string k = mtlLoadError(dir.write("k.json", R"({"materials": [{"name": "w"}],
                    "shapes": [{"type": "obj", "file": "m.obj", "materials": "json"}]})"));
  EXPECT_NE(k.find("shapes[0].materials: expected 'mtl'"), std::string::npos) << k;
}

TEST(ScenePly, PlyShapeGivesTheSameTrianglesAsTheEquivalentObj) {
  test::TempDir dir;
  // A quad and a triangle, with an extra vertex property and an extra face property.
  dir.write("m.ply",
            "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\n"
            "property float z\nproperty uchar red\nelement face 2\n"
            "property list uchar int vertex_indices\nproperty int flags\nend_header\n"
            "0 0 0 1\n1 0 0 2\n1 1 0 3\n0 1 0 4\n0.5 2 0 5\n4 0 1 2 3 7\n3 3 2 4 8\n");
  dir.write("m.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 2 0\nf 1 2 3 4\nf 4 3 5\n");
  auto load = [&](const std::string& type, const std::string& file) {
    return loadScene(dir.write(type + ".json", R"({"materials": [{"name": "w"}],
        "shapes": [{"type": ")" + type + R"(", "file": ")" +
                                                   file +
                                                   R"(", "material": "w",
                    "transform": {"scale": [2, 2, 2], "translate": [1, 0, 0]}}]})"));
  };
  const Scene ply = load("ply", "m.ply");
  const Scene obj = load("obj", "m.obj");
  ASSERT_EQ(ply.triangles.size(), 3u);
  ASSERT_EQ(obj.triangles.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(ply.triangles[i].v0, obj.triangles[i].v0);
    EXPECT_EQ(ply.triangles[i].v1, obj.triangles[i].v1);
    EXPECT_EQ(ply.triangles[i].v2, obj.triangles[i].v2);
  }
  EXPECT_EQ(ply.triangles[2].v2, vec3(2.0f, 4.0f, 0.0f));  // transformed
}

TEST(ScenePly, MalformedPlyNamesTheSceneEntry) {
  test::TempDir dir;
  dir.write("m.ply",
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
            "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
            "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 9\n");
  const std::string m = mtlLoadError(dir.write("s.json", R"({"materials": [{"name": "w"}],
                    "shapes": [{"type": "ply", "file": "m.ply", "material": "w"}]})"));
  EXPECT_NE(m.find("m.ply: face 0"), std::string::npos) << m;
  EXPECT_NE(m.find("out of range"), std::string::npos) << m;
  EXPECT_NE(m.find("s.json: shapes[0].file"), std::string::npos) << m;
}

// ---- texture maps ---------------------------------------------------------------------------

// A 4 x 2 image whose texels all differ, every value in (0, 1).
Image mapImage() {
  Image image(4, 2);
  for (int y = 0; y < 2; ++y) {
    for (int x = 0; x < 4; ++x) {
      image.at(x, y) =
          vec3(0.1f + 0.2f * float(x), 0.2f + 0.5f * float(y), 0.05f + 0.1f * float(x + 4 * y));
    }
  }
  return image;
}

// Texel (x, y) of an image file as a texture reads it: floats as stored, bytes decoded from
// sRGB or linearly.
glm::dvec3 fileTexel(const std::filesystem::path& path, int x, int y, bool srgb) {
  const TextureImage image = readTextureImage(path);
  const std::size_t c = std::size_t(image.channels);
  const std::size_t at = c * (std::size_t(y) * std::size_t(image.width) + std::size_t(x));
  glm::dvec3 v;
  for (int i = 0; i < 3; ++i) {
    const std::size_t k = at + (c == 1 ? 0 : std::size_t(i));
    if (!image.eightBit()) {
      v[i] = image.floats[k];
    } else {
      const double b = image.bytes[k] / 255.0;
      v[i] = !srgb ? b : b <= 0.04045 ? b / 12.92 : std::pow((b + 0.055) / 1.055, 2.4);
    }
  }
  return v;
}

// The (u, v) of texel (x, y)'s centre in a width x height image (row 0 at v = 1).
vec2 texelCentre(int x, int y, int width, int height) {
  return vec2((float(x) + 0.5f) / float(width), 1.0f - (float(y) + 0.5f) / float(height));
}

// A unit quad with texture coordinates (0, 0) .. (1, 1) in m.obj, its faces of material `m`
// from m.mtl (`mtl`, written here), loaded as a scene.
Scene loadMappedQuad(const test::TempDir& dir, const std::string& mtl) {
  dir.write("m.mtl", mtl);
  dir.write("m.obj",
            "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
            "usemtl m\nf 1/1 2/2 3/3 4/4\n");
  return loadScene(dir.write("s.json", R"({"materials": [{"name": "w"}],
                    "shapes": [{"type": "obj", "file": "m.obj", "materials": "mtl"}]})"));
}

struct MappedMaterial {
  const Scene& scene;
  MaterialTextures textures;
  Material material;
  TextureTables tables() const {
    return TextureTables{scene.textureNodes.data(), scene.imageWords.data(),
                         scene.materialTextures.data(), scene.uvs.data()};
  }
  vec3 at(uint texture, vec2 uv) const { return evalTexture(tables(), texture, uv); }
};

MappedMaterial mtlMaterial(const Scene& scene) {
  EXPECT_EQ(scene.materialNames.size(), 2u);
  EXPECT_EQ(scene.materialTextures.size(), scene.materials.size());
  if (scene.materialTextures.size() < 2) return {scene, noMaterialTextures(), Material{}};
  return {scene, scene.materialTextures[1], scene.materials[1]};
}

void expectNearMtl(vec3 got, glm::dvec3 want, double tolerance, const std::string& what) {
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(double(got[c]), want[c], tolerance) << what << " channel " << c;
  }
}

TEST(SceneMtlMaps, MapKdIsTheReflectanceTimesKd) {
  const test::TempDir dir;
  writeImage(mapImage(), dir / "wood.exr");
  const Scene scene = loadMappedQuad(dir, "newmtl m\nKd 0.5 0.25 1\nmap_Kd wood.exr\n");
  EXPECT_TRUE(scene.warnings.empty());
  const MappedMaterial m = mtlMaterial(scene);
  EXPECT_EQ(m.material.type, kMaterialDiffuse);
  ASSERT_NE(m.textures.reflectance, kNoTexture);
  EXPECT_EQ(m.textures.alpha, kNoTexture);
  EXPECT_EQ(m.textures.displacement, kNoTexture);
  // The quad keeps the OBJ's texture coordinates.
  ASSERT_EQ(scene.uvs.size(), scene.triangles.size());
  EXPECT_EQ(scene.uvs[0].uv1, vec2(1.0f, 0.0f));
  for (int y = 0; y < 2; ++y) {
    for (int x = 0; x < 4; ++x) {
      const vec2 uv = texelCentre(x, y, 4, 2);
      const glm::dvec3 want = glm::dvec3(0.5, 0.25, 1.0) * fileTexel(dir / "wood.exr", x, y, false);
      expectNearMtl(m.at(m.textures.reflectance, uv), want, 1e-6, "texel " + std::to_string(x));
      // The material at that point: the diffuse reflectance replaced.
      const Material r = resolveMaterial(m.tables(), m.material, m.textures, uv);
      expectNearMtl(r.reflectance, want, 1e-6, "resolved");
    }
  }
}

TEST(SceneMtlMaps, EightBitMapKdIsDecodedFromSrgbAndUsedAloneWithoutKd) {
  const test::TempDir dir;
  writeImage(mapImage(), dir / "wood.png");
  // No Kd line: the image alone (tinyobjloader's 0.6 only chooses the rule).
  const Scene scene = loadMappedQuad(dir, "newmtl m\nmap_Kd wood.png\n");
  const MappedMaterial m = mtlMaterial(scene);
  EXPECT_EQ(m.material.type, kMaterialDiffuse);
  ASSERT_NE(m.textures.reflectance, kNoTexture);
  const glm::dvec3 want = fileTexel(dir / "wood.png", 2, 1, true);
  expectNearMtl(m.at(m.textures.reflectance, texelCentre(2, 1, 4, 2)), want, 1e-6, "texel (2, 1)");
  // And close to the colour written (8-bit sRGB quantizes it).
  expectNearMtl(m.at(m.textures.reflectance, texelCentre(2, 1, 4, 2)),
                glm::dvec3(mapImage().at(2, 1)), 5e-3, "written");
}

TEST(SceneMtlMaps, MapKsTexturesMirrorsAndConductorsTimesKs) {
  const test::TempDir dir;
  writeImage(mapImage(), dir / "s.exr");
  for (const std::string& rule : {std::string("illum 3\nKs 0.5 0.5 0.5\n"),
                                  std::string("Kd 0 0 0\nKs 0.5 0.5 0.5\nNs 20\n")}) {
    const Scene scene = loadMappedQuad(dir, "newmtl m\n" + rule + "map_Ks s.exr\n");
    EXPECT_TRUE(scene.warnings.empty()) << scene.warnings[0];
    const MappedMaterial m = mtlMaterial(scene);
    ASSERT_NE(m.textures.reflectance, kNoTexture) << rule;
    expectNearMtl(m.at(m.textures.reflectance, texelCentre(1, 0, 4, 2)),
                  0.5 * fileTexel(dir / "s.exr", 1, 0, false), 1e-6, rule);
  }
  // A mirror of black Ks has reflectance 1: its map alone.
  const Scene black = loadMappedQuad(dir, "newmtl m\nillum 5\nmap_Ks s.exr\n");
  const MappedMaterial m = mtlMaterial(black);
  EXPECT_EQ(m.material.type, kMaterialMirror);
  expectNearMtl(m.at(m.textures.reflectance, texelCentre(3, 1, 4, 2)),
                fileTexel(dir / "s.exr", 3, 1, false), 1e-6, "illum 5");
}

TEST(SceneMtlMaps, ScaleOffsetAndClampOptionsMapTheCoordinates) {
  const test::TempDir dir;
  writeImage(mapImage(), dir / "t.exr");
  const Scene scene =
      loadMappedQuad(dir, "newmtl m\nKd 1 1 1\nmap_Kd -s 2 3 1 -o 0.25 0.5 0 -clamp on t.exr\n");
  const MappedMaterial m = mtlMaterial(scene);
  ASSERT_NE(m.textures.reflectance, kNoTexture);
  const TextureNode node = scene.textureNodes[m.textures.reflectance];
  EXPECT_EQ(node.mapping, vec4(2.0f, 3.0f, 0.25f, 0.5f));
  EXPECT_EQ((node.flags >> 4) & 0xFu, kWrapClamp);
  // (s, t) = (2 u + 0.25, 3 v + 0.5) at texel (1, 0)'s centre (0.375, 0.75).
  const vec2 uv((0.375f - 0.25f) / 2.0f, (0.75f - 0.5f) / 3.0f);
  expectNearMtl(m.at(m.textures.reflectance, uv), fileTexel(dir / "t.exr", 1, 0, false), 1e-5,
                "-s -o");
  // Beyond the image's top-right corner: clamped to its texel.
  expectNearMtl(m.at(m.textures.reflectance, vec2(0.6f, 0.9f)),
                fileTexel(dir / "t.exr", 3, 0, false), 1e-6, "-clamp on");
  // Without -clamp, repeated.
  // Without -clamp, repeated; -s with two numbers (tinyobjloader would take the file name
  // for w and lose the map).
  const Scene repeated = loadMappedQuad(dir, "newmtl m\nmap_Kd -s 2 3 t.exr\n");
  const uint texture = mtlMaterial(repeated).textures.reflectance;
  ASSERT_NE(texture, kNoTexture);
  EXPECT_EQ(repeated.textureNodes[texture].mapping, vec4(2.0f, 3.0f, 0.0f, 0.0f));
  EXPECT_EQ((repeated.textureNodes[texture].flags >> 4) & 0xFu, kWrapRepeat);
}

TEST(SceneMtlMaps, MapDIsALinearAlphaTimesD) {
  const test::TempDir dir;
  Image mask(2, 1);
  mask.at(0, 0) = vec3(0.0f);
  mask.at(1, 0) = vec3(0.6f);
  writeImage(mask, dir / "mask.png");
  const Scene scene = loadMappedQuad(dir, "newmtl m\nKd 0.5 0.5 0.5\nd 0.5\nmap_d mask.png\n");
  // d < 1 is simulated by the alpha: no transparency warning.
  EXPECT_TRUE(scene.warnings.empty()) << scene.warnings[0];
  const MappedMaterial m = mtlMaterial(scene);
  ASSERT_NE(m.textures.alpha, kNoTexture);
  EXPECT_EQ(m.textures.reflectance, kNoTexture);
  EXPECT_EQ(evalFloatTexture(m.tables(), m.textures.alpha, texelCentre(0, 0, 2, 1)), 0.0f);
  // The PNG's byte read linearly (not sRGB-decoded), times d.
  EXPECT_NEAR(evalFloatTexture(m.tables(), m.textures.alpha, texelCentre(1, 0, 2, 1)),
              0.5 * fileTexel(dir / "mask.png", 1, 0, false).x, 1e-6);
  // Where the alpha is 0 the surface is cut away: on the second triangle (corners (0, 0),
  // (1, 1), (0, 1)) at texel (0, 0)'s centre (0.25, 0.5).
  EXPECT_FALSE(alphaKeepsHit(m.tables(), 1, 1, vec3(0.5f, 0.25f, 0.25f), 0.0f));
  EXPECT_TRUE(alphaKeepsHit(m.tables(), 1, 1, vec3(0.0f, 1.0f, 0.0f), 0.0f));
}

TEST(SceneMtlMaps, BumpMapsAreDisplacementScaledByBm) {
  const test::TempDir dir;
  writeImage(mapImage(), dir / "b.exr");
  for (const std::string& statement : {"map_Bump", "map_bump", "bump"}) {
    const Scene scene =
        loadMappedQuad(dir, "newmtl m\nKd 0.5 0.5 0.5\n" + statement + " -bm 0.2 b.exr\n");
    EXPECT_TRUE(scene.warnings.empty()) << scene.warnings[0];
    const MappedMaterial m = mtlMaterial(scene);
    ASSERT_NE(m.textures.displacement, kNoTexture) << statement;
    EXPECT_EQ(m.textures.reflectance, kNoTexture);
    const glm::dvec3 t = fileTexel(dir / "b.exr", 2, 0, false);
    EXPECT_NEAR(evalFloatTexture(m.tables(), m.textures.displacement, texelCentre(2, 0, 4, 2)),
                0.2 * (t.x + t.y + t.z) / 3.0, 1e-6)
        << statement;
  }
}

TEST(SceneMtlMaps, UnreadableImageIsAOneLineErrorNamingMtlMaterialAndMap) {
  const test::TempDir dir;
  const std::string missing =
      errorOf([&] { loadMappedQuad(dir, "newmtl m\nKd 0.5 0.5 0.5\nmap_Kd gone.png\n"); });
  EXPECT_EQ(missing.find('\n'), std::string::npos) << missing;
  EXPECT_EQ(missing.rfind((dir / "m.mtl").string() + ": material 'm': map_Kd 'gone.png': " +
                              (dir / "gone.png").string() + ": ",
                          0),
            0u)
      << missing;
  dir.write("bad.png", "not a png");
  const std::string bad = errorOf([&] { loadMappedQuad(dir, "newmtl m\nmap_d bad.png\n"); });
  EXPECT_NE(bad.find("m.mtl: material 'm': map_d 'bad.png': "), std::string::npos) << bad;
  EXPECT_EQ(bad.find('\n'), std::string::npos) << bad;
  // A material no face uses reads no image.
  dir.write("m.mtl", "newmtl m\nKd 0.5 0.5 0.5\nnewmtl unused\nmap_Kd gone.png\n");
  EXPECT_NO_THROW(loadScene(dir / "s.json"));
}

TEST(MtlMapping, MapsAndOptionsNotSimulatedAreWarnings) {
  const MtlMaterial m = onlyMaterial(
      "newmtl m\nKd 0.5 0.5 0.5\nmap_Kd -mm 0.1 0.9 -imfchan r -cc on -s 2 2 d.png\n"
      "map_Ks spec.png\nmap_Ke glow.png\nnorm n.png\ndisp h.png\nmap_Ns ns.png\n");
  EXPECT_EQ(m.material.type, kMaterialDiffuse);
  ASSERT_EQ(m.maps.size(), 1u);
  // -cc is unknown to tinyobjloader; the options after it still apply.
  EXPECT_EQ(m.maps[0].file, "d.png");
  EXPECT_EQ(m.maps[0].desc.filename, std::filesystem::path("d.png"));
  EXPECT_EQ(m.maps[0].desc.mapping, vec4(2.0f, 2.0f, 0.0f, 0.0f));
  EXPECT_EQ(m.maps[0].desc.encoding, "sRGB");
  const std::vector<std::string> want = {
      "m.mtl: material 'm': map_Kd 'd.png': options -mm, -imfchan, -cc are not simulated; "
      "ignored",
      "m.mtl: material 'm': map_Ks 'spec.png' is not simulated for a diffuse surface (it has no "
      "parameter for Ks); ignored",
      "m.mtl: material 'm': map_Ns 'ns.png' is not simulated; the constant values are used",
      "m.mtl: material 'm': disp 'h.png' is not simulated; the constant values are used",
      "m.mtl: material 'm': map_Ke 'glow.png' is not simulated; the constant values are used",
      "m.mtl: material 'm': norm 'n.png' is not simulated; the constant values are used",
  };
  EXPECT_EQ(m.warnings, want);

  // The coat of a coated diffuse surface has no colour; glass is clear.
  const MtlMaterial coated =
      onlyMaterial("newmtl c\nKd 0.5 0.5 0.5\nKs 0.5 0.5 0.5\nNs 10\nmap_Ks s.png\n");
  ASSERT_EQ(coated.warnings.size(), 1u);
  EXPECT_NE(coated.warnings[0].find("coated diffuse surface (its coat has no colour); ignored"),
            std::string::npos)
      << coated.warnings[0];
  const MtlMaterial glass = onlyMaterial("newmtl g\nillum 7\nmap_Kd k.png\nmap_d a.png\nd 0.1\n");
  ASSERT_EQ(glass.warnings.size(), 1u);
  EXPECT_NE(glass.warnings[0].find("map_Kd 'k.png' is not simulated for a glass"),
            std::string::npos);
  ASSERT_EQ(glass.maps.size(), 1u);  // the alpha, not times d (part of the glass)
  EXPECT_EQ(glass.maps[0].target, scene_detail::MtlMap::Target::kAlpha);
  EXPECT_EQ(glass.maps[0].factor, vec3(1.0f));
  EXPECT_EQ(glass.maps[0].desc.encoding, "linear");
}

TEST(MtlMapping, MapPathsAreRelativeToTheMtlFileAndBadOptionsAreErrors) {
  const std::vector<MtlMaterial> m =
      loadMtlMaterials("newmtl m\nmap_Kd -colorspace linear tex/a b.png\n", "dir/m.mtl");
  ASSERT_EQ(m.size(), 1u);
  ASSERT_EQ(m[0].maps.size(), 1u);
  EXPECT_EQ(m[0].maps[0].desc.filename, std::filesystem::path("dir/tex/a b.png"));
  EXPECT_EQ(m[0].maps[0].desc.encoding, "linear");
  EXPECT_EQ(mtlError("newmtl m\nmap_Kd -colorspace xyz a.png\n"),
            "m.mtl: material 'm': map_Kd 'a.png': -colorspace: expected 'sRGB' or 'linear', got "
            "'xyz'");
  EXPECT_EQ(mtlError("newmtl m\nbump -bm nan a.png\n"),
            "m.mtl: material 'm': bump 'a.png': -bm: expected a finite number, got nan");
  EXPECT_EQ(mtlError("newmtl m\nmap_Kd -s inf 1 a.png\n"),
            "m.mtl: material 'm': map_Kd 'a.png': -s: expected finite numbers, got inf 1");
  EXPECT_EQ(mtlError("newmtl m\nmap_d -o 0 1e39 a.png\n"),
            "m.mtl: material 'm': map_d 'a.png': -o: expected finite numbers, got 0 inf");
}

// An OBJ plane with map_Kd under a distant light: both backends agree.
TEST(SceneMtlMaps, MapKdQuadRendersAlikeOnBothBackends) {
  const test::TempDir dir;
  writeImage(mapImage(), dir / "wood.png");
  dir.write("p.mtl", "newmtl m\nKd 0.9 0.8 0.7\nmap_Kd -s 2 2 wood.png\n");
  dir.write("p.obj",
            "mtllib p.mtl\nv 10 0 -10\nv -10 0 -10\nv -10 0 10\nv 10 0 10\nvt 0 0\nvt 1 0\n"
            "vt 1 1\nvt 0 1\nusemtl m\nf 1/1 2/2 3/3 4/4\n");
  const Scene scene = loadScene(dir.write("s.json", R"({"camera": {"position": [0, 10, 0],
      "target": [0, 0, 0], "up": [0, 0, 1], "vfov": 60, "width": 32, "height": 32},
    "integrator": {"spp": 16, "maxDepth": 2},
    "materials": [{"name": "w"}],
    "shapes": [{"type": "obj", "file": "p.obj", "materials": "mtl"}],
    "lights": [{"type": "distant", "direction": [0, 1, 0], "radiance": [3, 3, 3]}]})"));
  const SceneData data = prepareScene(scene, RenderSettings{});
  EXPECT_TRUE(data.effects.textures);
  expectAgreement(renderBoth(data, data.spp));
}

}  // namespace
}  // namespace pt
