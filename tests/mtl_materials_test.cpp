// OBJ materials from MTL files ("materials": "mtl") and PLY shapes, as the scene loader
// maps them: a Cornell-box-style OBJ+MTL, its warnings, and the errors for what is missing;
// then the MTL mapping rule (mtl_materials.h) one rule at a time.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "common/check.h"
#include "scene/mtl_materials.h"
#include "scene/scene.h"
#include "test_util.h"

namespace pt {
namespace {

const std::filesystem::path kMtlData =
    std::filesystem::path(PT_SOURCE_DIR) / "tests/data/scene/mtl";

std::string loadError(const std::filesystem::path& scene) {
  try {
    loadScene(scene);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
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
  const MtlMaterial textured =
      onlyMaterial("newmtl wood\nKd 0.5 0.3 0.1\nKs 0.2 0.2 0.2\nmap_Kd wood.png\n");
  EXPECT_EQ(textured.material.type, kMaterialCoatedDiffuse);
  ASSERT_EQ(textured.warnings.size(), 1u);
  EXPECT_EQ(textured.warnings[0],
            "m.mtl: material 'wood': texture maps are not simulated; the constant colours are "
            "used");
}

TEST(SceneMtl, UnknownUsemtlNamesTheObjLine) {
  test::TempDir dir;
  dir.write("m.mtl", "newmtl red\nKd 0.8 0.1 0.1\n");
  dir.write("m.obj",
            "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\nusemtl rad\nf 1 3 2\n");
  const std::string m = loadError(dir.write("s.json", R"({"materials": [{"name": "w"}],
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
  const std::string m = loadError(dir.write("s.json", R"({"materials": [{"name": "w"}],
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

  const std::string m = loadError(dir.write("t.json", R"({"materials": [{"name": "w"}],
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
      loadError(dir.write("s.json", R"({"materials": [{"name": "white"}, {"name": "light"}],
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
  const std::string m =
      loadError(dir.write("s.json", R"({"materials": [{"name": "w"}],
                    "shapes": [{"type": "obj", "file": ")" +
                                        deep + R"(/m.obj", "materials": "mtl"}]})"));
  const std::string full = (dir.path() / deep / "missing.mtl").string();
  EXPECT_NE(m.find("(looked for '" + full + "': No such file or directory)"), std::string::npos)
      << m;
}

TEST(SceneMtl, BadColoursAndBadKeyAreInputErrors) {
  test::TempDir dir;
  dir.write("m.mtl", "newmtl hot\nKd 1.5 0.1 0.1\n");
  dir.write("m.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl hot\nf 1 2 3\n");
  const std::string m = loadError(dir.write("s.json", R"({"materials": [{"name": "w"}],
                    "shapes": [{"type": "obj", "file": "m.obj", "materials": "mtl"}]})"));
  EXPECT_NE(m.find("m.mtl: material 'hot': Kd: expected colour components in [0, 1], got (1.5, "
                   "0.1, 0.1)"),
            std::string::npos)
      << m;

  const std::string k = loadError(dir.write("k.json", R"({"materials": [{"name": "w"}],
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
  const std::string m = loadError(dir.write("s.json", R"({"materials": [{"name": "w"}],
                    "shapes": [{"type": "ply", "file": "m.ply", "material": "w"}]})"));
  EXPECT_NE(m.find("m.ply: face 0"), std::string::npos) << m;
  EXPECT_NE(m.find("out of range"), std::string::npos) << m;
  EXPECT_NE(m.find("s.json: shapes[0].file"), std::string::npos) << m;
}

}  // namespace
}  // namespace pt
