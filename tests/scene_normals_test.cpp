// Vertex normals from OBJ and PLY meshes into Scene::normals: transformed with the shape,
// normalized, the geometric normal where a face has none, and flat normals for the triangles
// of meshes without any. The readers themselves: obj_mesh_test.cpp, ply_mesh_test.cpp.
#include <gtest/gtest.h>

#include <string>

#include "render/prepare.h"
#include "scene/load_scene.h"
#include "scene/scene.h"
#include "test_util.h"

namespace pt {
namespace {

void expectNormalNear(vec3 a, vec3 b, const char* what) {
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], 1e-6f) << what << " component " << c;
}

// A scene with a quad (no normals) first, then an OBJ whose first face has normals and whose
// second has none, then a PLY with normals under a rotation and non-uniform scale.
constexpr char kObj[] =
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n"
    "vn 0 0 2\nvn 0.6 0 0.8\n"
    "f 1//1 2//2 3//1\n"
    "f 2 4 3\n";
constexpr char kPly[] =
    "ply\nformat ascii 1.0\nelement vertex 3\n"
    "property float x\nproperty float y\nproperty float z\n"
    "property float nx\nproperty float ny\nproperty float nz\n"
    "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
    "0 0 0 1 0 1\n1 0 0 1 0 1\n0 1 0 1 0 1\n"
    "3 0 1 2\n";

std::string normalsSceneJson() {
  return R"({
  "camera": {"position": [0, 0, 5], "target": [0, 0, 0]},
  "materials": [{"name": "m", "type": "diffuse"}],
  "shapes": [
    {"type": "quad", "material": "m", "vertices": [[0,0,-1],[1,0,-1],[1,1,-1],[0,1,-1]]},
    {"type": "obj", "material": "m", "file": "mesh.obj"},
    {"type": "ply", "material": "m", "file": "mesh.ply",
     "transform": {"scale": [2, 1, 1], "rotate": {"axis": [0, 0, 1], "degrees": 90}}}
  ]
})";
}

TEST(SceneNormals, FromObjAndPlyTransformedAndFilled) {
  test::TempDir dir;
  dir.write("mesh.obj", kObj);
  dir.write("mesh.ply", kPly);
  const Scene scene = loadScene(dir.write("scene.json", normalsSceneJson()));
  ASSERT_EQ(scene.triangles.size(), 5u);  // quad 2, OBJ 2, PLY 1
  ASSERT_EQ(scene.normals.size(), scene.triangles.size());
  // The quad, before any mesh with normals: its geometric normal (+z: counter-clockwise).
  expectNormalNear(scene.normals[0].n0, vec3(0, 0, 1), "quad");
  expectNormalNear(scene.normals[1].n2, vec3(0, 0, 1), "quad");
  // The OBJ's first face: its normals, unit length.
  expectNormalNear(scene.normals[2].n0, vec3(0, 0, 1), "obj face 1, v1");
  expectNormalNear(scene.normals[2].n1, vec3(0.6f, 0, 0.8f), "obj face 1, v2");
  // The OBJ's second face has no normals: the geometric normal.
  expectNormalNear(scene.normals[3].n1, vec3(0, 0, 1), "obj face 2");
  // The PLY's normal (1, 0, 1) / sqrt(2) under scale (2, 1, 1) and 90 degrees about z: the
  // inverse transpose scales x by 1/2, giving (0.5, 0, 1), rotated to (0, 0.5, 1).
  expectNormalNear(scene.normals[4].n0, normalize(vec3(0, 0.5f, 1)), "ply");
}

TEST(SceneNormals, MeshesWithoutNormalsLeaveNone) {
  const Scene scene = loadScene(test::kConfigs / "bunny-box.json");
  EXPECT_TRUE(scene.normals.empty());
  const SceneData data = prepareScene(scene, RenderSettings{.width = 8, .height = 8});
  EXPECT_FALSE(data.effects.shadingNormals);
}

TEST(SceneNormals, ReachTheRendererAsAnEffect) {
  test::TempDir dir;
  dir.write("mesh.obj", kObj);
  dir.write("mesh.ply", kPly);
  const SceneData data = prepareScene(loadScene(dir.write("scene.json", normalsSceneJson())),
                                      RenderSettings{.width = 8, .height = 8});
  EXPECT_TRUE(data.effects.shadingNormals);
  EXPECT_EQ(data.params.normalsPresent, 1u);
  EXPECT_NE(data.effects.toString().find("shading-normals"), std::string::npos);
  EXPECT_EQ(data.normals.size(), 5u);
}

}  // namespace
}  // namespace pt
