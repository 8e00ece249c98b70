// pbrt-v4's Shape directive (its shapes.cpp Create functions): trianglemesh, plymesh, sphere,
// disk, bilinearmesh and the rest, tessellated and appended to the scene under the CTM.
#include "scene/pbrt/pbrt_shapes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include "common/check.h"
#include "scene/json_reader.h"
#include "scene/pbrt/pbrt_builder.h"
#include "scene/ply_mesh.h"
#include "scene/reader_helpers.h"

namespace pt::pbrt {

namespace fs = std::filesystem;

using scene_detail::quotedPath;

void reverseMesh(Mesh& mesh) {
  for (Tri& t : mesh.triangles) std::swap(t[1], t[2]);
  for (UVs& uv : mesh.uvs) std::swap(uv[1], uv[2]);
  for (Tri& n : mesh.normals) {
    std::swap(n[1], n[2]);
    for (glm::dvec3& v : n) v = -v;
  }
}

Mesh transformMesh(Mesh mesh, const glm::dmat4& m) {
  const glm::dmat3 linear(m);
  const double det = glm::determinant(linear);
  const bool swap = det < 0.0;
  const bool invertible = det != 0.0 && std::isfinite(det);
  const glm::dmat3 normalMatrix =
      invertible ? glm::transpose(glm::inverse(linear)) : glm::dmat3(0.0);
  // In place: a large mesh's copy would cost as much as its transform (fresh pages).
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    Tri& t = mesh.triangles[i];
    UVs unused{};
    UVs& uv = mesh.uvs.empty() ? unused : mesh.uvs[i];
    for (glm::dvec3& p : t) p = transformPoint(m, p);
    if (swap) {
      std::swap(t[1], t[2]);
      std::swap(uv[1], uv[2]);
    }
    if (!mesh.normals.empty()) {
      Tri& n = mesh.normals[i];
      for (glm::dvec3& v : n) v = normalMatrix * v;  // zero where singular: see emit
      if (swap) std::swap(n[1], n[2]);
      glm::dvec3 sum(0.0);
      for (const glm::dvec3& v : n) {
        const double len = glm::length(v);
        if (len > 0.0 && std::isfinite(len)) sum += v / len;
      }
      if (glm::dot(glm::cross(t[1] - t[0], t[2] - t[0]), sum) < 0.0) {
        std::swap(t[1], t[2]);
        std::swap(n[1], n[2]);
        std::swap(uv[1], uv[2]);
      }
    }
  }
  return mesh;
}

void Builder::shape(Statement& s) {
  const std::string& type = s.strings[0];
  const std::string context = "Shape \"" + type + "\"";
  Params p(*this, s, &gs_.shapeAttributes, context);
  Mesh mesh;
  const bool built = buildShape(type, p, s, mesh);
  // pbrt-v4's "alpha": the shape is cut away where it is 0 (a texture or a number).
  uint alpha = kNoTexture;
  if (const Param* a = p.find("alpha", {ParamType::kFloat, ParamType::kTexture})) {
    if (a->type == ParamType::kTexture) {
      alpha = textureParam(p, "alpha", true);
      if (alpha == kNoTexture) {
        warnOnce("alpha", a->location,
                 "\"alpha\" of a texture class that is not simulated is ignored: the shape is "
                 "opaque");
      }
    } else {
      p.expectCount(*a, 1);
      p.checkBounded(*a, a->numbers[0], 0.0, false, 1.0, false, "a number in [0, 1]");
      if (a->numbers[0] != 1.0) alpha = textures_.constant(vec3(float(a->numbers[0])));
    }
  }
  p.reportUnused();
  if (!built || mesh.triangles.empty()) {
    ++skippedShapes_;
    return;
  }
  // The shape's triangles take the current MediumInterface; those of an "interface" material
  // are kept only where it is a transition (finish).
  mediumInterfaces_[gs_.mediumInterface].used = true;
  if (gs_.reverseOrientation) reverseMesh(mesh);
  Mesh world = transformMesh(std::move(mesh), gs_.ctm.m);
  if (!activeInstance_.empty()) {
    if (gs_.areaLight) {
      warnOnce("instance area light", s.location,
               "area lights in object instances are ignored, as pbrt-v4 ignores them");
    }
    instances_[activeInstance_].shapes.push_back(InstanceShape{
        std::move(world), slotFor(gs_.material, alpha), gs_.mediumInterface, s.location, context});
    return;
  }
  uint slot;
  if (gs_.areaLight && isKnownInterface(gs_.material)) {
    warnOnce("interface area light", s.location,
             "an area light on shapes with the \"interface\" material is ignored, as pbrt-v4 "
             "ignores it");
    slot = slotFor(gs_.material, alpha);
  } else if (gs_.areaLight) {
    const AreaLight& light = *gs_.areaLight;
    double scale = light.scale;
    if (light.power > 0.0) {
      // pbrt-v4: the scale that makes the shape emit `power`, area * pi per unit radiance
      // and side.
      double area = 0.0;
      for (const Tri& t : world.triangles) {
        area += 0.5 * glm::length(glm::cross(t[1] - t[0], t[2] - t[0]));
      }
      if (area > 0.0)
        scale *= light.power / ((light.twoSided ? 2.0 : 1.0) * area * 3.14159265358979323846);
    }
    const glm::dvec3 emission = glm::dvec3(light.radiance) * scale;
    for (int c = 0; c < 3; ++c) {
      if (!(static_cast<float>(emission[c]) < std::numeric_limits<float>::infinity())) {
        fail(light.location, "the area light's emission (L * scale) does not fit a 32-bit float");
      }
    }
    slot = static_cast<uint>(slots_.size());
    slots_.push_back(Slot{gs_.material, vec3(emission),
                          "AreaLightSource at " + light.location.fileLine(), light.twoSided,
                          alpha});
    // A sphere that stays a sphere (a rotation and a uniform scale, no mirror) and emits
    // outwards on one side: light sampling takes the cone it subtends, as pbrt-v4's does.
    const glm::dmat3 m(gs_.ctm.m);
    const double size = glm::length(m[0]);
    bool similar = glm::determinant(m) > 0.0 && size > 0.0;
    for (int a = 0; a < 3 && similar; ++a) {
      similar = std::fabs(glm::length(m[a]) - size) <= 1e-6 * size &&
                std::fabs(glm::dot(m[a], m[(a + 1) % 3])) <= 1e-6 * size * size;
    }
    if (type == "sphere" && similar && !light.twoSided && !gs_.reverseOrientation) {
      Light sphere{};
      sphere.type = kLightSphere;
      glm::dvec3 centre = transformPoint(gs_.ctm.m, glm::dvec3(0.0));
      if (mirrored_) centre.x = -centre.x;
      sphere.position = vec3(centre);
      sphere.radius = static_cast<float>(p.number("radius").value_or(1.0) * size);
      sphere.radiance = vec3(emission);
      sphereLights_.emplace_back(sphere, slot);
    }
  } else {
    slot = slotFor(gs_.material, alpha);
  }
  emit(world, slot, gs_.mediumInterface, s.location, context);
}

// The shape's triangles in object space; false when it is skipped (warned).
bool Builder::buildShape(const std::string& type, const Params& p, const Statement& s, Mesh& mesh) {
  const std::string& context = p.context();
  if (type == "trianglemesh" || type == "loopsubdiv" || type == "bilinearmesh") {
    if (type != "trianglemesh") {
      warnOnce("shape " + type, s.location,
               context + " skipped: " +
                   (type == "loopsubdiv" ? "subdivision surfaces" : "bilinear patches") +
                   " are not supported yet");
      p.markAllUsed();
      return false;
    }
    const Param* P = p.find("P", {ParamType::kPoint3});
    if (P == nullptr) fail(s.location, context + " needs \"point3 P\"");
    const std::size_t points = P->numbers.size() / 3;
    std::vector<double> indices;
    if (const Param* I = p.find("indices", {ParamType::kInteger})) {
      indices = I->numbers;
      if (indices.size() % 3 != 0) {
        fail(I->location, "\"indices\" of " + context + " takes a multiple of 3 integers, got " +
                              std::to_string(indices.size()));
      }
      for (double v : indices) {
        if (v < 0 || v >= static_cast<double>(points)) {
          fail(I->location, "vertex index " + std::to_string(static_cast<long long>(v)) + " of " +
                                context + " out of range (the mesh has " + std::to_string(points) +
                                " points; indices start at 0)");
        }
      }
    } else if (points == 3) {
      indices = {0, 1, 2};  // pbrt-v4: three points need no indices
    } else {
      fail(s.location, context +
                           " needs \"integer indices\" (only a mesh of exactly 3 points "
                           "may leave them out)");
    }
    const Param* N = p.find("N", {ParamType::kNormal});
    if (N != nullptr && N->numbers.size() != P->numbers.size()) {
      fail(N->location, "\"N\" of " + context + " has " + std::to_string(N->numbers.size() / 3) +
                            " normals for " + std::to_string(points) + " points");
    }
    // Texture coordinates are kept; tangents are read (and checked) but not used.
    const Param* uv = p.find("uv", {ParamType::kPoint2, ParamType::kFloat});
    if (uv != nullptr) {
      if (uv->numbers.size() != 2 * points) {
        fail(uv->location, "\"uv\" of " + context + " has " +
                               std::to_string(uv->numbers.size() / 2) + " pairs for " +
                               std::to_string(points) + " points");
      }
      for (double v : uv->numbers) {
        if (!(std::fabs(v) <= double(std::numeric_limits<float>::max()))) {
          fail(uv->location, "\"uv\" of " + context +
                                 " has a value that is not finite or "
                                 "does not fit a 32-bit float");
        }
      }
    }
    p.find("S");
    p.find("faceIndices");
    const auto point = [&](const std::vector<double>& v, double i) {
      const std::size_t k = static_cast<std::size_t>(i) * 3;
      return glm::dvec3(v[k], v[k + 1], v[k + 2]);
    };
    mesh.triangles.reserve(indices.size() / 3);
    for (std::size_t t = 0; t + 2 < indices.size(); t += 3) {
      mesh.triangles.push_back(Tri{point(P->numbers, indices[t]), point(P->numbers, indices[t + 1]),
                                   point(P->numbers, indices[t + 2])});
      if (N != nullptr) {
        mesh.normals.push_back(Tri{point(N->numbers, indices[t]), point(N->numbers, indices[t + 1]),
                                   point(N->numbers, indices[t + 2])});
      }
      if (uv != nullptr) {
        const auto at = [&](double i) {
          const std::size_t k = static_cast<std::size_t>(i) * 2;
          return glm::vec2(float(uv->numbers[k]), float(uv->numbers[k + 1]));
        };
        mesh.uvs.push_back(UVs{at(indices[t]), at(indices[t + 1]), at(indices[t + 2])});
      }
    }
    return true;
  }
  if (type == "plymesh") {
    const Param* f = p.find("filename", {ParamType::kString});
    if (f == nullptr) fail(s.location, context + " needs \"string filename\"");
    p.expectCount(*f, 1);
    const std::string& name = f->strings[0];
    if (name.empty()) fail(f->location, "\"filename\" of " + context + " is empty");
    const fs::path path = resolvePath(name, f->location, mainFile_);
    std::string bytes, why;
    if (!scene_detail::readTextFile(path, &bytes, &why)) {
      const std::string looked =
          path.string() == name ? std::string() : "looked for " + quotedPath(path.string()) + ": ";
      fail(f->location, "cannot open " + quotedPath(name) + " (" + looked + why + ")");
    }
    scene_detail::PlyMesh ply = scene_detail::loadPlyMesh(
        bytes, path.string(), " (referenced by " + f->location.fileLine() + ")");
    mesh.triangles = std::move(ply.triangles);
    mesh.normals = std::move(ply.normals);
    mesh.uvs = std::move(ply.uvs);
    if (ply.nonFiniteNormals > 0) {
      warnOnce("non-finite normals", f->location,
               context + ": " + std::to_string(ply.nonFiniteNormals) + " vertex normals of " +
                   quotedPath(name) +
                   " are not finite (NaN or infinite): their triangles take the geometric "
                   "normal at those vertices");
    }
    for (const char* displacement : {"displacement", "edgelength"}) {
      if (p.find(displacement)) {
        warnOnce("plymesh displacement", s.location,
                 context + ": displacement ignored (the mesh is rendered as it is)");
      }
    }
    return true;
  }
  if (type == "sphere") {
    const double radius =
        p.bounded("radius", 0.0, true, 3.4e38, false, "a positive radius").value_or(1.0);
    const double zmin = p.number("zmin").value_or(-radius);
    const double zmax = p.number("zmax").value_or(radius);
    const double phimax = p.number("phimax").value_or(360.0);
    if (zmin > -radius || zmax < radius || phimax < 360.0) {
      warnOnce("partial sphere", s.location,
               "partial spheres (zmin, zmax, phimax) are not supported: skipped");
      return false;
    }
    warnOnce("sphere", s.location,
             "spheres are tessellated into " +
                 std::to_string(2 * kSphereSegments * (kSphereRings - 1)) +
                 " triangles with vertex normals (chord error 3e-4 of the radius) until they "
                 "are exact primitives");
    const auto direction = [](int ring, int segment) {
      if (ring == 0) return glm::dvec3(0, 0, 1);
      if (ring == kSphereRings) return glm::dvec3(0, 0, -1);
      const auto [cosTheta, sinTheta] = cosSinDegrees(180.0 * ring / kSphereRings);
      const auto [cosPhi, sinPhi] =
          cosSinDegrees(360.0 * (segment % kSphereSegments) / kSphereSegments);
      return glm::dvec3(sinTheta * cosPhi, sinTheta * sinPhi, cosTheta);
    };
    // pbrt-v4's (u, v) on a sphere: u = phi / 2 pi, v = 1 - theta / pi (theta from +z).
    const auto uvAt = [](int ring, int segment) {
      return glm::vec2(float(double(segment) / kSphereSegments),
                       float(1.0 - double(ring) / kSphereRings));
    };
    for (int i = 0; i < kSphereRings; ++i) {
      for (int j = 0; j < kSphereSegments; ++j) {
        const glm::dvec3 a = direction(i, j), b = direction(i, j + 1);
        const glm::dvec3 c = direction(i + 1, j), d = direction(i + 1, j + 1);
        const glm::vec2 ua = uvAt(i, j), ub = uvAt(i, j + 1), uc = uvAt(i + 1, j),
                        ud = uvAt(i + 1, j + 1);
        // (a, c, b) and (b, c, d): the winding's normal points outwards, pbrt's front.
        if (i != 0) {
          mesh.triangles.push_back(Tri{a * radius, c * radius, b * radius});
          mesh.normals.push_back(Tri{a, c, b});
          mesh.uvs.push_back(UVs{ua, uc, ub});
        }
        if (i != kSphereRings - 1) {
          mesh.triangles.push_back(Tri{b * radius, c * radius, d * radius});
          mesh.normals.push_back(Tri{b, c, d});
          mesh.uvs.push_back(UVs{ub, uc, ud});
        }
      }
    }
    return true;
  }
  if (type == "disk") {
    const double height = p.number("height").value_or(0.0);
    const double radius =
        p.bounded("radius", 0.0, true, 3.4e38, false, "a positive radius").value_or(1.0);
    const double inner = p.number("innerradius").value_or(0.0);
    const double phimax =
        p.bounded("phimax", 0.0, true, 360.0, false, "an angle in degrees in (0, 360]")
            .value_or(360.0);
    if (!(inner >= 0.0 && inner < radius)) {
      fail(p.find("innerradius")->location,
           "\"innerradius\" of " + context + " must be at least 0 and less than the radius");
    }
    warnOnce("disk", s.location,
             "disks are tessellated into " + std::to_string(kDiskSegments) +
                 " segments (chord error 3e-4 of the radius) until they are exact primitives");
    const int segments = std::max(1, static_cast<int>(std::ceil(kDiskSegments * phimax / 360.0)));
    const auto at = [&](double r, int j) {
      if (j == segments && phimax == 360.0) j = 0;  // closes the circle exactly
      const auto [c, sn] = cosSinDegrees(phimax * j / segments);
      return glm::dvec3(r * c, r * sn, height);
    };
    const glm::dvec3 center(0.0, 0.0, height);
    // pbrt-v4's (u, v) on a disk: u = phi / phimax, v = (radius - r) / (radius - inner); the
    // centre takes its segment's middle u.
    const auto uvAt = [&](double r, double j) {
      return glm::vec2(float(j / segments), float((radius - r) / (radius - inner)));
    };
    // Counter-clockwise about +z: the winding's normal is +z, pbrt's front of a disk.
    for (int j = 0; j < segments; ++j) {
      if (inner == 0.0) {
        mesh.triangles.push_back(Tri{center, at(radius, j), at(radius, j + 1)});
        mesh.uvs.push_back(UVs{uvAt(0.0, j + 0.5), uvAt(radius, j), uvAt(radius, j + 1)});
      } else {
        mesh.triangles.push_back(Tri{at(inner, j), at(radius, j), at(radius, j + 1)});
        mesh.triangles.push_back(Tri{at(inner, j), at(radius, j + 1), at(inner, j + 1)});
        mesh.uvs.push_back(UVs{uvAt(inner, j), uvAt(radius, j), uvAt(radius, j + 1)});
        mesh.uvs.push_back(UVs{uvAt(inner, j), uvAt(radius, j + 1), uvAt(inner, j + 1)});
      }
    }
    return true;
  }
  if (type == "curve" || type == "cylinder") {
    warnOnce("shape " + type, s.location,
             context + " skipped: " + (type == "curve" ? "curves (hair)" : "cylinders") +
                 " are not supported yet");
    p.markAllUsed();
    return false;
  }
  fail(s.stringLocations[0],
       "unknown shape type " + singleQuoted(type) +
           scene_detail::didYouMean(type, {"bilinearmesh", "curve", "cylinder", "disk",
                                           "loopsubdiv", "plymesh", "sphere", "trianglemesh"}));
}

// Appends an oriented world-space mesh to the scene: mirrored with the camera if need be,
// rounded to float, zero-area triangles dropped as the JSON reader drops them.
void Builder::emit(const Mesh& mesh, uint slot, std::size_t mediumInterface, const Location& where,
                   const std::string& context) {
  std::size_t dropped = 0;
  Scene& scene = scene_;
  // Room for the shape, growing geometrically: reserving the exact size for every shape
  // would copy the whole scene once per shape (855 PLY meshes took 9.6 s, mostly page faults).
  reserveGeometric(scene.triangles, scene.triangles.size() + mesh.triangles.size());
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    Tri t = mesh.triangles[i];
    Tri n = mesh.normals.empty() ? Tri{} : mesh.normals[i];
    UVs uv = mesh.uvs.empty() ? UVs{} : mesh.uvs[i];
    if (mirrored_) {
      // x -> -x reverses the winding, and the swap restores the front.
      for (glm::dvec3& v : t) v.x = -v.x;
      for (glm::dvec3& v : n) v.x = -v.x;
      std::swap(t[1], t[2]);
      std::swap(n[1], n[2]);
      std::swap(uv[1], uv[2]);
    }
    Triangle out{};
    glm::vec3* corners[3] = {&out.v0, &out.v1, &out.v2};
    for (int k = 0; k < 3; ++k) {
      *corners[k] = glm::vec3(t[k]);
      if (!std::isfinite(corners[k]->x) || !std::isfinite(corners[k]->y) ||
          !std::isfinite(corners[k]->z)) {
        fail(where, context + ": the transform moves vertices beyond the range of 32-bit floats");
      }
    }
    // Zero-area triangles dropped, normals made unit, as the JSON reader does.
    out.material = slot;
    const Appended appended = appendTriangle(scene, out, mesh.normals.empty() ? nullptr : &n,
                                             mesh.uvs.empty() ? nullptr : &uv);
    if (appended == Appended::kZeroArea) ++dropped;
    if (appended == Appended::kTooMany) {
      fail(where, "too many triangles in the scene (at most 4294967295)");
    }
    if (appended == Appended::kAdded) triangleInterfaces_.push_back(mediumInterface);
  }
  if (dropped > 0) {
    // One warning for the whole scene (finish): Bitterli's staircase drops some in 30 shapes.
    if (droppedShapes_ == 0) firstDrop_ = where.fileLine() + ": " + context;
    droppedTriangles_ += dropped;
    ++droppedShapes_;
  }
}

}  // namespace pt::pbrt
