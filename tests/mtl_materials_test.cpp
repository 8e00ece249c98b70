// OBJ materials from MTL files ("materials": "mtl") and PLY shapes, as the scene loader
// maps them: a Cornell-box-style OBJ+MTL, its warnings, and the errors for what is missing.
#include <gtest/gtest.h>

#include <string>

#include "common/check.h"
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
  const Material& glossy = materialNamed(scene, "glossy");  // Ns 50: stays diffuse
  EXPECT_EQ(glossy.type, kMaterialDiffuse);
  EXPECT_EQ(glossy.reflectance, vec3(0.5f, 0.4f, 0.3f));
  EXPECT_EQ(materialNamed(scene, "glass").type, kMaterialDiffuse);

  // Triangles take their face's usemtl, in file order: floor (2), wall (2), light (2), then
  // one triangle each for mirror, glass, shiny, glossy and floor again.
  EXPECT_EQ(scene.materialNames[scene.triangles[0].material], "box.mtl:floor");
  EXPECT_EQ(scene.materialNames[scene.triangles[3].material], "box.mtl:leftWall");
  EXPECT_EQ(scene.materialNames[scene.triangles[5].material], "box.mtl:light");
  EXPECT_EQ(scene.materialNames[scene.triangles[6].material], "box.mtl:mirror");
  EXPECT_EQ(scene.materialNames[scene.triangles[10].material], "box.mtl:floor");

  // What could not be simulated is a warning naming the material and what it became.
  std::string warnings;
  for (const std::string& w : scene.warnings) warnings += w + "\n";
  EXPECT_NE(warnings.find("material 'glass': transparency/refraction (illum 7, d 0.1) is not "
                          "simulated; rendered as an opaque diffuse surface"),
            std::string::npos)
      << warnings;
  EXPECT_NE(warnings.find("material 'glossy': glossy highlight Ks (0.2, 0.2, 0.2), Ns 50 is not "
                          "simulated; rendered as diffuse with Kd (0.5, 0.4, 0.3)"),
            std::string::npos)
      << warnings;
  EXPECT_NE(warnings.find("material 'shiny': diffuse part Kd (0.1, 0.1, 0.1)"), std::string::npos)
      << warnings;
  EXPECT_EQ(warnings.find("'floor'"), std::string::npos) << warnings;  // plain Kd: no warning
  EXPECT_EQ(warnings.find("'light'"), std::string::npos) << warnings;
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
