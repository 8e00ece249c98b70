// setCamera (gltf_camera.h).
#include "scene/gltf/gltf_camera.h"

#include <cmath>
#include <limits>
#include <optional>

#include <glm/geometric.hpp>

namespace pt::gltf {

namespace {

constexpr double kPi = 3.14159265358979323846;

// The camera --camera names: an index into "cameras" or a camera's name.
std::size_t findCamera(const tinygltf::Model& model, const std::string& wanted,
                       const Context& context) {
  char* end = nullptr;
  const unsigned long index = std::strtoul(wanted.c_str(), &end, 10);
  if (!wanted.empty() && *end == '\0' && wanted[0] != '-') {
    if (index >= model.cameras.size()) {
      context.fail("cameras", "--camera " + wanted + " out of range (the file has " +
                                  std::to_string(model.cameras.size()) + " cameras)");
    }
    return index;
  }
  for (std::size_t i = 0; i < model.cameras.size(); ++i) {
    if (model.cameras[i].name == wanted) return i;
  }
  std::vector<std::string_view> names;
  for (const auto& c : model.cameras) names.push_back(c.name);
  context.fail("cameras", "no camera named " + scene_detail::singleQuoted(wanted) +
                              scene_detail::didYouMean(wanted, names));
}

void frameBounds(Scene& scene) {
  vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
  for (const Triangle& t : scene.triangles) {
    for (const vec3& v : {t.v0, t.v1, t.v2}) {
      lo = glm::min(lo, v);
      hi = glm::max(hi, v);
    }
  }
  const glm::dvec3 centre = (glm::dvec3(lo) + glm::dvec3(hi)) * 0.5;
  const double radius = std::max(0.5 * glm::length(glm::dvec3(hi) - glm::dvec3(lo)), 1e-6);
  // The bounding sphere just inside the vertical field of view, seen along -z.
  const double distance = radius / std::sin(0.5 * kDefaultFovDegrees * kPi / 180.0);
  scene.camera.position = vec3(centre + glm::dvec3(0.0, 0.0, distance));
  scene.camera.target = vec3(centre);
  scene.camera.up = vec3(0.0f, 1.0f, 0.0f);
  scene.camera.vfovDegrees = kDefaultFovDegrees;
  scene.camera.width = kFilmHeight;
  scene.camera.height = kFilmHeight;
}

}  // namespace

void setCamera(const tinygltf::Model& model, const std::vector<PlacedNode>& nodes,
               const std::string& wanted, Scene& scene, Context& context) {
  std::optional<std::size_t> cameraIndex;
  if (!wanted.empty()) cameraIndex = findCamera(model, wanted, context);
  const PlacedNode* placed = nullptr;
  for (const PlacedNode& p : nodes) {
    const int c = model.nodes[p.node].camera;
    if (c < 0) continue;
    const std::string where = indexed("nodes", p.node) + ".camera";
    if (std::size_t(c) >= model.cameras.size()) {
      context.fail(where, "camera " + std::to_string(c) + " out of range (the file has " +
                              std::to_string(model.cameras.size()) + ")");
    }
    if (placed == nullptr && (!cameraIndex || *cameraIndex == std::size_t(c))) {
      placed = &p;
      cameraIndex = std::size_t(c);
    }
  }
  if (placed == nullptr) {
    if (!wanted.empty()) {
      context.fail("cameras[" + std::to_string(*cameraIndex) + "]",
                   "--camera " + wanted + ": no node of the scene places this camera");
    }
    frameBounds(scene);
    return;
  }
  const std::string path = indexed("cameras", *cameraIndex);
  const tinygltf::Camera& camera = model.cameras[*cameraIndex];
  if (camera.type != "perspective") {
    context.warnOnce("orthographic", path + ".type",
                     "'" + camera.type +
                         "' cameras are not simulated: the scene's bounding box is framed instead");
    frameBounds(scene);
    return;
  }
  const tinygltf::PerspectiveCamera& p = camera.perspective;
  if (!(p.yfov > 0.0 && p.yfov < kPi)) {
    context.fail(path + ".perspective.yfov", "must be between 0 and pi radians");
  }
  if (!(p.aspectRatio >= 0.0 && p.aspectRatio < 1e4)) {
    context.fail(path + ".perspective.aspectRatio", "must be a positive number");
  }
  const glm::dmat4& m = placed->world;
  const glm::dvec3 forward(m * glm::dvec4(0.0, 0.0, -1.0, 0.0));
  const glm::dvec3 up(m * glm::dvec4(0.0, 1.0, 0.0, 0.0));
  const glm::dvec3 position(m[3]);
  if (!(glm::length(forward) > 0.0) || !(glm::length(glm::cross(forward, up)) > 0.0)) {
    context.fail(indexed("nodes", placed->node),
                 "the camera's transform collapses its view direction or its up vector");
  }
  scene.camera.position = vec3(position);
  scene.camera.target = vec3(position + glm::normalize(forward));
  scene.camera.up = vec3(glm::normalize(up));
  scene.camera.vfovDegrees = float(p.yfov * 180.0 / kPi);
  scene.camera.height = kFilmHeight;
  scene.camera.width = p.aspectRatio > 0.0
                           ? std::max(1, int(std::lround(kFilmHeight * p.aspectRatio)))
                           : kFilmHeight;
}

}  // namespace pt::gltf
