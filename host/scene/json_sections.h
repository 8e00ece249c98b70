// Sections of the JSON scene format (docs/scene-format.md) that another reader shares: the
// glTF wrapper (scene/gltf/gltf_wrapper.h) reads its camera, integrator and environment as a
// JSON scene reads them.
#pragma once

#include <filesystem>

#include "scene/json_reader.h"
#include "scene/scene.h"

namespace pt::scene_detail {

// "camera": the keys given replace those of `base`.
CameraDesc readJsonCamera(const JsonNode& node, const CameraDesc& base);
// "integrator".
IntegratorSettings readJsonIntegrator(const JsonNode& node);
// An "environment" light's object ("filename", "mapping", "scale", "rotate"; or "radiance"),
// its image relative to sceneFile: scene.environment, or a constant infinite light.
void readJsonEnvironment(const JsonNode& node, const std::filesystem::path& sceneFile,
                         Scene& scene);

}  // namespace pt::scene_detail
