// The glTF reader's entry points: the document (gltf_document.h), its nodes placed
// (gltf_nodes.h), their meshes appended (gltf_meshes.h) with their materials
// (gltf_materials.h), the camera (gltf_camera.h).
#include "scene/gltf/gltf_scene.h"

#include <cmath>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "image/image.h"
#include "scene/gltf/gltf_camera.h"
#include "scene/gltf/gltf_context.h"
#include "scene/gltf/gltf_document.h"
#include "scene/gltf/gltf_lights.h"
#include "scene/gltf/gltf_material_textures.h"
#include "scene/gltf/gltf_materials.h"
#include "scene/gltf/gltf_meshes.h"
#include "scene/gltf/gltf_nodes.h"
#include "scene/gltf/gltf_textures.h"
#include "scene/gltf/gltf_volume_media.h"
#include "scene/json_reader.h"

namespace pt {

namespace {

using gltf::addPunctualLights;
using gltf::Context;
using gltf::indexed;
using gltf::MaterialSlot;
using gltf::MeshReader;
using gltf::parseDocument;
using gltf::PlacedNode;
using gltf::placeNodes;
using gltf::readDocument;
using gltf::readMaterial;
using gltf::readMaterialTextures;
using gltf::setCamera;
using gltf::TextureReader;

// Extensions of the file that the reader reads, in part or whole (docs/gltf.md).
bool isReadExtension(const std::string& name) {
  return name == "KHR_materials_emissive_strength" || name == "KHR_materials_ior" ||
         name == "KHR_materials_transmission" || name == "KHR_materials_volume" ||
         name == "KHR_materials_clearcoat" || name == "KHR_materials_specular" ||
         name == "KHR_materials_sheen" || name == "KHR_lights_punctual" ||
         name == "KHR_texture_transform";
}

void warnUnsimulated(const tinygltf::Model& model, Context& context) {
  for (std::size_t i = 0; i < model.extensionsUsed.size(); ++i) {
    const std::string& name = model.extensionsUsed[i];
    if (isReadExtension(name)) continue;
    context.warnOnce("extension " + name, "extensionsUsed[" + std::to_string(i) + "]",
                     name + " is not simulated (rendered without it)");
  }
  if (!model.animations.empty()) {
    context.warnOnce("animations", "animations",
                     "animations are not simulated: the rest pose is rendered");
  }
  if (!model.skins.empty()) {
    context.warnOnce("skins", "skins", "skins are not simulated: the rest pose is rendered");
  }
}

// --env: a latitude-longitude image, +y up as glTF's world is. Errors name the image's file.
EnvironmentImage readEnvironment(const std::filesystem::path& path) {
  EnvironmentImage env;
  env.file = path.string();
  env.image = readImage(path);
  env.mapping = kEnvironmentLatLong;
  for (vec3& c : env.image.pixels) {
    if (!std::isfinite(c.x) || !std::isfinite(c.y) || !std::isfinite(c.z)) {
      scene_detail::throwInputError(env.file, "",
                                    "infinite or not-a-number pixels, no use as a light");
    }
    c = glm::max(c, vec3(0.0f));
  }
  return env;
}

Scene build(const tinygltf::Model& model, const std::string& file,
            const SceneLoadOptions& options) {
  Scene scene;
  Context context(file, options.strict, scene.warnings);
  warnUnsimulated(model, context);
  const std::vector<PlacedNode> nodes = placeNodes(model, context);
  // Scene materials made on first use, one per glTF material (and one for the default).
  std::map<int, gltf::MaterialChoice> slots;
  TextureReader textures(model, scene, context);
  std::vector<gltf::MaterialExtensions> extensions;  // parallel to scene.materials
  const MaterialSlot slot = [&](int material, const std::string&) {
    const auto [it, added] =
        slots.emplace(material, gltf::MaterialChoice{uint(scene.materials.size()), 0});
    if (added) {
      extensions.emplace_back();
      scene.materials.push_back(readMaterial(model, material, context, &extensions.back()));
      if (material >= 0) {
        setMaterialTextures(
            scene, it->second.material,
            readMaterialTextures(model, material, scene.materials.back(), extensions.back(),
                                 textures, context, it->second.uvSet));
      }
      const std::string name = material >= 0 ? model.materials[std::size_t(material)].name : "";
      scene.materialNames.push_back(
          material < 0 ? "default"
                       : (name.empty() ? indexed("materials", std::size_t(material)) : name));
    }
    return it->second;
  };
  MeshReader meshes(model, context);
  for (const PlacedNode& p : nodes) {
    const tinygltf::Node& node = model.nodes[p.node];
    if (node.mesh >= 0 || node.mesh < -1) {
      meshes.emit(node.mesh, indexed("nodes", p.node) + ".mesh", p.world, slot, scene);
    }
  }
  if (meshes.dropped() > 0) {
    scene.warnings.push_back(file + ": dropped " + std::to_string(meshes.dropped()) +
                             " zero-area triangle" + (meshes.dropped() == 1 ? "" : "s"));
  }
  if (scene.triangles.empty()) context.fail("scene", "the scene has no triangles to render");
  gltf::addVolumeMedia(extensions, scene);
  padMaterialTextures(scene);
  setCamera(model, nodes, options.camera, scene, context);
  addPunctualLights(model, nodes, scene, context);
  // glTF has no environment: --env gives one, and a scene without a light of its own is lit as
  // viewers light it, by a uniform white sky (radiance 1).
  if (!options.environment.empty()) {
    scene.environment = readEnvironment(options.environment);
    return scene;
  }
  bool emits = false;
  for (const Material& m : scene.materials) {
    emits = emits || m.emission.x > 0.0f || m.emission.y > 0.0f || m.emission.z > 0.0f;
  }
  if (!emits && scene.lights.empty()) {
    Light sky{};
    sky.type = kLightInfinite;
    sky.radiance = vec3(1.0f);
    scene.lights.push_back(sky);
  }
  return scene;
}

}  // namespace

Scene loadGltfSceneBytes(const std::string& bytes, const std::filesystem::path& path,
                         const SceneLoadOptions& options) {
  return build(parseDocument(bytes, path), path.string(), options);
}

Scene loadGltfScene(const std::filesystem::path& path, const SceneLoadOptions& options) {
  return build(readDocument(path), path.string(), options);
}

}  // namespace pt
