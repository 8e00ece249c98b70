// addPunctualLights (gltf_lights.h).
#include "scene/gltf/gltf_lights.h"

#include <cmath>
#include <string>

#include <glm/geometric.hpp>

#include "scene/json_reader.h"

namespace pt::gltf {

namespace {

constexpr double kHalfPi = 1.57079632679489661923;

Light makeLight(const tinygltf::Light& l, const std::string& path, const glm::dmat4& world,
                Context& context) {
  vec3 color(1.0f);
  if (!l.color.empty()) {
    if (l.color.size() != 3) context.fail(path + ".color", "expected 3 numbers");
    for (int i = 0; i < 3; ++i) {
      const double c = l.color[std::size_t(i)];
      if (!(c >= 0.0 && c <= 1.0)) {
        context.fail(path + ".color", scene_detail::formatNumber(c) + " is not in [0, 1]");
      }
      color[i] = float(c);
    }
  }
  if (!(l.intensity >= 0.0 && l.intensity < 3e38)) {
    context.fail(path + ".intensity", "must be a non-negative number");
  }
  if (l.range != 0.0) {
    if (!(l.range > 0.0)) context.fail(path + ".range", "must be positive");
    context.warnOnce("light range", path + ".range",
                     "a light's range is not simulated: its light falls off with the inverse "
                     "square of the distance, without a cut-off");
  }
  const glm::dvec3 axis(world * glm::dvec4(0.0, 0.0, -1.0, 0.0));
  if (!(glm::length(axis) > 0.0)) context.fail(path, "its node's transform collapses -z");
  Light out{};
  out.position = vec3(glm::dvec3(world[3]));
  out.radiance = color * float(l.intensity);
  out.direction = vec3(glm::normalize(axis));
  if (l.type == "point") {
    out.type = kLightPoint;
  } else if (l.type == "spot") {
    const double inner = l.spot.innerConeAngle, outer = l.spot.outerConeAngle;
    if (!(outer > 0.0 && outer <= kHalfPi)) {
      context.fail(path + ".spot.outerConeAngle", "must be in (0, pi/2]");
    }
    if (!(inner >= 0.0 && inner < outer)) {
      context.fail(path + ".spot.innerConeAngle", "must be in [0, outerConeAngle)");
    }
    out.type = kLightSpot;
    out.cosFalloffStart = float(std::cos(inner));
    out.cosFalloffEnd = float(std::cos(outer));
  } else if (l.type == "directional") {
    out.type = kLightDistant;
    out.direction = -out.direction;  // a distant light's direction points towards the light
  } else {
    context.fail(path + ".type", "'" + l.type + "' is not point, spot or directional");
  }
  return out;
}

}  // namespace

void addPunctualLights(const tinygltf::Model& model, const std::vector<PlacedNode>& nodes,
                       Scene& scene, Context& context) {
  for (const PlacedNode& p : nodes) {
    const auto it = model.nodes[p.node].extensions.find("KHR_lights_punctual");
    if (it == model.nodes[p.node].extensions.end()) continue;
    const std::string where = indexed("nodes", p.node) + ".extensions.KHR_lights_punctual";
    if (!it->second.IsObject() || !it->second.Has("light") || !it->second.Get("light").IsNumber()) {
      context.fail(where, "expected an object with a light index");
    }
    const double index = it->second.Get("light").GetNumberAsDouble();
    if (!(index >= 0.0 && index < double(model.lights.size())) || index != std::floor(index)) {
      context.fail(where + ".light", "light " + scene_detail::formatNumber(index) +
                                         " out of range (the file has " +
                                         std::to_string(model.lights.size()) + ")");
    }
    const std::size_t i = std::size_t(index);
    scene.lights.push_back(makeLight(
        model.lights[i], "extensions.KHR_lights_punctual.lights[" + std::to_string(i) + "]",
        p.world, context));
  }
}

}  // namespace pt::gltf
