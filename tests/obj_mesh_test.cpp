// Tests of the OBJ reader's vertex normals (host/scene/obj_mesh): `v//vn` and `v/vt/vn`
// references give one normal triple per triangle, fanned like the triangles; faces without
// normals among faces with them get zeros; a file whose faces reference no normal gives none;
// `vn` lines that are not three finite floats give their one-line message. Texture
// coordinates likewise: `v/vt` and `v/vt/vn` give one triple per triangle, faces without
// them get pbrt-v4's defaults, malformed `vt` lines their message. The reader's other
// messages are tested through the scene loader (scene_test.cpp).
#include <gtest/gtest.h>

#include <array>
#include <string>
#include <vector>

#include "common/check.h"
#include "scene/obj_mesh.h"

namespace pt {
namespace {

using scene_detail::loadObjMesh;
using scene_detail::ObjMesh;

const std::string kContext = " (referenced by scene.json: shapes[0].file)";

// Lines 1-5: five vertices, a pentagon's corners; lines 6-10: a normal for each, distinct
// and not of unit length (the reader keeps them as read).
const std::string kObjVertices = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 1.5 0\n";
const std::string kNormals = "vn 0 0 1\nvn 0 0.5 2\nvn 0.25 0 1\nvn -1 0 4\nvn 0 -0.75 1\n";
const std::vector<glm::dvec3> kPoints = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 1.5, 0}};
const std::vector<glm::dvec3> kNormalValues = {
    {0, 0, 1}, {0, 0.5, 2}, {0.25, 0, 1}, {-1, 0, 4}, {0, -0.75, 1}};

ObjMesh loadObj(const std::string& text) {
  return loadObjMesh(text, "mesh.obj", kContext);
}

// Checks triangle t against the point indices `points` and normal indices `normals` (-1:
// a zero normal).
void expectObjTriangle(const ObjMesh& mesh, std::size_t t, const std::array<int, 3>& points,
                       const std::array<int, 3>& normals) {
  ASSERT_LT(t, mesh.triangles.size());
  ASSERT_LT(t, mesh.normals.size());
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(mesh.triangles[t][k], kPoints[static_cast<std::size_t>(points[k])])
        << "triangle " << t << " vertex " << k;
    const glm::dvec3 normal =
        normals[k] < 0 ? glm::dvec3(0.0) : kNormalValues[static_cast<std::size_t>(normals[k])];
    EXPECT_EQ(mesh.normals[t][k], normal) << "triangle " << t << " vertex " << k;
  }
}

TEST(ObjMeshNormals, VertexNormalReferencesFollowTheFan) {
  // The normals of each corner differ from its vertex index, so that a mix-up shows.
  const ObjMesh mesh =
      loadObj(kObjVertices + kNormals + "f 1//5 2//4 3//3 4//2 5//1\nf 2//1 3//1 4//2\n");
  ASSERT_EQ(mesh.triangles.size(), 4u);
  ASSERT_EQ(mesh.normals.size(), 4u);
  expectObjTriangle(mesh, 0, {0, 1, 2}, {4, 3, 2});
  expectObjTriangle(mesh, 1, {0, 2, 3}, {4, 2, 1});
  expectObjTriangle(mesh, 2, {0, 3, 4}, {4, 1, 0});
  expectObjTriangle(mesh, 3, {1, 2, 3}, {0, 0, 1});
}

TEST(ObjMeshNormals, TextureAndNormalReferences) {
  // v/vt/vn, with negative (relative) indices too.
  const ObjMesh mesh = loadObj(kObjVertices + kNormals +
                               "vt 0 0\nvt 1 0\nvt 1 1\nf 1/1/1 2/2/2 3/3/3 4/1/4\n"
                               "f -5/-3/-1 -4/-2/-2 -3/-1/-3\n");
  ASSERT_EQ(mesh.triangles.size(), 3u);
  ASSERT_EQ(mesh.normals.size(), 3u);
  expectObjTriangle(mesh, 0, {0, 1, 2}, {0, 1, 2});
  expectObjTriangle(mesh, 1, {0, 2, 3}, {0, 2, 3});
  expectObjTriangle(mesh, 2, {0, 1, 2}, {4, 3, 2});
}

TEST(ObjMeshNormals, FacesWithoutNormalsAmongOthersGetZeros) {
  // Without, with (v//vn), without (v/vt), with (v/vt/vn), normals at only some corners:
  // zeros for the faces without, also for those before the first with.
  const ObjMesh mesh = loadObj(kObjVertices + kNormals +
                               "vt 0 0\nf 1 2 3 4\nf 1//1 2//2 3//3\nf 1/1 3/1 4/1\n"
                               "f 2/1/4 3/1/5 4/1/1\nf 1//1 2 3\nf 2 3//2 4\n");
  ASSERT_EQ(mesh.triangles.size(), 7u);
  ASSERT_EQ(mesh.normals.size(), 7u);
  expectObjTriangle(mesh, 0, {0, 1, 2}, {-1, -1, -1});
  expectObjTriangle(mesh, 1, {0, 2, 3}, {-1, -1, -1});
  expectObjTriangle(mesh, 2, {0, 1, 2}, {0, 1, 2});
  expectObjTriangle(mesh, 3, {0, 2, 3}, {-1, -1, -1});
  expectObjTriangle(mesh, 4, {1, 2, 3}, {3, 4, 0});
  expectObjTriangle(mesh, 5, {0, 1, 2}, {-1, -1, -1});
  expectObjTriangle(mesh, 6, {1, 2, 3}, {-1, -1, -1});
  // The materials stay parallel too.
  EXPECT_EQ(mesh.material.size(), 7u);
}

TEST(ObjMeshNormals, FilesWhoseFacesReferenceNoNormalHaveNone) {
  EXPECT_TRUE(loadObj(kObjVertices + "f 1 2 3 4\n").normals.empty());
  // Normals defined but not referenced, texture coordinates, lines and points.
  const ObjMesh mesh =
      loadObj(kObjVertices + kNormals + "vt 0 0\nf 1/1 2/1 3/1\nf 1 3 4\nl 1//1 2//2\np 3//3\n");
  EXPECT_EQ(mesh.triangles.size(), 2u);
  EXPECT_TRUE(mesh.normals.empty());
}

TEST(ObjMeshNormals, NormalsAreKeptAsRead) {
  const ObjMesh mesh =
      loadObj(kObjVertices + "vn 0 0 0\nvn 3 +4 -0\nvn 0.125e0 2E1 .5\nf 1//1 2//2 3//3\n");
  ASSERT_EQ(mesh.normals.size(), 1u);
  EXPECT_EQ(mesh.normals[0][0], glm::dvec3(0.0));  // for the scene loader to replace
  EXPECT_EQ(mesh.normals[0][1], glm::dvec3(3, 4, 0));
  EXPECT_EQ(mesh.normals[0][2], glm::dvec3(0.125, 20, 0.5));
}

// The message for `text`, or empty (and a test failure) if it loads or throws anything else.
std::string objError(const std::string& text) {
  try {
    loadObjMesh(text, "bad.obj", kContext);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected an InputError";
  return {};
}

TEST(ObjMeshNormals, MalformedNormalLines) {
  // Line 6 is the `vn` line; it is checked whether or not a face uses it.
  const std::string face = "f 1//1 2//1 3//1\n";
  EXPECT_EQ(objError(kObjVertices + "vn 0 nan 1\n" + face),
            "bad.obj: line 6: non-finite normal component 'nan'" + kContext);
  EXPECT_EQ(objError(kObjVertices + "vn -inf 0 1\nf 1 2 3\n"),
            "bad.obj: line 6: non-finite normal component '-inf'" + kContext);
  EXPECT_EQ(objError(kObjVertices + "vn 0 0 1e39\n" + face),
            "bad.obj: line 6: non-finite normal component '1e39' (too large for a 32-bit float)" +
                kContext);
  EXPECT_EQ(objError(kObjVertices + "vn 0 x 1\n" + face),
            "bad.obj: line 6: normal component 'x' is not a number" + kContext);
  EXPECT_EQ(objError(kObjVertices + "vn 0 1\n" + face),
            "bad.obj: line 6: normal has 2 components (need 3)" + kContext);
  EXPECT_EQ(objError(kObjVertices + "vn 1\n" + face),
            "bad.obj: line 6: normal has 1 component (need 3)" + kContext);
  // References to normals that do not exist.
  EXPECT_EQ(objError(kObjVertices + "vn 0 0 1\nf 1//1 2//2 3//1\n"),
            "bad.obj: line 7: normal index 2 out of range (file has 1 normals)" + kContext);
  EXPECT_EQ(objError(kObjVertices + "f 1//-1 2//1 3//1\nvn 0 0 1\n"),
            "bad.obj: line 6: normal index -1 out of range (0 normals defined before this line)" +
                kContext);
}

// ---- Texture coordinates ----

// Lines 6-10 (after kVertices): a texture coordinate for each vertex, distinct, exact in a
// float, some outside [0, 1] and negative (kept as written, not flipped or wrapped).
const std::string kTexcoords = "vt 0.25 0.5\nvt 0.75 -0.125\nvt 1.5 1 0.5\nvt 0 2\nvt -0.5 0.375\n";
const std::vector<glm::vec2> kUvValues = {
    {0.25f, 0.5f}, {0.75f, -0.125f}, {1.5f, 1.0f}, {0.0f, 2.0f}, {-0.5f, 0.375f}};

// Checks the texture coordinates of triangle t against the indices `uvs` into kUvValues
// (all -1: pbrt-v4's defaults (0,0), (1,0), (1,1)).
void expectUvs(const ObjMesh& mesh, std::size_t t, const std::array<int, 3>& uvs) {
  ASSERT_LT(t, mesh.uvs.size());
  const std::array<glm::vec2, 3> defaults = {glm::vec2(0, 0), glm::vec2(1, 0), glm::vec2(1, 1)};
  for (std::size_t k = 0; k < 3; ++k) {
    const glm::vec2 uv = uvs[k] < 0 ? defaults[k] : kUvValues[static_cast<std::size_t>(uvs[k])];
    EXPECT_EQ(mesh.uvs[t][k], uv) << "triangle " << t << " vertex " << k;
  }
}

TEST(ObjMeshUvs, TextureReferencesFollowTheFan) {
  // v/vt and v/vt/vn; the texture coordinate of each corner differs from its vertex index,
  // and negative (relative) indices.
  const ObjMesh mesh = loadObj(kObjVertices + kTexcoords + kNormals +
                               "f 1/5 2/4 3/3 4/2 5/1\nf 2/1/1 3/1/1 4/2/2\nf -5/-1 -4/-2 -3/-3\n");
  ASSERT_EQ(mesh.triangles.size(), 5u);
  ASSERT_EQ(mesh.uvs.size(), 5u);
  expectUvs(mesh, 0, {4, 3, 2});
  expectUvs(mesh, 1, {4, 2, 1});
  expectUvs(mesh, 2, {4, 1, 0});
  expectUvs(mesh, 3, {0, 0, 1});
  expectUvs(mesh, 4, {4, 3, 2});
  // Normals only where referenced (face 2): zeros elsewhere.
  ASSERT_EQ(mesh.normals.size(), 5u);
  expectObjTriangle(mesh, 3, {1, 2, 3}, {0, 0, 1});
  EXPECT_EQ(mesh.normals[0][0], glm::dvec3(0.0));
}

TEST(ObjMeshUvs, FacesWithoutTextureCoordinatesGetTheDefaults) {
  // Without (v), with (v/vt), without (v//vn), with (v/vt/vn), at only some corners: the
  // defaults for each triangle of the faces without, also for those before the first with.
  const ObjMesh mesh = loadObj(kObjVertices + kTexcoords + kNormals +
                               "f 1 2 3 4\nf 1/1 2/2 3/3\nf 1//1 3//1 4//1\n"
                               "f 2/4/4 3/5/5 4/1/1\nf 1/1 2 3\nf 2 3/2/1 4 5\n");
  ASSERT_EQ(mesh.triangles.size(), 8u);
  ASSERT_EQ(mesh.uvs.size(), 8u);
  expectUvs(mesh, 0, {-1, -1, -1});
  expectUvs(mesh, 1, {-1, -1, -1});
  expectUvs(mesh, 2, {0, 1, 2});
  expectUvs(mesh, 3, {-1, -1, -1});
  expectUvs(mesh, 4, {3, 4, 0});
  expectUvs(mesh, 5, {-1, -1, -1});
  expectUvs(mesh, 6, {-1, -1, -1});
  expectUvs(mesh, 7, {-1, -1, -1});
  EXPECT_EQ(mesh.material.size(), 8u);
  EXPECT_EQ(mesh.normals.size(), 8u);
}

TEST(ObjMeshUvs, FilesWhoseFacesReferenceNoTextureCoordinateHaveNone) {
  EXPECT_TRUE(loadObj(kObjVertices + "f 1 2 3 4\n").uvs.empty());
  // Texture coordinates defined but not referenced by faces (normals, lines and points).
  const ObjMesh mesh = loadObj(kObjVertices + kTexcoords + kNormals +
                               "f 1//1 2//1 3//1\nf 1 3 4\nl 1/1 2/2\np 3/3\n");
  EXPECT_EQ(mesh.triangles.size(), 2u);
  EXPECT_TRUE(mesh.uvs.empty());
  EXPECT_EQ(mesh.normals.size(), 2u);
}

TEST(ObjMeshUvs, TextureCoordinatesAreKeptAsRead) {
  // A missing v is 0; w is ignored; signs, exponents.
  const ObjMesh mesh =
      loadObj(kObjVertices + "vt 0.5\nvt +3 -0 7\nvt 0.125e0 2E1 .5 9\nf 1/1 2/2 3/3\n");
  ASSERT_EQ(mesh.uvs.size(), 1u);
  EXPECT_EQ(mesh.uvs[0][0], glm::vec2(0.5f, 0.0f));
  EXPECT_EQ(mesh.uvs[0][1], glm::vec2(3.0f, 0.0f));
  EXPECT_EQ(mesh.uvs[0][2], glm::vec2(0.125f, 20.0f));
}

TEST(ObjMeshUvs, MalformedTextureCoordinateLines) {
  // Line 6 is the `vt` line; it is checked whether or not a face uses it.
  const std::string face = "f 1/1 2/1 3/1\n";
  EXPECT_EQ(objError(kObjVertices + "vt 0 nan\n" + face),
            "bad.obj: line 6: non-finite texture coordinate value 'nan'" + kContext);
  EXPECT_EQ(objError(kObjVertices + "vt -inf 0\nf 1 2 3\n"),
            "bad.obj: line 6: non-finite texture coordinate value '-inf'" + kContext);
  EXPECT_EQ(objError(kObjVertices + "vt 0 1e39\n" + face),
            "bad.obj: line 6: non-finite texture coordinate value '1e39' (too large for a 32-bit "
            "float)" +
                kContext);
  EXPECT_EQ(objError(kObjVertices + "vt 0 x\n" + face),
            "bad.obj: line 6: texture coordinate value 'x' is not a number" + kContext);
  EXPECT_EQ(objError(kObjVertices + "vt \n" + face),
            "bad.obj: line 6: texture coordinate has no values (need at least u)" + kContext);
  // A w is not read, so not checked.
  EXPECT_EQ(loadObj(kObjVertices + "vt 0 1 nan\n" + face).uvs.size(), 1u);
  // References to texture coordinates that do not exist.
  EXPECT_EQ(objError(kObjVertices + "vt 0 0\nf 1/1 2/2 3/1\n"),
            "bad.obj: line 7: texture coordinate index 2 out of range (file has 1 texture "
            "coordinates)" +
                kContext);
  EXPECT_EQ(objError(kObjVertices + "f 1/-1 2/1 3/1\nvt 0 0\n"),
            "bad.obj: line 6: texture coordinate index -1 out of range (0 texture coordinates "
            "defined before this line)" +
                kContext);
  EXPECT_EQ(
      objError(kObjVertices + "vt 0 0\nf 1/0 2/1 3/1\n"),
      "bad.obj: line 7: texture coordinate index 0 is invalid (OBJ indices start at 1)" + kContext);
  EXPECT_EQ(objError(kObjVertices + "vt 0 0\nf 1/1/ 2/1 3/1\n"),
            "bad.obj: line 7: malformed vertex reference '1/1/'" + kContext);
}

}  // namespace
}  // namespace pt
