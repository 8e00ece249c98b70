// pbrt-v4 files into a Scene (host/scene/pbrt/pbrt_scene.h): transforms against hand-computed
// matrices, orientation, meshes and their normals, materials and area lights, instancing,
// camera and options, warnings and errors, and configs/cornell-box.pbrt against the JSON box.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>

#include "common/check.h"
#include "cpu/integrator.h"
#include "image/image.h"
#include "render/camera.h"
#include "render/prepare.h"
#include "scene/camera_filter.h"
#include "scene/load_scene.h"
#include "scene/pbrt/pbrt_graphics_state.h"
#include "scene/pbrt/pbrt_scene.h"
#include "scene/pbrt/pbrt_shapes.h"
#include "scene/pbrt/spectra.h"
#include "scene/reader_helpers.h"
#include "scene/scene.h"
#include "test_util.h"
#include "texture.h"

namespace pt {
namespace {

namespace fs = std::filesystem;

// A camera before the world block that needs no mirroring (Scale -1 1 1, as Bitterli's files
// start), so that world coordinates come through unchanged.
constexpr char kUnmirrored[] =
    "Scale -1 1 1\nLookAt 0 0 -10  0 0 0  0 1 0\nCamera \"perspective\"\n"
    "PixelFilter \"box\"\nWorldBegin\n";

Scene load(const std::string& text, const fs::path& path = "scene.pbrt") {
  return loadPbrtSceneText(text, path);
}

std::string pbrtErrorOf(const std::string& text, const fs::path& path = "scene.pbrt") {
  try {
    load(text, path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

void expectNearPbrt(glm::dvec3 a, glm::dvec3 b, double tolerance, const std::string& what) {
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], tolerance) << what << " [" << c << "]";
}

void expectMatrixNear(const glm::dmat4& a, const glm::dmat4& b, double tolerance) {
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 4; ++r)
      EXPECT_NEAR(a[c][r], b[c][r], tolerance) << "[" << c << "][" << r << "]";
  }
}

// A triangle at the origin with its right angle there: (0,0,0), (1,0,0), (0,1,0).
constexpr char kTriangle[] =
    "Shape \"trianglemesh\" \"point3 P\" [ 0 0 0  1 0 0  0 1 0 ] \"integer indices\" [ 0 1 2 ]\n";

vec3 geometricNormal(const Triangle& t) {
  return glm::normalize(glm::cross(t.v1 - t.v0, t.v2 - t.v0));
}

// ---- transforms -----------------------------------------------------------------------------

TEST(PbrtTransforms, LookAtAgainstAHandComputedMatrix) {
  // Eye (1, 2, 3) looking at (1, 2, 4) with up +y: camera x is up x dir = +x, y is +y, z
  // is +z; camera from world is then a translation by -eye.
  expectMatrixNear(pbrt::lookAtMatrix({1, 2, 3}, {1, 2, 4}, {0, 1, 0}),
                   pbrt::translateMatrix({-1, -2, -3}), 1e-15);
  // Eye (0, 0, 0) looking down -x, up +z: dir = (-1,0,0), right = up x dir = (0,-1,0),
  // newUp = dir x right = (0,0,1). Camera from world has those as its rows.
  glm::dmat4 expected(0.0);
  expected[0] = {0, 0, -1, 0};  // column 0: the world x axis's camera coordinates
  expected[1] = {-1, 0, 0, 0};
  expected[2] = {0, 1, 0, 0};
  expected[3] = {0, 0, 0, 1};
  expectMatrixNear(pbrt::lookAtMatrix({0, 0, 0}, {-5, 0, 0}, {0, 0, 3}), expected, 1e-15);
  // With a translation: a world point 2 units in front of the eye is camera (0, 0, 2).
  const glm::dmat4 m = pbrt::lookAtMatrix({4, 5, 6}, {4, 5, 0}, {1, 0, 0});
  expectNearPbrt(glm::dvec3(m * glm::dvec4(4, 5, 4, 1)), {0, 0, 2}, 1e-14, "in front");
  expectNearPbrt(glm::dvec3(m * glm::dvec4(5, 5, 6, 1)), {0, 1, 0}, 1e-14, "up");
  // Right = up x dir = (1,0,0) x (0,0,-1) = (0, 1, 0).
  expectNearPbrt(glm::dvec3(m * glm::dvec4(4, 6, 6, 1)), {1, 0, 0}, 1e-14, "right");
}

TEST(PbrtTransforms, RotateAboutASkewAxis) {
  // 120 degrees about (1, 1, 1) cycles the axes: x -> y -> z -> x.
  const glm::dmat4 r = pbrt::rotateMatrix(120.0, {2, 2, 2});
  expectNearPbrt(glm::dvec3(r * glm::dvec4(1, 0, 0, 0)), {0, 1, 0}, 1e-15, "x");
  expectNearPbrt(glm::dvec3(r * glm::dvec4(0, 1, 0, 0)), {0, 0, 1}, 1e-15, "y");
  expectNearPbrt(glm::dvec3(r * glm::dvec4(0, 0, 1, 0)), {1, 0, 0}, 1e-15, "z");
  // 90 degrees about z, exactly: counter-clockwise, x -> y.
  const glm::dmat4 z = pbrt::rotateMatrix(90.0, {0, 0, 1});
  EXPECT_EQ(glm::dvec3(z * glm::dvec4(1, 0, 0, 0)), glm::dvec3(0, 1, 0));
  // 60 degrees about (0, 1, 1)/sqrt 2, by Rodrigues' formula written out.
  const glm::dvec3 a = glm::normalize(glm::dvec3(0, 1, 1));
  const double c = 0.5, s = std::sqrt(3.0) / 2;
  const glm::dvec3 v(1, 2, 0);
  const glm::dvec3 expected = v * c + glm::cross(a, v) * s + a * glm::dot(a, v) * (1 - c);
  expectNearPbrt(glm::dvec3(pbrt::rotateMatrix(60, {0, 3, 3}) * glm::dvec4(v, 0)), expected, 1e-14,
                 "rodrigues");
}

TEST(PbrtTransforms, FileMatricesAreColumnByColumn) {
  const double n[16] = {1, 2, 3, 0, 4, 5, 6, 0, 7, 8, 9, 0, 10, 11, 12, 1};
  const glm::dmat4 m = pbrt::fileMatrix(n);
  // The translation is numbers 13 to 15; the first column is numbers 1 to 3.
  EXPECT_EQ(glm::dvec3(m * glm::dvec4(0, 0, 0, 1)), glm::dvec3(10, 11, 12));
  EXPECT_EQ(glm::dvec3(m * glm::dvec4(1, 0, 0, 0)), glm::dvec3(1, 2, 3));
}

// The vertices of the file's one triangle, as loaded.
std::vector<glm::dvec3> vertices(const std::string& transforms,
                                 const std::string& shape = kTriangle) {
  const Scene scene = load(std::string(kUnmirrored) + transforms + shape);
  EXPECT_EQ(scene.triangles.size(), 1u);
  if (scene.triangles.empty()) return {};
  const Triangle& t = scene.triangles[0];
  return {glm::dvec3(t.v0), glm::dvec3(t.v1), glm::dvec3(t.v2)};
}

TEST(PbrtTransforms, TheCtmActsOnPointsLastDirectiveFirst) {
  // Translate then Scale: p -> T(S(p)).
  auto v = vertices("Translate 10 0 0\nScale 2 3 4\n");
  expectNearPbrt(v[1], {12, 0, 0}, 0, "v1");
  expectNearPbrt(v[2], {10, 3, 0}, 0, "v2");
  // Rotate 90 about z then Translate: p -> R(T(p)).
  v = vertices("Rotate 90 0 0 1\nTranslate 1 0 0\n");
  expectNearPbrt(v[0], {0, 1, 0}, 0, "v0");
  expectNearPbrt(v[1], {0, 2, 0}, 0, "v1");
  expectNearPbrt(v[2], {-1, 1, 0}, 0, "v2");
  // ConcatTransform's numbers are column by column: a translation by (5, 6, 7).
  v = vertices("Translate 1 0 0\nConcatTransform [ 1 0 0 0  0 1 0 0  0 0 1 0  5 6 7 1 ]\n");
  expectNearPbrt(v[0], {6, 6, 7}, 0, "concat");
  // Transform replaces the CTM; Identity resets it.
  v = vertices("Translate 100 0 0\nTransform [ 2 0 0 0  0 2 0 0  0 0 2 0  0 0 1 1 ]\n");
  expectNearPbrt(v[1], {2, 0, 1}, 0, "transform");
  v = vertices("Translate 100 0 0\nIdentity\n");
  expectNearPbrt(v[1], {1, 0, 0}, 0, "identity");
  // LookAt in the world block is a transform like any other (camera from world).
  v = vertices("LookAt 0 0 0  0 0 1  0 1 0\nTranslate 0 0 5\n");
  expectNearPbrt(v[0], {0, 0, 5}, 1e-12, "lookat");
}

TEST(PbrtTransforms, AttributeAndTransformBlocksRestoreTheCtm) {
  const Scene scene = load(
      std::string(kUnmirrored) + "Translate 1 0 0\nAttributeBegin\nTranslate 10 0 0\n" + kTriangle +
      "AttributeEnd\nTransformBegin\nTranslate 20 0 0\nTransformEnd\n" + kTriangle);
  ASSERT_EQ(scene.triangles.size(), 2u);
  EXPECT_EQ(scene.triangles[0].v0, vec3(11, 0, 0));
  EXPECT_EQ(scene.triangles[1].v0, vec3(1, 0, 0));
}

TEST(PbrtTransforms, CoordinateSystemsAndTheCamera) {
  // CoordSysTransform "camera": the world from camera transform of the Camera directive.
  // Eye (1, 2, 3) looking down +x with up +z: camera z is world +x, camera y world +z,
  // camera x = up x dir = (0, 1, 0) (this camera is mirrored at WorldBegin; undone below).
  const Scene scene = load(
      "LookAt 1 2 3  5 2 3  0 0 1\nCamera \"perspective\"\nPixelFilter \"box\"\nWorldBegin\n"
      "CoordinateSystem \"start\"\nTranslate 50 0 0\nAttributeBegin\nCoordSysTransform "
      "\"camera\"\n"
      "Shape \"trianglemesh\" \"point3 P\" [ 0 0 4  1 0 4  0 1 4 ]\nAttributeEnd\n"
      "CoordSysTransform \"start\"\n" +
      std::string(kTriangle));
  ASSERT_EQ(scene.triangles.size(), 2u);
  // The world is mirrored in x (pbrt's camera space is left-handed): undo it to compare.
  auto world = [](vec3 p) { return glm::dvec3(-p.x, p.y, p.z); };
  const Triangle& t = scene.triangles[0];
  // The winding is swapped by the mirroring, so v1 and v2 trade places.
  expectNearPbrt(world(t.v0), {5, 2, 3}, 1e-5, "camera (0,0,4)");
  expectNearPbrt(world(t.v2), {5, 3, 3}, 1e-5, "camera (1,0,4)");
  expectNearPbrt(world(t.v1), {5, 2, 4}, 1e-5, "camera (0,1,4)");
  // "start" was the identity: the second triangle is back at the origin.
  EXPECT_EQ(world(scene.triangles[1].v0), glm::dvec3(0, 0, 0));
  // The camera: at the eye, looking along +x (mirrored: -x), up +z.
  EXPECT_EQ(scene.camera.position, vec3(-1, 2, 3));
  const Camera camera = makeCamera(scene.camera, 16, 16);
  expectNearPbrt(camera.forward, {-1, 0, 0}, 1e-6, "forward");
  expectNearPbrt(camera.up, {0, 0, 1}, 1e-6, "up");
}

TEST(PbrtTransforms, ReverseOrientationAndHandednessFlipTheFront) {
  // The front of a mesh without normals is its winding's side; ReverseOrientation makes it
  // the other side (here: another winding), and so does a mirroring transform, which pbrt-v4
  // compensates (transformSwapsHandedness): both together cancel.
  const std::string light = "AreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\n";
  auto normalOf = [&](const std::string& state) {
    const Scene scene = load(std::string(kUnmirrored) + light + state + kTriangle);
    return geometricNormal(scene.triangles.at(0));
  };
  EXPECT_EQ(normalOf(""), vec3(0, 0, 1));
  EXPECT_EQ(normalOf("ReverseOrientation\n"), vec3(0, 0, -1));
  // Scale -1 1 1 mirrors the triangle; its front stays the mirrored +z, i.e. +z.
  EXPECT_EQ(normalOf("Scale -1 1 1\n"), vec3(0, 0, 1));
  EXPECT_EQ(normalOf("Scale 1 1 -1\n"), vec3(0, 0, -1));  // the mirror image of +z
  EXPECT_EQ(normalOf("Scale -1 1 1\nReverseOrientation\n"), vec3(0, 0, -1));
  // ReverseOrientation is graphics state: restored by AttributeEnd.
  EXPECT_EQ(normalOf("AttributeBegin\nReverseOrientation\nAttributeEnd\n"), vec3(0, 0, 1));
}

// ---- shapes ---------------------------------------------------------------------------------

TEST(PbrtShapes, TriangleMeshWithNormalsFillsSceneNormals) {
  // A quad without normals first, then a mesh whose normals point to -z although its
  // winding faces +z: pbrt-v4 takes the normals' side as the front, and so does the winding.
  const Scene scene = load(std::string(kUnmirrored) + kTriangle +
                           "Translate 0 0 1\nShape \"trianglemesh\" \"point3 P\" [ 0 0 0  1 0 0  "
                           "0 1 0 ] \"normal N\" [ 0 0 -2  0 0 -1  0.6 0 -0.8 ]\n");
  ASSERT_EQ(scene.triangles.size(), 2u);
  ASSERT_EQ(scene.normals.size(), 2u);
  EXPECT_EQ(scene.normals[0].n0, vec3(0, 0, 1));  // flat: the mesh before had none
  EXPECT_EQ(geometricNormal(scene.triangles[1]), vec3(0, 0, -1));
  // Rewound: v1 and v2 swapped, with their normals.
  EXPECT_EQ(scene.triangles[1].v1, vec3(0, 1, 1));
  EXPECT_EQ(scene.normals[1].n0, vec3(0, 0, -1));
  EXPECT_EQ(scene.normals[1].n1, vec3(0.6f, 0, -0.8f));
  EXPECT_EQ(scene.normals[1].n2, vec3(0, 0, -1));
}

TEST(PbrtShapes, NormalsTransformWithTheInverseTranspose) {
  const Scene scene =
      load(std::string(kUnmirrored) + "Scale 2 1 1\nReverseOrientation\n" +
           "Shape \"trianglemesh\" \"point3 P\" [ 0 0 0  1 0 0  0 1 0 ] \"normal N\" [ 1 0 1  1 0 "
           "1  1 0 1 ]\n");
  ASSERT_EQ(scene.normals.size(), 1u);
  // (1, 0, 1) under diag(2, 1, 1)^-T is (0.5, 0, 1), reversed: -(0.5, 0, 1) / |.|.
  const glm::dvec3 n = -glm::normalize(glm::dvec3(0.5, 0, 1));
  expectNearPbrt(scene.normals[0].n0, n, 1e-7, "n0");
  EXPECT_LT(glm::dot(glm::dvec3(geometricNormal(scene.triangles[0])), n), 0.0 + 1.0);
  EXPECT_EQ(geometricNormal(scene.triangles[0]), vec3(0, 0, -1));
}

TEST(PbrtShapes, TrianglesWithoutIndicesAndZeroArea) {
  const Scene scene = load(std::string(kUnmirrored) +
                           "Shape \"trianglemesh\" \"point3 P\" [ 0 0 0  1 0 0  0 1 0 ]\n"
                           "Shape \"trianglemesh\" \"point3 P\" [ 0 0 0  1 0 0  2 0 0  0 1 0 ]\n"
                           "  \"integer indices\" [ 0 1 2  0 1 3 ]\n");
  ASSERT_EQ(scene.triangles.size(), 2u);
  ASSERT_EQ(scene.warnings.size(), 1u);
  EXPECT_EQ(scene.warnings[0],
            "scene.pbrt:7: Shape \"trianglemesh\": dropped 1 zero-area triangle in 1 shape");
  EXPECT_EQ(scene.triangles[1].primitive, 1u);
  // Drops in several shapes make one warning, at the first.
  const Scene more = load(std::string(kUnmirrored) +
                          "Shape \"trianglemesh\" \"point3 P\" [ 0 0 0  1 0 0  2 0 0  0 1 0 ]\n"
                          "  \"integer indices\" [ 0 1 2  0 1 3 ]\n"
                          "Shape \"trianglemesh\" \"point3 P\" [ 0 0 0  1 0 0  2 0 0  0 1 0 ]\n"
                          "  \"integer indices\" [ 0 1 2  0 2 1  0 1 3 ]\n");
  ASSERT_EQ(more.warnings.size(), 1u);
  EXPECT_EQ(more.warnings[0],
            "scene.pbrt:6: Shape \"trianglemesh\": dropped 3 zero-area triangles in 2 shapes "
            "(this is the first)");
}

TEST(PbrtShapes, PlyMeshRelativeToTheFileThatNamesIt) {
  test::TempDir dir;
  dir.write("meshes/quad.ply",
            "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
            "property float z\nproperty float nx\nproperty float ny\nproperty float nz\n"
            "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
            "0 0 0 0 0 1\n1 0 0 0 0 1\n1 1 0 0 0 1\n0 1 0 0 0 1\n4 0 1 2 3\n");
  dir.write("meshes/part.pbrt", "Shape \"plymesh\" \"string filename\" \"quad.ply\"\n");
  const fs::path main =
      dir.write("scene.pbrt", std::string(kUnmirrored) +
                                  "Translate 0 0 5\nInclude \"meshes/part.pbrt\"\n"
                                  "Shape \"plymesh\" \"string filename\" \"meshes/quad.ply\"\n");
  const Scene scene = loadScene(main);    // through the dispatch by extension
  ASSERT_EQ(scene.triangles.size(), 4u);  // the quad fanned, twice
  ASSERT_EQ(scene.normals.size(), 4u);
  EXPECT_EQ(scene.triangles[0].v0, vec3(0, 0, 5));
  EXPECT_EQ(scene.triangles[1].v2, vec3(0, 1, 5));
  EXPECT_EQ(scene.normals[3].n2, vec3(0, 0, 1));
  EXPECT_EQ(
      pbrtErrorOf(std::string(kUnmirrored) + "Shape \"plymesh\" \"string filename\" \"no.ply\"",
                  dir / "x.pbrt"),
      (dir / "x.pbrt").string() + ":6:17: cannot open 'no.ply' (looked for '" +
          (dir / "no.ply").string() + "': No such file or directory)");
}

TEST(PbrtShapes, SpheresAndDisksAreTessellated) {
  const Scene scene = load(std::string(kUnmirrored) +
                           "Translate 0 5 0\nShape \"sphere\" \"float radius\" 2\n"
                           "Shape \"disk\" \"float radius\" 3 \"float height\" 1\n"
                           "Shape \"disk\" \"float radius\" 3 \"float innerradius\" 1\n"
                           "Shape \"sphere\" \"float zmax\" 0.5\n");
  const std::size_t sphere = 2 * pbrt::kSphereSegments * (pbrt::kSphereRings - 1);
  ASSERT_EQ(scene.triangles.size(), sphere + pbrt::kDiskSegments + 2 * pbrt::kDiskSegments);
  ASSERT_EQ(scene.normals.size(), scene.triangles.size());
  for (std::size_t i = 0; i < sphere; ++i) {
    const Triangle& t = scene.triangles[i];
    for (vec3 v : {t.v0, t.v1, t.v2}) EXPECT_NEAR(glm::length(v - vec3(0, 5, 0)), 2.0f, 1e-5f);
    // Wound outwards, with outward unit normals.
    const vec3 centroid = (t.v0 + t.v1 + t.v2) / 3.0f - vec3(0, 5, 0);
    EXPECT_GT(glm::dot(geometricNormal(t), centroid), 0.0f) << i;
    EXPECT_NEAR(glm::length(scene.normals[i].n0), 1.0f, 1e-6f);
    EXPECT_GT(glm::dot(scene.normals[i].n0, t.v0 - vec3(0, 5, 0)), 0.0f);
  }
  for (std::size_t i = sphere; i < scene.triangles.size(); ++i) {
    expectNearPbrt(geometricNormal(scene.triangles[i]), {0, 0, 1}, 1e-6, "disk");  // faces +z
  }
  EXPECT_EQ(scene.triangles[sphere].v0, vec3(0, 5, 1));  // the first disk's centre
  std::string joined;
  for (const std::string& w : scene.warnings) joined += w + "\n";
  EXPECT_EQ(joined,
            "scene.pbrt:7: spheres are tessellated into 16128 triangles with vertex normals "
            "(chord error 3e-4 of the radius) until they are exact primitives\n"
            "scene.pbrt:8: disks are tessellated into 128 segments (chord error 3e-4 of the "
            "radius) until they are exact primitives\n"
            "scene.pbrt:10: partial spheres (zmin, zmax, phimax) are not supported: skipped\n");
}

TEST(PbrtShapes, UnsupportedShapesAreSkippedWithOneWarning) {
  const Scene scene = load(std::string(kUnmirrored) + kTriangle +
                           "Shape \"curve\" \"point3 P\" [0 0 0 1 1 1 2 2 2 3 3 3]\n"
                           "Shape \"curve\" \"point3 P\" [0 0 0 1 1 1 2 2 2 3 3 3]\n"
                           "Shape \"loopsubdiv\" \"integer levels\" 3\n"
                           "Shape \"bilinearmesh\"\nShape \"cylinder\"\n");
  EXPECT_EQ(scene.triangles.size(), 1u);
  ASSERT_EQ(scene.warnings.size(), 4u);
  EXPECT_EQ(scene.warnings[0],
            "scene.pbrt:7: Shape \"curve\" skipped: curves (hair) are not supported yet");
  EXPECT_EQ(scene.warnings[1],
            "scene.pbrt:9: Shape \"loopsubdiv\" skipped: subdivision "
            "surfaces are not supported yet");
}

// ---- materials ------------------------------------------------------------------------------

// The material of the file's first triangle.
Material materialOf(const std::string& material, std::vector<std::string>* warnings = nullptr) {
  const Scene scene = load(std::string(kUnmirrored) + material + "\n" + kTriangle);
  if (warnings != nullptr) *warnings = scene.warnings;
  return scene.materials.at(scene.triangles.at(0).material);
}

TEST(PbrtMaterials, EachTypeWithPbrtV4sParameterNames) {
  Material m = materialOf("");  // pbrt-v4's default: diffuse of 0.5
  EXPECT_EQ(m.type, kMaterialDiffuse);
  EXPECT_EQ(m.reflectance, vec3(0.5f));
  m = materialOf("Material \"diffuse\" \"rgb reflectance\" [0.1 0.2 0.3]");
  EXPECT_EQ(m.reflectance, vec3(0.1f, 0.2f, 0.3f));

  m = materialOf("Material \"conductor\"");  // pbrt-v4's default: metal-Cu
  EXPECT_EQ(m.type, kMaterialConductor);
  EXPECT_EQ(m.eta, spectra::namedMetal("Cu")->eta);
  EXPECT_EQ(m.k, spectra::namedMetal("Cu")->k);
  m = materialOf(
      "Material \"conductor\" \"rgb eta\" [0.2 0.3 0.4] \"rgb k\" [3 2 1] \"float roughness\" "
      "0.25 \"float vroughness\" 0.04");
  EXPECT_EQ(m.eta, vec3(0.2f, 0.3f, 0.4f));
  EXPECT_EQ(m.k, vec3(3, 2, 1));
  EXPECT_EQ(m.alphaX, 0.5f);  // sqrt(0.25): remapped by default
  EXPECT_EQ(m.alphaY, 0.2f);
  m = materialOf("Material \"conductor\" \"float roughness\" 0.3 \"bool remaproughness\" false");
  EXPECT_EQ(m.alphaX, 0.3f);
  m = materialOf("Material \"conductor\" \"rgb reflectance\" [0.5 0.5 0.5]");
  Material expected = defaultMaterial(kMaterialConductor);
  setConductorReflectance(expected, vec3(0.5f));
  EXPECT_EQ(m.eta, expected.eta);
  EXPECT_EQ(m.k, expected.k);
  std::vector<std::string> warnings;
  m = materialOf(
      "Material \"conductor\" \"spectrum eta\" \"metal-Au-eta\" \"spectrum k\" \"metal-Au-k\"",
      &warnings);
  EXPECT_EQ(m.eta, spectra::namedMetal("Au")->eta);  // pbrt-v4's spectra fitted per channel
  EXPECT_EQ(m.k, spectra::namedMetal("Au")->k);
  EXPECT_TRUE(warnings.empty());

  m = materialOf("Material \"dielectric\" \"float eta\" 1.33 \"float roughness\" 0.01");
  EXPECT_EQ(m.type, kMaterialDielectric);
  EXPECT_EQ(m.eta.x, 1.33f);
  EXPECT_EQ(m.alphaX, 0.1f);
  m = materialOf("Material \"dielectric\" \"spectrum eta\" \"glass-BK7\"", &warnings);
  EXPECT_NEAR(m.eta.x, 1.5198f, 1e-4f);  // the mean of BK7's dispersion curve's RGB
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0],
            "scene.pbrt:6: named glass spectra (here 'glass-BK7') are taken as one index, the "
            "mean of their dispersion curve's RGB (1.51978; dispersion is not simulated)");
  m = materialOf("Material \"thindielectric\" \"float eta\" 1.7");
  EXPECT_EQ(m.type, kMaterialThinDielectric);
  EXPECT_EQ(m.eta.x, 1.7f);

  m = materialOf(
      "Material \"diffusetransmission\" \"rgb reflectance\" [0.5 0.5 0.5] \"rgb transmittance\" "
      "[0.2 0.4 0.8] \"float scale\" 1.5");
  EXPECT_EQ(m.type, kMaterialDiffuseTransmission);
  EXPECT_EQ(m.reflectance, vec3(0.75f));
  EXPECT_EQ(m.transmittance, vec3(0.3f, 0.6f, 1.0f));  // clamped to 1

  m = materialOf(
      "Material \"coateddiffuse\" \"rgb reflectance\" [0.1 0.2 0.3] \"float roughness\" 0.04 "
      "\"float thickness\" 0.2 \"float eta\" 1.4 \"rgb albedo\" [0.5 0.5 0.5] \"float g\" 0.3 "
      "\"integer maxdepth\" 20 \"integer nsamples\" 4");
  EXPECT_EQ(m.type, kMaterialCoatedDiffuse);
  EXPECT_EQ(m.reflectance, vec3(0.1f, 0.2f, 0.3f));
  EXPECT_EQ(m.alphaX, 0.2f);
  EXPECT_EQ(m.thickness, 0.2f);
  EXPECT_EQ(m.eta.x, 1.4f);
  EXPECT_EQ(m.transmittance, vec3(0.5f));
  EXPECT_EQ(m.g, 0.3f);
  EXPECT_EQ(m.maxDepth, 20u);
  EXPECT_EQ(m.nSamples, 4u);
  m = materialOf("Material \"coateddiffuse\"");
  EXPECT_EQ(m.reflectance, vec3(0.5f));
  EXPECT_EQ(m.thickness, 0.01f);
}

TEST(PbrtMaterials, NamedMaterialsTexturesAttributesAndMix) {
  const test::TempDir dir;
  Image image(2, 1);  // mean (0.3, 0.5, 0.7)
  image.pixels = {vec3(0.2f, 0.4f, 0.6f), vec3(0.4f, 0.6f, 0.8f)};
  writeImage(image, dir / "a.pfm");
  const Scene scene = load(
      std::string(kUnmirrored) +
          "Texture \"grey\" \"spectrum\" \"constant\" \"rgb value\" [0.3 0.3 0.3]\n"
          "Texture \"rough\" \"float\" \"constant\" \"float value\" 0.09\n"
          "Texture \"img\" \"spectrum\" \"imagemap\" \"string filename\" \"a.pfm\"\n"
          "NamedMaterial \"late\"\n" +
          kTriangle +  // defined below: resolved at the end
          "MakeNamedMaterial \"late\" \"string type\" \"diffuse\" \"texture reflectance\" "
          "\"grey\"\n"
          "MakeNamedMaterial \"metal\" \"string type\" \"conductor\" \"texture roughness\" "
          "\"rough\"\n"
          "MakeNamedMaterial \"pic\" \"string type\" \"diffuse\" \"texture reflectance\" \"img\"\n"
          "MakeNamedMaterial \"both\" \"string type\" \"mix\" \"string materials\" [\"late\" "
          "\"metal\"] \"float amount\" 0.8\n"
          "AttributeBegin\nAttribute \"material\" \"rgb reflectance\" [0.7 0.7 0.7]\n"
          "Material \"diffuse\"\n" +
          kTriangle +
          "AttributeEnd\n"
          "NamedMaterial \"metal\"\n" +
          kTriangle + "NamedMaterial \"pic\"\n" + kTriangle + "NamedMaterial \"both\"\n" +
          kTriangle + "NamedMaterial \"late\"\n" + kTriangle,
      dir / "scene.pbrt");
  ASSERT_EQ(scene.triangles.size(), 6u);
  ASSERT_EQ(scene.materialTextures.size(), scene.materials.size());
  // Each triangle's material with its textures evaluated at (u, v) = (0.25, 0.5).
  const TextureTables tables{scene.textureNodes.data(), scene.imageWords.data(), nullptr, nullptr};
  auto material = [&](int i) {
    const uint m = scene.triangles[i].material;
    return resolveMaterial(tables, scene.materials[m], scene.materialTextures[m],
                           vec2(0.25f, 0.5f));
  };
  EXPECT_NEAR(material(0).reflectance.x, 0.3f, 1e-7f);  // a constant texture
  EXPECT_EQ(material(1).reflectance, vec3(0.7f));       // from the Attribute
  EXPECT_EQ(material(2).type, kMaterialConductor);
  EXPECT_NEAR(material(2).alphaX, 0.3f, 1e-7f);  // roughness 0.09 from a texture, remapped
  // An image texture: the left texel at u = 0.25.
  EXPECT_NEAR(material(3).reflectance.x, 0.2f, 1e-6f);
  EXPECT_NEAR(material(3).reflectance.y, 0.4f, 1e-6f);
  EXPECT_NEAR(material(3).reflectance.z, 0.6f, 1e-6f);
  EXPECT_EQ(material(4).type, kMaterialConductor);  // amount 0.8: the second, mostly
  EXPECT_EQ(scene.triangles[5].material, scene.triangles[0].material);  // one slot per name
  EXPECT_EQ(scene.materials.size(), 5u);  // "both" shares metal's definition but not its slot
  EXPECT_EQ(scene.materialNames[scene.triangles[0].material], "late");
  std::string joined;
  for (const std::string& w : scene.warnings) joined += w + "\n";
  EXPECT_EQ(joined.find("not simulated"), std::string::npos) << joined;
  EXPECT_NE(joined.find("Material \"mix\" is rendered as the one of its two materials"),
            std::string::npos);
}

TEST(PbrtMaterials, InterfaceShapesAreLeftOut) {
  const Scene scene = load(std::string(kUnmirrored) + kTriangle + "Material \"interface\"\n" +
                           kTriangle + "NamedMaterial \"later\"\n" + kTriangle +
                           "MakeNamedMaterial \"later\" \"string type\" \"interface\"\n");
  ASSERT_EQ(scene.triangles.size(), 1u);
  EXPECT_EQ(scene.materials.size(), 1u);
  EXPECT_EQ(scene.triangles[0].primitive, 0u);
}

// ---- lights ---------------------------------------------------------------------------------

TEST(PbrtLights, AreaLightEmissionIsLTimesScalePerShape) {
  const Scene scene = load(std::string(kUnmirrored) +
                           "AttributeBegin\n"
                           "AreaLightSource \"diffuse\" \"rgb L\" [4 2 1] \"float scale\" 2.5\n"
                           "Material \"diffuse\" \"rgb reflectance\" [0 0 0]\n" +
                           kTriangle + kTriangle + "AttributeEnd\n" + kTriangle +
                           "AttributeBegin\nAreaLightSource \"diffuse\" \"float power\" 10\n" +
                           kTriangle + "AttributeEnd\n" +
                           "AttributeBegin\nAreaLightSource \"diffuse\" \"blackbody L\" 3000 "
                           "\"bool twosided\" true\n" +
                           kTriangle + "AttributeEnd\n");
  ASSERT_EQ(scene.triangles.size(), 5u);
  auto material = [&](int i) { return scene.materials[scene.triangles[i].material]; };
  EXPECT_EQ(material(0).emission, vec3(10, 5, 2.5f));
  EXPECT_EQ(material(0).reflectance, vec3(0));
  EXPECT_NE(scene.triangles[0].material, scene.triangles[1].material);  // a copy per shape
  EXPECT_EQ(material(1).emission, vec3(10, 5, 2.5f));
  EXPECT_EQ(material(2).emission, vec3(0));  // after AttributeEnd: no light
  // "power" 10 over a triangle of area 1/2, one-sided: L = 10 / (0.5 pi).
  EXPECT_FLOAT_EQ(material(3).emission.x, float(10.0 / (0.5 * 3.14159265358979323846)));
  // A blackbody: luminance 1 of its colour (tests/spectra_test.cpp); two-sided.
  EXPECT_EQ(material(4).emission, vec3(spectra::blackbodyRgb(3000)));
  EXPECT_EQ(material(4).twoSided, 1u);
  EXPECT_EQ(material(3).twoSided, 0u);
}

TEST(PbrtLights, OtherLightsMediaAndTexturesWarnOncePerKind) {
  const Scene scene = load(std::string(kUnmirrored) +
                           "LightSource \"point\" \"rgb I\" [1 1 1]\n"
                           "LightSource \"point\" \"rgb I\" [1 1 1]\n"
                           "LightSource \"infinite\" \"rgb L\" [1 1 1]\n"
                           "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\"\n"
                           "MediumInterface \"fog\" \"\"\nMediumInterface \"\"\n"
                           "LightSource \"goniometric\" \"string filename\" \"g.exr\"\n"
                           "LightSource \"goniometric\"\n" +
                           kTriangle);
  // Point and infinite lights are simulated (tests/lights_test.cpp); goniometric and
  // projection lights are not, warned once per kind. Homogeneous media are read
  // (tests/media_reader_test.cpp): no warning, and none in the scene, as no shape uses it.
  ASSERT_EQ(scene.lights.size(), 3u);
  EXPECT_TRUE(scene.media.empty());
  ASSERT_EQ(scene.warnings.size(), 1u);
  EXPECT_EQ(scene.warnings[0],
            "scene.pbrt:12: LightSource 'goniometric' ignored: goniometric lights (an image over "
            "the directions) are not simulated");
}

// ---- instancing -----------------------------------------------------------------------------

TEST(PbrtInstances, FlattenedWithTheDefinitionAndUseTransforms) {
  const Scene scene =
      load(std::string(kUnmirrored) +
           "ObjectInstance \"early\"\n"  // before its definition, as pbrt allows
           "AttributeBegin\nTranslate 0 0 1\nObjectBegin \"early\"\n" +
           kTriangle + "Translate 0 0 1\n" + kTriangle + "ObjectEnd\nAttributeEnd\n" +
           "Translate 10 0 0\nObjectInstance \"early\"\nScale -1 1 1\n"
           "ObjectInstance \"early\"\n");
  // The shapes of an object are not drawn where they are defined; three uses of two.
  ASSERT_EQ(scene.triangles.size(), 6u);
  EXPECT_EQ(scene.triangles[0].v0, vec3(0, 0, 1));  // the definition's CTM alone
  EXPECT_EQ(scene.triangles[1].v0, vec3(0, 0, 2));
  EXPECT_EQ(scene.triangles[2].v0, vec3(10, 0, 1));
  // Scale -1 1 1 after the translation: (1, 0, 0) goes to (9, 0, 1); the mirroring instance
  // keeps the front (+z) by rewinding, so that vertex is now v2.
  EXPECT_EQ(scene.triangles[4].v2, vec3(9, 0, 1));
  EXPECT_EQ(geometricNormal(scene.triangles[4]), vec3(0, 0, 1));
  EXPECT_EQ(scene.triangles[5].primitive, 5u);
}

// ---- camera and options ---------------------------------------------------------------------

TEST(PbrtCamera, FovSpansTheShorterAxis) {
  auto vfov = [](const std::string& film) {
    return load("Camera \"perspective\" \"float fov\" 40\n" + film +
                "PixelFilter \"box\"\nWorldBegin\n" + kTriangle)
        .camera.vfovDegrees;
  };
  EXPECT_EQ(vfov("Film \"rgb\" \"integer xresolution\" 200 \"integer yresolution\" 100\n"), 40.0f);
  EXPECT_EQ(vfov("Film \"rgb\" \"integer xresolution\" 100 \"integer yresolution\" 100\n"), 40.0f);
  // Portrait: the fov is horizontal; the vertical one is wider.
  const double expected = 2.0 * std::atan(std::tan(20.0 * 3.14159265358979323846 / 180.0) * 2.0) *
                          180.0 / 3.14159265358979323846;
  EXPECT_FLOAT_EQ(vfov("Film \"rgb\" \"integer xresolution\" 100 \"integer yresolution\" 200\n"),
                  float(expected));
}

TEST(PbrtCamera, DefaultsAndOptionsAsPbrtV4) {
  Scene scene = load(std::string("WorldBegin\n") + kTriangle);
  EXPECT_EQ(scene.camera.width, 1280);
  EXPECT_EQ(scene.camera.height, 720);
  EXPECT_EQ(scene.camera.vfovDegrees, 90.0f);
  EXPECT_EQ(scene.integrator.maxDepth, 5);
  EXPECT_EQ(scene.integrator.spp, 16);
  // The default camera at the origin looking down +z is left-handed: the world is mirrored.
  EXPECT_EQ(scene.triangles[0].v0, vec3(0, 0, 0));
  EXPECT_EQ(scene.triangles[0].v2, vec3(-1, 0, 0));
  // No PixelFilter: pbrt-v4's default, a gaussian of radius 1.5 and sigma 0.5.
  EXPECT_TRUE(scene.warnings.empty()) << scene.warnings.at(0);
  EXPECT_EQ(scene.camera.filter.type, kFilterGaussian);
  EXPECT_EQ(scene.camera.filter.radiusX, 1.5f);
  EXPECT_EQ(scene.camera.filter.radiusY, 1.5f);
  EXPECT_EQ(scene.camera.filter.sigma, 0.5f);
  scene = load(
      "Film \"rgb\" \"integer xresolution\" 32 \"integer yresolution\" 24 \"float iso\" 100\n"
      "Sampler \"halton\" \"integer pixelsamples\" 64 \"integer seed\" 7\n"
      "Integrator \"lightpath\" \"integer maxdepth\" 12\nPixelFilter \"gaussian\"\n"
      "Camera \"perspective\" \"float lensradius\" 0.1 \"float focaldistance\" 5\n"
      "WorldBegin\n" +
      std::string(kTriangle));
  EXPECT_EQ(scene.camera.width, 32);
  EXPECT_EQ(scene.camera.height, 24);
  EXPECT_EQ(scene.integrator.spp, 64);
  EXPECT_EQ(scene.integrator.seed, 7u);
  EXPECT_EQ(scene.integrator.maxDepth, 12);
  EXPECT_EQ(scene.camera.filter.type, kFilterGaussian);
  EXPECT_EQ(scene.camera.lensRadius, 0.1f);
  EXPECT_EQ(scene.camera.focalDistance, 5.0f);
  std::string joined;
  for (const std::string& w : scene.warnings) joined += w + "\n";
  EXPECT_EQ(
      joined,
      "scene.pbrt:3: Integrator 'lightpath' is rendered with the path tracer (\"path\": light "
      "and BSDF sampling with MIS)\n");
  EXPECT_EQ(scene.integrator.integrator, kIntegratorPath);
  scene = load(std::string(kUnmirrored) + kTriangle + "Shape \"sphere\" \"float radiuss\" 1\n");
  EXPECT_EQ(scene.warnings.at(1),
            "scene.pbrt:7: Shape \"sphere\": parameter 'float radiuss' "
            "ignored (not used by this renderer)");
}

TEST(PbrtCamera, CornellBoxPbrtIsTheJsonScene) {
  const Scene json = loadScene(test::kConfigs / "cornell-box.json");
  const Scene pbrt = loadScene(test::kConfigs / "cornell-box.pbrt");
  EXPECT_TRUE(pbrt.warnings.empty()) << pbrt.warnings.at(0);
  ASSERT_EQ(pbrt.triangles.size(), json.triangles.size());
  for (std::size_t i = 0; i < json.triangles.size(); ++i) {
    const Triangle& a = pbrt.triangles[i];
    const Triangle& b = json.triangles[i];
    EXPECT_EQ(a.v0, b.v0) << i;
    EXPECT_EQ(a.v1, b.v1) << i;
    EXPECT_EQ(a.v2, b.v2) << i;
    EXPECT_EQ(a.primitive, b.primitive);
    const Material& ma = pbrt.materials[a.material];
    const Material& mb = json.materials[b.material];
    EXPECT_EQ(0, std::memcmp(&ma, &mb, sizeof(Material))) << i;
  }
  EXPECT_EQ(pbrt.normals.size(), json.normals.size());
  const Camera ca = makeCamera(pbrt.camera, 256, 256);
  const Camera cb = makeCamera(json.camera, 256, 256);
  EXPECT_EQ(0, std::memcmp(&ca, &cb, sizeof(Camera)));
  EXPECT_EQ(pbrt.camera.width, json.camera.width);
  EXPECT_EQ(pbrt.camera.height, json.camera.height);
  EXPECT_EQ(pbrt.integrator.spp, json.integrator.spp);
  EXPECT_EQ(pbrt.integrator.maxDepth, json.integrator.maxDepth);
  EXPECT_EQ(pbrt.integrator.seed, json.integrator.seed);

  // And so the same image, bit for bit, on the CPU at a small size.
  RenderSettings settings;
  settings.width = 32;
  settings.height = 32;
  const SceneData da = prepareScene(pbrt, settings);
  const SceneData db = prepareScene(json, settings);
  Film fa(32, 32), fb(32, 32);
  renderCpu(da, test::cpuOptions(2, 4), fa);
  renderCpu(db, test::cpuOptions(2, 4), fb);
  const Image ia = fa.resolve(), ib = fb.resolve();
  ASSERT_EQ(ia.pixels.size(), ib.pixels.size());
  for (std::size_t i = 0; i < ia.pixels.size(); ++i) EXPECT_EQ(ia.pixels[i], ib.pixels[i]) << i;
}

// ---- errors ---------------------------------------------------------------------------------

TEST(PbrtSceneErrors, NameFileLineAndColumn) {
  const std::string w = kUnmirrored;  // 5 lines: the world starts on line 6
  const std::vector<std::pair<std::string, std::string>> cases = {
      {kTriangle, "scene.pbrt:1:1: Shape is allowed only after WorldBegin (in the world block)"},
      {w + "Camera \"perspective\"",
       "scene.pbrt:6:1: Camera is allowed only before WorldBegin (first at scene.pbrt:5)"},
      {w + "WorldBegin", "scene.pbrt:6:1: WorldBegin appears twice (first at scene.pbrt:5)"},
      {"Camera \"perspective\"\n",
       "scene.pbrt:2:1: the file ends before WorldBegin (a scene needs a world block)"},
      {w + "AttributeBegin\n" + kTriangle,
       "scene.pbrt:6:1: AttributeBegin without a matching AttributeEnd"},
      {w + "ObjectBegin \"a\"\nAttributeEnd",
       "scene.pbrt:7:1: AttributeEnd closes the ObjectBegin "
       "at scene.pbrt:6"},
      {w + "ObjectEnd", "scene.pbrt:6:1: ObjectEnd without an ObjectBegin"},
      {w + "ObjectInstance \"b\"\n" + kTriangle,
       "scene.pbrt:6:1: ObjectInstance: no object named 'b'"},
      {w + "NamedMaterial \"whit\"\nMakeNamedMaterial \"white\" \"string type\" \"diffuse\"\n" +
           kTriangle,
       "scene.pbrt:6:1: NamedMaterial 'whit': no material of that name (did you mean 'white'?)"},
      {w + "Material \"difuse\"",
       "scene.pbrt:6:10: unknown material type 'difuse' (did you mean 'diffuse'?)"},
      {w + "MakeNamedMaterial \"m\"",
       "scene.pbrt:6:1: MakeNamedMaterial 'm' needs a \"string "
       "type\" parameter"},
      {w + "Material \"diffuse\" \"rgb reflectance\" [1.5 0 0]",
       "scene.pbrt:6:20: rgb 'reflectance' of Material has a component above 1 (it is an "
       "albedo)"},
      {w + "Material \"diffuse\" \"rgb reflectance\" [0.5 -1 0]",
       "scene.pbrt:6:20: rgb 'reflectance' of Material has a negative component"},
      {w + "Material \"diffuse\" \"float reflectance\" 0.5",
       "scene.pbrt:6:20: 'reflectance' of Material must be rgb, spectrum, blackbody or texture, "
       "got 'float reflectance'"},
      {w + "Material \"conductor\" \"rgb reflectance\" [0.5 0.5 0.5] \"rgb eta\" [1 1 1]",
       "scene.pbrt:6:54: a conductor takes either \"reflectance\" or \"eta\" and \"k\", not both "
       "(as in pbrt-v4)"},
      {w + "Material \"dielectric\" \"float roughness\" -1",
       "scene.pbrt:6:23: 'roughness' of Material: expected a non-negative number, got -1"},
      {w + "Material \"coateddiffuse\" \"integer maxdepth\" 0",
       "scene.pbrt:6:26: maxdepth: expected an integer from 1 to 1000, got 0"},
      {w + "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0 0 0 1]",
       "scene.pbrt:6:1: Shape \"trianglemesh\" needs \"integer indices\" (only a mesh of exactly "
       "3 points may leave them out)"},
      {w + "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 3]",
       "scene.pbrt:6:53: vertex index 3 of Shape \"trianglemesh\" out of range (the mesh has 3 "
       "points; indices start at 0)"},
      {w + "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1]",
       "scene.pbrt:6:53: \"indices\" of Shape \"trianglemesh\" takes a multiple of 3 integers, "
       "got 2"},
      {w + "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"normal N\" [0 0 1]",
       "scene.pbrt:6:53: \"N\" of Shape \"trianglemesh\" has 1 normals for 3 points"},
      {w + "Shape \"trianglemesh\" \"float P\" [0 0 0 1 0 0 0 1 0]",
       "scene.pbrt:6:22: 'P' of Shape \"trianglemesh\" must be a point3, got 'float P'"},
      {w + "Shape \"trianglemsh\"",
       "scene.pbrt:6:7: unknown shape type 'trianglemsh' (did you mean 'trianglemesh'?)"},
      {w + "Shape \"sphere\" \"float radius\" [1 2]",
       "scene.pbrt:6:16: 'radius' of Shape \"sphere\" takes 1 value, got 2"},
      {w + "Shape \"sphere\" \"float radius\" 0",
       "scene.pbrt:6:16: 'radius' of Shape \"sphere\": expected a positive radius, got 0"},
      {w + "Rotate 10 0 0 0",
       "scene.pbrt:6:1: Rotate about the zero vector (the axis is the "
       "last three numbers)"},
      {"LookAt 0 0 0  0 0 0  0 1 0\n",
       "scene.pbrt:1:1: LookAt: the eye and the look-at point are equal"},
      {"LookAt 0 0 0  0 1 0  0 1 0\n",
       "scene.pbrt:1:1: LookAt: the up vector is parallel to the view direction"},
      {"Scale 1 0 1\nCamera \"perspective\"\nWorldBegin\n",
       "scene.pbrt:2:1: the camera transform (the CTM at Camera) is singular"},
      {"Camera \"perspective\" \"float fov\" 180\nWorldBegin\n",
       "scene.pbrt:1:22: 'fov' of Camera \"perspective\": expected a field of view in degrees "
       "strictly between 0 and 180, got 180"},
      {"Film \"rgb\" \"integer xresolution\" 0\n",
       "scene.pbrt:1:12: xresolution: expected an integer from 1 to 16384, got 0"},
      {w + "AreaLightSource \"point\"",
       "scene.pbrt:6:17: unknown area light type 'point' (pbrt-v4 has only \"diffuse\")"},
      {w + "Attribute \"shapes\" \"float radius\" 1",
       "scene.pbrt:6:11: unknown Attribute target 'shapes' (expected \"shape\", \"light\", "
       "\"material\", \"medium\" or \"texture\")"},
      {w + "Texture \"t\" \"color\" \"constant\"",
       "scene.pbrt:6:13: Texture 't': unknown texture type 'color' (expected \"float\" or "
       "\"spectrum\")"},
      {w + "Material \"diffuse\" \"texture reflectance\" \"nope\"",
       "scene.pbrt:6:20: unknown spectrum texture 'nope' for 'reflectance'"},
      {w + "Material \"conductor\" \"spectrum eta\" \"metal-Xx-eta\"",
       "scene.pbrt:6:22: unknown named spectrum 'metal-Xx-eta' for 'eta' of Material, and no "
       "such spectrum file (looked for 'metal-Xx-eta': No such file or directory)"},
      {w + "Material \"diffuse\" \"spectrum reflectance\" [500 0.5 400 0.5]",
       "scene.pbrt:6:20: spectrum 'reflectance' of Material: the wavelengths must increase (400 "
       "follows 500)"},
      {w +
           "Shape \"disk\"\nMaterial \"interface\"\nMakeNamedMaterial \"m\" \"string type\" "
           "\"mix\" \"string materials\" [\"a\" \"b\"]\nNamedMaterial \"m\"\n" +
           kTriangle,
       "scene.pbrt:8:43: mix: no named material 'a'"},
      {w + "Material \"interface\"\n" + kTriangle,
       "scene.pbrt:8:1: the scene has no triangles to render"},
  };
  for (const auto& [text, message] : cases) EXPECT_EQ(pbrtErrorOf(text), message) << text;
}

TEST(PbrtSceneErrors, CommandLineExitsWithStatus2AndOneLine) {
  test::TempDir dir;
  const fs::path bad = dir.write("bad.pbrt", "WorldBegin\nShape \"sphere\" \"float radius\" [ 1");
  const test::PtResult r =
      test::runPt("render " + bad.string() + " --backend cpu --out " + (dir / "x.png").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err, bad.string() + ":2:31: unterminated '[' (the file ends before its ']')\n");
  EXPECT_FALSE(fs::exists(dir / "x.png"));
}

// ---- camera and film: filters, thin lens, screen window, crop, --strict ----------------------

TEST(PbrtCameraFilm, PixelFiltersWithPbrtV4sParametersAndDefaults) {
  auto filter = [](const std::string& directive) {
    return load(directive + "\nWorldBegin\n" + kTriangle).camera.filter;
  };
  PixelFilterDesc f = filter("PixelFilter \"box\"");
  EXPECT_EQ(f.type, kFilterBox);
  EXPECT_EQ(f.radiusX, 0.5f);
  EXPECT_EQ(f.radiusY, 0.5f);
  f = filter("PixelFilter \"triangle\" \"float xradius\" 1.25");
  EXPECT_EQ(f.type, kFilterTriangle);
  EXPECT_EQ(f.radiusX, 1.25f);
  EXPECT_EQ(f.radiusY, 2.0f);
  f = filter("PixelFilter \"gaussian\" \"float sigma\" 0.75 \"float yradius\" 2");
  EXPECT_EQ(f.type, kFilterGaussian);
  EXPECT_EQ(f.radiusX, 1.5f);
  EXPECT_EQ(f.radiusY, 2.0f);
  EXPECT_EQ(f.sigma, 0.75f);
  f = filter("PixelFilter \"mitchell\" \"float B\" 0 \"float C\" 0.5");
  EXPECT_EQ(f.type, kFilterMitchell);
  EXPECT_EQ(f.radiusX, 2.0f);
  EXPECT_EQ(f.b, 0.0f);
  EXPECT_EQ(f.c, 0.5f);
  f = filter("");  // none: pbrt-v4's default
  EXPECT_EQ(f.type, kFilterGaussian);
  EXPECT_EQ(f.radiusX, 1.5f);
  EXPECT_EQ(f.sigma, 0.5f);
  // "sinc" is not simulated: pbrt-v4's default filter instead, warned.
  const Scene sinc =
      load("PixelFilter \"sinc\" \"float tau\" 2\nWorldBegin\n" + std::string(kTriangle));
  EXPECT_EQ(sinc.camera.filter.type, kFilterGaussian);
  ASSERT_EQ(sinc.warnings.size(), 1u);
  EXPECT_EQ(sinc.warnings[0],
            "scene.pbrt:1: PixelFilter \"sinc\" is rendered with pbrt-v4's default filter, "
            "\"gaussian\" (the windowed sinc is not simulated)");
  // A parameter of another filter is unused, as pbrt-v4 reports it.
  const Scene unused =
      load("PixelFilter \"box\" \"float sigma\" 2\nWorldBegin\n" + std::string(kTriangle));
  ASSERT_EQ(unused.warnings.size(), 1u);
  EXPECT_EQ(unused.warnings[0],
            "scene.pbrt:1: PixelFilter \"box\": parameter 'float sigma' ignored (not used by "
            "this renderer)");
}

TEST(PbrtCameraFilm, ThinLensScreenWindowAndFrame) {
  const std::string film = "Film \"rgb\" \"integer xresolution\" 40 \"integer yresolution\" 20\n";
  Scene scene = load(film +
                     "Camera \"perspective\" \"float fov\" 30 \"float lensradius\" 0.2 "
                     "\"float focaldistance\" 8 \"float screenwindow\" [-1 3 -0.5 1.5]\n"
                     "WorldBegin\n" +
                     kTriangle);
  EXPECT_TRUE(scene.warnings.empty()) << scene.warnings.at(0);
  EXPECT_EQ(scene.camera.lensRadius, 0.2f);
  EXPECT_EQ(scene.camera.focalDistance, 8.0f);
  // With a screen window, fov is its unit: tan(fov / 2) times the window, whatever the film.
  EXPECT_EQ(scene.camera.vfovDegrees, 30.0f);
  EXPECT_EQ(scene.camera.screenWindow, (std::array<float, 4>{-1, 3, -0.5f, 1.5f}));
  // pbrt-v4's ray through raster point (px, py): camera-space (sx t, sy t, 1), t = tan(fov / 2),
  // sx = x0 + (x1 - x0) px / W, sy = y1 - (y1 - y0) py / H; camera +x is the image's right.
  const Camera cam = makeCamera(scene.camera, 40, 20);
  const double t = std::tan(15.0 * 3.14159265358979323846 / 180.0);
  for (const glm::dvec2 raster : {glm::dvec2(0, 0), glm::dvec2(40, 20), glm::dvec2(10, 15)}) {
    const double sx = -1.0 + 4.0 * raster.x / 40.0, sy = 1.5 - 2.0 * raster.y / 20.0;
    const glm::dvec3 d(cameraDirection(cam, vec2(raster)));
    const double z = glm::dot(d, glm::dvec3(cam.forward));
    EXPECT_NEAR(glm::dot(d, glm::dvec3(cam.right)) / z, sx * t, 1e-6);
    EXPECT_NEAR(glm::dot(d, glm::dvec3(cam.up)) / z, sy * t, 1e-6);
  }
  // frameaspectratio: pbrt-v4's window [-frame, frame] x [-1, 1] (landscape) or [-1, 1] x
  // [-1/frame, 1/frame] (portrait) on the film, whatever its shape: both are [-frame, frame,
  // -1, 1] in units of the vertical half-angle.
  scene = load(film +
               "Camera \"perspective\" \"float fov\" 60 \"float frameaspectratio\" 1\n"
               "WorldBegin\n" +
               kTriangle);
  EXPECT_TRUE(scene.warnings.empty()) << scene.warnings.at(0);
  EXPECT_EQ(scene.camera.vfovDegrees, 60.0f);
  EXPECT_EQ(scene.camera.screenWindow, (std::array<float, 4>{-1, 1, -1, 1}));
  scene = load(film +
               "Camera \"perspective\" \"float fov\" 60 \"float frameaspectratio\" 0.5\n"
               "WorldBegin\n" +
               kTriangle);
  EXPECT_EQ(scene.camera.screenWindow, (std::array<float, 4>{-0.5f, 0.5f, -1, 1}));
  // The horizontal half-angle is the fov's: tan(30 degrees) at the film's left edge.
  const Camera portrait = makeCamera(scene.camera, 40, 20);
  const glm::dvec3 left(cameraDirection(portrait, vec2(0.0f, 10.0f)));
  EXPECT_NEAR(
      -glm::dot(left, glm::dvec3(portrait.right)) / glm::dot(left, glm::dvec3(portrait.forward)),
      std::tan(30.0 * 3.14159265358979323846 / 180.0), 1e-6);
  // Without either, the window is CameraDesc's default, which follows --width and --height.
  scene = load(film + "Camera \"perspective\" \"float lensradius\" -1\nWorldBegin\n" + kTriangle);
  EXPECT_FALSE(scene.camera.screenWindow.has_value());
  EXPECT_EQ(scene.camera.lensRadius, 0.0f);  // pbrt-v4: a radius of 0 or less is a pinhole
}

TEST(PbrtCameraFilm, LensUnitsFollowTheCameraTransformsScale) {
  // A uniform scale in the camera transform scales camera space: the lens and the focal
  // distance are camera-space lengths.
  const Scene scene = load(
      "Scale 2 2 2\nLookAt 0 0 -10  0 0 0  0 1 0\nCamera \"perspective\" \"float lensradius\" 0.5 "
      "\"float focaldistance\" 4\nWorldBegin\n" +
      std::string(kTriangle));
  EXPECT_FLOAT_EQ(scene.camera.lensRadius, 0.25f);
  EXPECT_FLOAT_EQ(scene.camera.focalDistance, 2.0f);
}

TEST(PbrtCameraFilm, CropWindowAndPixelBoundsAsPbrtV4) {
  const std::string res = "Film \"rgb\" \"integer xresolution\" 10 \"integer yresolution\" 8 ";
  Scene scene = load(res + "\"float cropwindow\" [0.75 0.25 0.1 0.5]\nWorldBegin\n" + kTriangle);
  EXPECT_EQ(scene.camera.cropWindow, (std::array<float, 4>{0.75f, 0.25f, 0.1f, 0.5f}));
  EXPECT_EQ(cropPixels(scene.camera, 10, 8), (std::array<int, 4>{3, 8, 1, 4}));
  const Camera cam = makeCamera(scene.camera, 10, 8);
  EXPECT_EQ(cam.width, 5u);
  EXPECT_EQ(cam.height, 3u);
  scene = load(res + "\"integer pixelbounds\" [2 5 1 7]\nWorldBegin\n" + kTriangle);
  EXPECT_TRUE(scene.warnings.empty());
  EXPECT_EQ(cropPixels(scene.camera, 10, 8), (std::array<int, 4>{2, 5, 1, 7}));
  // Beyond the film: clipped, warned (as pbrt-v4).
  scene = load(res + "\"integer pixelbounds\" [2 50 1 7]\nWorldBegin\n" + kTriangle);
  EXPECT_EQ(cropPixels(scene.camera, 10, 8), (std::array<int, 4>{2, 10, 1, 7}));
  ASSERT_EQ(scene.warnings.size(), 1u);
  EXPECT_EQ(scene.warnings[0],
            "scene.pbrt:1: Film: \"pixelbounds\" reach beyond the 10x8 film: clipped to it (as "
            "pbrt-v4 does)");
  // Both: the crop window, warned.
  scene = load(res +
               "\"integer pixelbounds\" [2 5 1 7] \"float cropwindow\" [0 0.5 0 0.5]\n"
               "WorldBegin\n" +
               kTriangle);
  EXPECT_EQ(cropPixels(scene.camera, 10, 8), (std::array<int, 4>{0, 5, 0, 4}));
  ASSERT_EQ(scene.warnings.size(), 1u);
  EXPECT_EQ(scene.warnings[0],
            "scene.pbrt:1: Film: both \"pixelbounds\" and \"cropwindow\" given: the crop window is "
            "used (as pbrt-v4 does)");
}

TEST(PbrtCameraFilm, BadCameraAndFilmParametersAreErrors) {
  const std::string w = "WorldBegin\n" + std::string(kTriangle);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"PixelFilter \"lanczos\"\n" + w,
       "scene.pbrt:1:13: unknown PixelFilter type 'lanczos' (pbrt-v4 has \"box\", \"gaussian\", "
       "\"mitchell\", \"sinc\" and \"triangle\")"},
      {"PixelFilter \"gaussian\" \"float xradius\" 0\n" + w,
       "scene.pbrt:1:1: PixelFilter 'gaussian': filter radius must be in (0, 4096] pixels, got 0"},
      {"PixelFilter \"gaussian\" \"float sigma\" 0\n" + w,
       "scene.pbrt:1:1: PixelFilter 'gaussian': gaussian filter: sigma must be a positive number, "
       "got 0"},
      {"Camera \"perspective\" \"float focaldistance\" -2\n" + w,
       "scene.pbrt:1:22: focaldistance must be a positive distance, got -2"},
      {"Camera \"perspective\" \"float screenwindow\" [0 1 2]\n" + w,
       "scene.pbrt:1:22: 'screenwindow' of Camera \"perspective\" takes 4 values, got 3"},
      {"Camera \"perspective\" \"float screenwindow\" [1 1 0 2]\n" + w,
       "scene.pbrt:1:22: screenwindow [x0 x1 y0 y1] must have some width and height"},
      {"Film \"rgb\" \"integer xresolution\" 10 \"float cropwindow\" [0.11 0.15 0 1]\n" + w,
       "scene.pbrt:1:37: cropwindow selects no pixel of the 10x720 film"},
      {"Film \"rgb\" \"integer pixelbounds\" [4 4 0 1]\n" + w,
       "scene.pbrt:1:12: pixelbounds selects no pixel of the 1280x720 film"},
      {"Film \"rgb\" \"float cropwindow\" [0 1]\n" + w,
       "scene.pbrt:1:12: 'cropwindow' of Film \"rgb\" takes 4 values, got 2"},
  };
  for (const auto& [text, message] : cases) EXPECT_EQ(pbrtErrorOf(text), message) << text;
}

TEST(PbrtCameraFilm, StrictMakesEveryWarningAnError) {
  const std::string text = std::string(kUnmirrored) +
                           "Shape \"curve\" \"point3 P\" [0 0 0 1 0 0 2 0 0 3 0 0]\n" + kTriangle;
  EXPECT_EQ(load(text).warnings.size(), 1u);
  try {
    loadPbrtSceneText(text, "scene.pbrt", SceneLoadOptions{.strict = true});
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "scene.pbrt:6:1: Shape \"curve\" skipped: curves (hair) are not supported yet (an "
              "error with --strict)");
  }
  // Through loadScene, with a parameter nothing reads.
  test::TempDir dir;
  const fs::path path = dir.write("s.pbrt", std::string(kUnmirrored) +
                                                "Shape \"trianglemesh\" \"point3 P\" [0 0 0 "
                                                "1 0 0 0 1 0] \"float bogus\" 1\n");
  EXPECT_NO_THROW(loadScene(path));
  try {
    loadScene(path, SceneLoadOptions{.strict = true});
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              path.string() +
                  ":6:53: Shape \"trianglemesh\": parameter 'float bogus' ignored (not "
                  "used by this renderer) (an error with --strict)");
  }
  // Configs/cornell-box.pbrt has nothing to warn about.
  EXPECT_NO_THROW(loadScene(test::kConfigs / "cornell-box.pbrt", SceneLoadOptions{.strict = true}));
}

TEST(PbrtMaterials, TexturesBecomeTheirPrograms) {
  const test::TempDir dir;
  Image image(2, 2);
  image.pixels = {vec3(0.0f), vec3(0.5f), vec3(0.25f), vec3(0.25f)};
  writeImage(image, dir / "g.pfm");
  dir.write("photo.jpg", "not a JPEG");
  std::vector<std::string> warnings;
  // The reflectance that texture "t" gives at (u, v).
  const auto reflectance = [&](const std::string& textures, vec2 uv) {
    const Scene scene = load(std::string(kUnmirrored) + textures +
                                 "Material \"diffuse\" \"texture reflectance\" \"t\"\n" + kTriangle,
                             dir / "scene.pbrt");
    warnings = scene.warnings;
    const uint m = scene.triangles[0].material;
    const TextureTables tables{scene.textureNodes.data(), scene.imageWords.data(), nullptr,
                               nullptr};
    if (scene.materialTextures.empty()) return scene.materials[m].reflectance;
    return resolveMaterial(tables, scene.materials[m], scene.materialTextures[m], uv).reflectance;
  };
  // A checkerboard: tex1 on even squares, tex2 on odd ones.
  const std::string board =
      "Texture \"t\" \"spectrum\" \"checkerboard\" \"float uscale\" 2 \"rgb tex1\" [0.2 0.4 0.6] "
      "\"rgb tex2\" [0.6 0.4 0.2]\n";
  EXPECT_EQ(reflectance(board, vec2(0.25f, 0.5f)), vec3(0.2f, 0.4f, 0.6f));
  EXPECT_EQ(reflectance(board, vec2(0.75f, 0.5f)), vec3(0.6f, 0.4f, 0.2f));
  // scale x an image, nested: the bottom-left texel (t = 0.25 is row 1) doubled.
  EXPECT_NEAR(reflectance("Texture \"g\" \"spectrum\" \"imagemap\" \"string filename\" \"g.pfm\" "
                          "\"string filter\" \"point\"\n"
                          "Texture \"t\" \"spectrum\" \"scale\" \"texture tex\" \"g\" "
                          "\"float scale\" 2\n",
                          vec2(0.25f, 0.25f))
                  .x,
              0.5f, 1e-6f);
  EXPECT_NEAR(
      reflectance("Texture \"t\" \"spectrum\" \"mix\" \"rgb tex1\" [0 0 0] \"rgb tex2\" [1 1 1] "
                  "\"float amount\" 0.25\n",
                  vec2(0.5f))
          .y,
      0.25f, 1e-6f);
  EXPECT_NEAR(reflectance("Texture \"t\" \"spectrum\" \"imagemap\" \"string filename\" \"g.pfm\" "
                          "\"bool invert\" true \"string filter\" \"point\"\n",
                          vec2(0.75f, 0.75f))
                  .z,
              0.5f, 1e-6f);
  // A class not simulated (bilerp) takes its mean, warned.
  EXPECT_NEAR(reflectance("Texture \"t\" \"spectrum\" \"bilerp\" \"rgb v00\" [0 0 0] \"rgb v01\" "
                          "[1 1 1] \"rgb v10\" [1 1 1] \"rgb v11\" [0 0 0]\n",
                          vec2(0.0f))
                  .x,
              0.5f, 1e-6f);
  ASSERT_FALSE(warnings.empty());
  EXPECT_NE(warnings[0].find("textures of class 'bilerp' are not simulated"), std::string::npos)
      << warnings[0];
  // A missing or malformed image is an error naming it, as in pbrt-v4.
  for (const char* file : {"none.pfm", "photo.jpg"}) {
    try {
      reflectance(std::string("Texture \"t\" \"spectrum\" \"imagemap\" \"string filename\" \"") +
                      file + "\"\n",
                  vec2(0.0f));
      ADD_FAILURE() << "expected an error for " << file;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace pt
