// Ray differentials (shaders/differentials.h): the footprint of a pixel on a surface against
// finite differences of the camera mapping (pinhole and thin lens), carried through a curved
// mirror and a refraction against the derivative of the exact mapping (central differences in
// double precision), the camera's smallest differentials standing in for a ray's own, the
// changes of (u, v) solved from a surface's partial derivatives, and the footprint at an
// untextured hit of a textured scene.
#include <gtest/gtest.h>

#include <cmath>

#include <glm/glm.hpp>

#include "differentials.h"
#include "filter.h"
#include "render/camera.h"
#include "render/prepare.h"
#include "scene/load_scene.h"
#include "scene/scene.h"
#include "test_util.h"

namespace pt {
namespace {

// A film of 1000 x 800 pixels: a pixel spans ~0.001 rad, where a differential's offset ray and
// the derivative it stands for agree to ~0.1 %.
RenderParams paramsWith(const CameraDesc& desc) {
  RenderParams p{};
  p.camera = makeCamera(desc, desc.width, desc.height);
  setCameraDifferentials(p, 1);
  return p;
}

CameraDesc wideFilm() {
  CameraDesc d;
  d.position = vec3(0.1f, -0.2f, 0.0f);
  d.target = vec3(0.3f, 0.1f, 5.0f);
  d.width = 1000;
  d.height = 800;
  d.vfovDegrees = 50.0f;
  return d;
}

// Where a ray meets the plane through q with normal n (double precision).
glm::dvec3 hitPlane(glm::dvec3 o, glm::dvec3 d, glm::dvec3 q, glm::dvec3 n) {
  return o + (glm::dot(q - o, n) / glm::dot(d, n)) * d;
}
glm::dvec3 toDouble(vec3 v) {
  return glm::dvec3(v);
}

// The pinhole's ray direction through film point f, in double precision (sampling.h's
// cameraFilmVector, which is linear in f).
glm::dvec3 filmDirection(const Camera& cam, glm::dvec2 f) {
  const double u = 2.0 * f.x / double(cam.filmWidth) - 1.0;
  const double v = 1.0 - 2.0 * f.y / double(cam.filmHeight);
  return glm::normalize(toDouble(cam.windowCenter) +
                        (u * double(cam.tanHalfFovY) * double(cam.aspect)) * toDouble(cam.right) +
                        (v * double(cam.tanHalfFovY)) * toDouble(cam.up));
}

void expectVectorNear(glm::dvec3 got, glm::dvec3 want, double relative, const char* what) {
  EXPECT_LE(glm::length(got - want), relative * glm::length(want))
      << what << ": got (" << got.x << ", " << got.y << ", " << got.z << "), want (" << want.x
      << ", " << want.y << ", " << want.z << ")";
}

TEST(Differentials, PinholeFootprintIsTheNextPixelsHit) {
  const CameraDesc desc = wideFilm();
  const RenderParams p = paramsWith(desc);
  const Camera& cam = p.camera;
  const vec2 f(317.25f, 211.5f);
  const vec3 d = normalize(cameraFilmVector(cam, f));
  const RayDifferential rd = cameraRayDifferential(cam, f, vec3(0.0f), cam.position, d, 1.0f);
  ASSERT_TRUE(rd.present);
  // A tilted plane 5 units away.
  const glm::dvec3 q(0.0, 0.0, 5.0);
  const glm::dvec3 n = glm::normalize(glm::dvec3(0.3, 0.2, -1.0));
  const glm::dvec3 o = toDouble(cam.position);
  const glm::dvec3 hit = hitPlane(o, filmDirection(cam, f), q, n);
  vec3 dpdx, dpdy;
  surfaceDpdxy(p, rd, vec3(hit), vec3(n), dpdx, dpdy);
  expectVectorNear(toDouble(dpdx),
                   hitPlane(o, filmDirection(cam, glm::dvec2(f) + glm::dvec2(1, 0)), q, n) - hit,
                   1e-3, "dp/dx");
  expectVectorNear(toDouble(dpdy),
                   hitPlane(o, filmDirection(cam, glm::dvec2(f) + glm::dvec2(0, 1)), q, n) - hit,
                   1e-3, "dp/dy");
  // Scaled (pbrt-v4's samples-per-pixel scale): the offset directions move towards the ray's.
  const RayDifferential half = cameraRayDifferential(cam, f, vec3(0.0f), cam.position, d, 0.5f);
  expectVectorNear(toDouble(half.rxDirection - d), 0.5 * toDouble(rd.rxDirection - d), 1e-4,
                   "scaled offset");
}

TEST(Differentials, ThinLensFootprintIsTheNextPixelsHitThroughTheSameLensPoint) {
  CameraDesc desc = wideFilm();
  desc.lensRadius = 0.2f;
  desc.focalDistance = 3.0f;
  desc.filter.type = kFilterBox;
  desc.filter.radiusX = desc.filter.radiusY = 0.5f;
  const RenderParams p = paramsWith(desc);
  const Camera& cam = p.camera;
  // generateCameraRay through film point pixel + u (a box filter of radius 1/2 adds u) and the
  // lens point of uLens; the next pixel's ray takes the same numbers.
  const uvec2 pixel(402, 300);
  const vec2 uFilter(0.3f, 0.7f);
  const vec2 uLens(0.8f, 0.35f);
  const CameraSample c = generateCameraRay(cam, pixel, uFilter, uLens);
  const CameraSample cx = generateCameraRay(cam, pixel + uvec2(1, 0), uFilter, uLens);
  const CameraSample cy = generateCameraRay(cam, pixel + uvec2(0, 1), uFilter, uLens);
  ASSERT_NE(c.lensOffset, vec3(0.0f));
  const RayDifferential rd =
      cameraRayDifferential(cam, c.filmPoint, c.lensOffset, c.origin, c.direction, 1.0f);
  // A plane beyond the plane in focus: the footprint is the lens's blur's neighbour too.
  const glm::dvec3 q(0.0, 0.0, 7.0);
  const glm::dvec3 n = glm::normalize(glm::dvec3(-0.2, 0.1, -1.0));
  const glm::dvec3 hit = hitPlane(toDouble(c.origin), toDouble(c.direction), q, n);
  vec3 dpdx, dpdy;
  surfaceDpdxy(p, rd, vec3(hit), vec3(n), dpdx, dpdy);
  expectVectorNear(toDouble(dpdx),
                   hitPlane(toDouble(cx.origin), toDouble(cx.direction), q, n) - hit, 1e-3,
                   "dp/dx");
  expectVectorNear(toDouble(dpdy),
                   hitPlane(toDouble(cy.origin), toDouble(cy.direction), q, n) - hit, 1e-3,
                   "dp/dy");
}

// A path camera -> surface -> plane, in double precision: where it meets the plane for film
// point f. The surface is a sphere (a mirror) or a plane (glass of relative index eta).
struct SpecularScene {
  glm::dvec3 centre{0.4, 0.1, 6.0};  // the mirror sphere
  double radius = 2.5;
  bool refract = false;
  double eta = 1.5;
  glm::dvec3 glassPoint{0.0, 0.0, 4.0};
  glm::dvec3 glassNormal = glm::normalize(glm::dvec3(0.25, -0.1, -1.0));  // facing the camera
  glm::dvec3 planePoint{0.0, 0.0, -3.0};  // where reflected rays land (behind the camera)
  glm::dvec3 planeNormal = glm::normalize(glm::dvec3(0.1, 0.2, 1.0));
  glm::dvec3 refractedPlanePoint{0.0, 0.0, 9.0};

  // The surface's hit and normal for a ray from o along unit d.
  void surface(glm::dvec3 o, glm::dvec3 d, glm::dvec3& p, glm::dvec3& n) const {
    if (refract) {
      p = hitPlane(o, d, glassPoint, glassNormal);
      n = glassNormal;
      return;
    }
    const glm::dvec3 oc = o - centre;
    const double b = glm::dot(oc, d);
    const double t = -b - std::sqrt(b * b - (glm::dot(oc, oc) - radius * radius));
    p = o + t * d;
    n = (p - centre) / radius;
  }
  glm::dvec3 scatter(glm::dvec3 d, glm::dvec3 n) const {
    if (!refract) return d - 2.0 * glm::dot(d, n) * n;
    // Snell's law, entering (n faces the incoming ray).
    const double cosI = -glm::dot(d, n);
    const double sin2T = (1.0 - cosI * cosI) / (eta * eta);
    return d / eta + (cosI / eta - std::sqrt(1.0 - sin2T)) * n;
  }
  glm::dvec3 landing(glm::dvec3 o, glm::dvec3 d) const {
    glm::dvec3 p, n;
    surface(o, d, p, n);
    const glm::dvec3 wi = scatter(d, n);
    return refract ? hitPlane(p, wi, refractedPlanePoint, planeNormal)
                   : hitPlane(p, wi, planePoint, planeNormal);
  }
};

// The offset ray of the differential after the surface, intersected with the landing plane,
// minus the path's landing point: the landing's change across the pixel, which should be the
// exact mapping's derivative (central differences, double precision) to first order.
void checkSpecular(const SpecularScene& scene) {
  const RenderParams p = paramsWith(wideFilm());
  const Camera& cam = p.camera;
  const vec2 f(455.5f, 371.25f);
  const glm::dvec3 o = toDouble(cam.position);
  const glm::dvec3 d = filmDirection(cam, f);
  const RayDifferential rd = cameraRayDifferential(cam, f, vec3(0.0f), cam.position, vec3(d), 1.0f);
  glm::dvec3 hit, normal;
  scene.surface(o, d, hit, normal);
  vec3 dpdx, dpdy;
  surfaceDpdxy(p, rd, vec3(hit), vec3(normal), dpdx, dpdy);
  // On a sphere, n = (p - c) / r: the normal changes by dp / r.
  const vec3 dndx = scene.refract ? vec3(0.0f) : dpdx / float(scene.radius);
  const vec3 dndy = scene.refract ? vec3(0.0f) : dpdy / float(scene.radius);
  const glm::dvec3 wi = scene.scatter(d, normal);
  const RayDifferential out =
      specularRayDifferential(rd, vec3(hit), dpdx, dpdy, vec3(normal), dndx, dndy, vec3(-d),
                              vec3(wi), !scene.refract, float(scene.eta));
  ASSERT_TRUE(out.present);
  const glm::dvec3 planeQ = scene.refract ? scene.refractedPlanePoint : scene.planePoint;
  const glm::dvec3 landing = scene.landing(o, d);
  const glm::dvec3 landX =
      hitPlane(toDouble(out.rxOrigin), toDouble(out.rxDirection), planeQ, scene.planeNormal);
  const glm::dvec3 landY =
      hitPlane(toDouble(out.ryOrigin), toDouble(out.ryDirection), planeQ, scene.planeNormal);
  const double h = 1e-4;
  const glm::dvec2 fd(f);
  const glm::dvec3 derivX = (scene.landing(o, filmDirection(cam, fd + glm::dvec2(h, 0))) -
                             scene.landing(o, filmDirection(cam, fd - glm::dvec2(h, 0)))) /
                            (2.0 * h);
  const glm::dvec3 derivY = (scene.landing(o, filmDirection(cam, fd + glm::dvec2(0, h))) -
                             scene.landing(o, filmDirection(cam, fd - glm::dvec2(0, h)))) /
                            (2.0 * h);
  expectVectorNear(landX - landing, derivX, 0.01, "landing's d/dx");
  expectVectorNear(landY - landing, derivY, 0.01, "landing's d/dy");
}

TEST(Differentials, CarriedThroughACurvedMirror) {
  checkSpecular(SpecularScene{});
}

TEST(Differentials, CarriedThroughARefraction) {
  SpecularScene scene;
  scene.refract = true;
  checkSpecular(scene);
}

TEST(Differentials, NoneAfterANonSpecularBounceOrWhenTheArrivingRayHasNone) {
  const RayDifferential none = noRayDifferential();
  const RayDifferential out = specularRayDifferential(
      none, vec3(0.0f), vec3(0.01f, 0.0f, 0.0f), vec3(0.0f, 0.01f, 0.0f), vec3(0.0f, 0.0f, 1.0f),
      vec3(0.0f), vec3(0.0f), vec3(0.0f, 0.0f, 1.0f), vec3(0.0f, 0.0f, 1.0f), true, 1.0f);
  EXPECT_FALSE(out.present);
}

// Where a ray has none, the camera's smallest differentials stand in (pbrt-v4's
// Approximate_dp_dxy): at a point straight ahead on a plane facing the camera, the footprint
// is the smallest angular step times the distance, perpendicular to the view. (Its direction
// within that plane is that of pbrt-v4's arbitrary frames, so only lengths are compared.) On a
// plane tilted by 60 degrees the footprint lies in the plane and its projection across the
// view keeps that length.
TEST(Differentials, CameraApproximationWhereARayHasNone) {
  CameraDesc desc = wideFilm();
  desc.position = vec3(0.0f);
  desc.target = vec3(0.0f, 0.0f, 1.0f);
  RenderParams p = paramsWith(desc);
  const Camera& cam = p.camera;
  // pbrt-v4's search: through the lens's centre every offset starts at the camera.
  EXPECT_EQ(p.minPosDifferentialX, vec3(0.0f));
  EXPECT_EQ(p.minPosDifferentialY, vec3(0.0f));
  const float stepX = length(p.minDirDifferentialX);
  const float stepY = length(p.minDirDifferentialY);
  // The smallest angular step is at the film's corners: below the centre's 2 tan(fov/2) / height.
  const float centreStep = 2.0f * cam.tanHalfFovY / float(cam.filmHeight);
  EXPECT_LT(stepY, centreStep);
  EXPECT_GT(stepY, 0.5f * centreStep);
  EXPECT_LT(stepX, centreStep);
  EXPECT_GT(stepX, 0.5f * centreStep);
  const vec3 point = cam.position + 4.0f * cam.forward;
  vec3 dpdx, dpdy;
  approximateDpdxy(p, point, -cam.forward, dpdx, dpdy);
  EXPECT_NEAR(length(dpdx), 4.0f * stepX, 1e-3f * 4.0f * stepX);
  EXPECT_NEAR(length(dpdy), 4.0f * stepY, 1e-3f * 4.0f * stepY);
  EXPECT_NEAR(dot(dpdx, cam.forward), 0.0f, 1e-6f);
  const vec3 tilted = -0.5f * cam.forward + 0.8660254f * cam.right;
  vec3 tx, ty;
  approximateDpdxy(p, point, tilted, tx, ty);
  EXPECT_NEAR(dot(tx, tilted), 0.0f, 1e-6f);
  EXPECT_GT(length(tx), 1.01f * length(dpdx));
  EXPECT_NEAR(length(tx - dot(tx, cam.forward) * cam.forward), length(dpdx), 1e-2f * length(dpdx));
  // Scaled for the samples per pixel: max(1/8, 1/sqrt(spp)).
  setCameraDifferentials(p, 16);
  EXPECT_EQ(p.differentialScale, 0.25f);
  vec3 sx, sy;
  approximateDpdxy(p, point, -cam.forward, sx, sy);
  EXPECT_NEAR(length(sx), 0.25f * length(dpdx), 1e-6f);
  setCameraDifferentials(p, 1024);
  EXPECT_EQ(p.differentialScale, 0.125f);
}

// pbrt-v4's least squares for (u, v) from p's change: hand-computed on a surface whose dp/du
// and dp/dv are (2, 0, 0) and (0, 3, 0): dp/dx = (0.2, 0.3, 0.5) has du/dx = 0.1, dv/dx = 0.1
// (the normal component is not in the plane and drops out); degenerate partials give zeros.
TEST(Differentials, TextureCoordinateChangesFromPartialDerivatives) {
  vec2 duvdx, duvdy;
  footprintUV(vec3(2.0f, 0.0f, 0.0f), vec3(0.0f, 3.0f, 0.0f), vec3(0.2f, 0.3f, 0.5f),
              vec3(-0.4f, 0.6f, 0.0f), duvdx, duvdy);
  EXPECT_NEAR(duvdx.x, 0.1f, 1e-7f);
  EXPECT_NEAR(duvdx.y, 0.1f, 1e-7f);
  EXPECT_NEAR(duvdy.x, -0.2f, 1e-7f);
  EXPECT_NEAR(duvdy.y, 0.2f, 1e-7f);
  // Sheared partials: dp/du = (1, 0, 0), dp/dv = (1, 1, 0); dp/dx = 2 dp/du + 3 dp/dv.
  footprintUV(vec3(1.0f, 0.0f, 0.0f), vec3(1.0f, 1.0f, 0.0f), vec3(5.0f, 3.0f, 0.0f), vec3(0.0f),
              duvdx, duvdy);
  EXPECT_NEAR(duvdx.x, 2.0f, 1e-6f);
  EXPECT_NEAR(duvdx.y, 3.0f, 1e-6f);
  footprintUV(vec3(1.0f, 0.0f, 0.0f), vec3(2.0f, 0.0f, 0.0f), vec3(1.0f, 0.0f, 0.0f), vec3(0.0f),
              duvdx, duvdy);
  EXPECT_EQ(duvdx, vec2(0.0f));
}

// pbrt-v4 takes the footprint at every hit, not only where a texture reads it: in a textured
// scene, an untextured mirror with vertex normals gets dp/dx and dp/dy where the ray's offset
// rays meet its tangent plane, and the interpolated normal's change across them, which its
// specular bounce carries on to the textures it reflects. The normal's change is checked
// against the (unnormalized) interpolation of the vertex normals at p + dp/dx, which is linear.
constexpr char kCurvedMirror[] =
    "v -1 -1 0\nv 1 -1 0\nv 0 1 0\n"
    "vn -0.3 -0.2 1\nvn 0.4 -0.1 1\nvn 0 0.3 1\n"
    "f 1//1 2//2 3//3\n";

TEST(Differentials, EveryHitOfATexturedSceneGetsItsFootprint) {
  const test::TempDir dir;
  dir.write("mirror.obj", kCurvedMirror);
  const Scene scene = loadScene(dir.write("scene.json", R"({
    "camera": {"position": [0.2, 0.1, 5], "target": [0, 0, 0], "vfov": 30,
               "width": 64, "height": 64},
    "textures": [{"name": "board", "type": "checkerboard", "uscale": 8, "vscale": 8,
                  "tex1": 0.1, "tex2": 0.9}],
    "materials": [{"name": "floor", "type": "diffuse", "reflectance": "board"},
                  {"name": "mirror", "type": "mirror", "reflectance": [1, 1, 1]}],
    "shapes": [
      {"type": "quad", "material": "floor",
       "vertices": [[-5, -5, -2], [5, -5, -2], [5, 5, -2], [-5, 5, -2]]},
      {"type": "obj", "material": "mirror", "file": "mirror.obj"}
    ],
    "lights": [{"type": "distant", "direction": [0, 0, 1], "radiance": [1, 1, 1]}]})"));
  const SceneData data = prepareScene(scene, RenderSettings{});
  ASSERT_EQ(data.params.footprints, 1u);
  ASSERT_EQ(data.params.normalsPresent, 1u);
  const PathScene ps = data.pathScene();
  uint index = 0;
  while (data.materials[data.bvh.triangles[index].material].type != kMaterialMirror) ++index;
  const Triangle& tri = data.bvh.triangles[index];
  const vec3 b(0.3f, 0.3f, 0.4f);
  const vec3 p = b.x * tri.v0 + b.y * tri.v1 + b.z * tri.v2;
  const Camera& cam = data.params.camera;
  const vec3 d = normalize(p - cam.position);
  const vec2 film(0.5f * float(cam.filmWidth), 0.5f * float(cam.filmHeight));
  const RayDifferential rd =
      cameraRayDifferential(cam, film, vec3(0.0f), cam.position, d, data.params.differentialScale);
  ASSERT_TRUE(rd.present);
  const SurfacePoint s = surfacePointAt(ps, index, tri, b, -d, rd);
  EXPECT_EQ(s.scatter, kScatterMirror);
  vec3 dpdx, dpdy;
  surfaceDpdxy(data.params, rd, p, s.ng, dpdx, dpdy);
  EXPECT_GT(length(dpdx), 0.0f);
  EXPECT_EQ(s.dpdx, dpdx);
  EXPECT_EQ(s.dpdy, dpdy);

  // The barycentrics of a point q of the triangle's plane, in double precision.
  const glm::dvec3 v0 = toDouble(tri.v0), v1 = toDouble(tri.v1), v2 = toDouble(tri.v2);
  const auto barycentrics = [&](glm::dvec3 q) {
    const glm::dvec3 n = glm::cross(v1 - v0, v2 - v0);
    const double area = glm::dot(n, n);
    const double w1 = glm::dot(glm::cross(q - v0, v2 - v0), n) / area;
    const double w2 = glm::dot(glm::cross(v1 - v0, q - v0), n) / area;
    return glm::dvec3(1.0 - w1 - w2, w1, w2);
  };
  const TriangleNormals& normals = ps.normals[tri.primitive];
  const auto interpolated = [&](glm::dvec3 w) {
    return w.x * toDouble(normals.n0) + w.y * toDouble(normals.n1) + w.z * toDouble(normals.n2);
  };
  const glm::dvec3 here = interpolated(barycentrics(toDouble(p)));
  const glm::dvec3 wantX = interpolated(barycentrics(toDouble(p + dpdx))) - here;
  const glm::dvec3 wantY = interpolated(barycentrics(toDouble(p + dpdy))) - here;
  EXPECT_GT(glm::length(wantX), 1e-4);
  expectVectorNear(toDouble(s.dndx), wantX, 1e-3, "dn/dx");
  expectVectorNear(toDouble(s.dndy), wantY, 1e-3, "dn/dy");
}

}  // namespace
}  // namespace pt
