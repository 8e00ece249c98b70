// The builder's dispatch of each directive to its family's handler, and the end of the file:
// instances flattened, materials resolved, the Scene returned. The families are in pbrt_*.cpp.
#include "scene/pbrt/pbrt_builder.h"

#include <cstddef>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "common/check.h"
#include "scene/json_reader.h"
#include "scene/media.h"
#include "scene/reader_helpers.h"

namespace pt::pbrt {

void Builder::handle(Statement& s) {
  const std::string& d = s.directive;
  if (d == "Translate" || d == "Scale" || d == "Rotate" || d == "LookAt" || d == "Transform" ||
      d == "ConcatTransform" || d == "Identity" || d == "CoordinateSystem" ||
      d == "CoordSysTransform" || d == "ActiveTransform" || d == "TransformTimes") {
    transform(s);
  } else if (d == "Camera" || d == "Film" || d == "PixelFilter" || d == "Sampler" ||
             d == "Integrator" || d == "Accelerator" || d == "ColorSpace" || d == "Option") {
    options(s);
  } else if (d == "WorldBegin") {
    worldBegin(s);
  } else if (d == "WorldEnd") {
    // pbrt-v3's end of the world block: nothing to do (pbrt-v4 files end at their end).
  } else if (d == "AttributeBegin" || d == "TransformBegin" || d == "AttributeEnd" ||
             d == "TransformEnd" || d == "Attribute" || d == "ReverseOrientation") {
    attributes(s);
  } else if (d == "Material" || d == "MakeNamedMaterial") {
    requireWorld(s);
    material(s, d == "MakeNamedMaterial");
  } else if (d == "NamedMaterial") {
    requireWorld(s);
    gs_.material = MaterialRef{true, 0, s.strings[0], s.location};
  } else if (d == "Texture") {
    requireWorld(s);
    texture(s);
  } else if (d == "AreaLightSource") {
    requireWorld(s);
    areaLightSource(s);
  } else if (d == "LightSource") {
    requireWorld(s);
    lightSource(s);
  } else if (d == "Shape") {
    requireWorld(s);
    shape(s);
  } else if (d == "ObjectBegin") {
    requireWorld(s);
    objectBegin(s);
  } else if (d == "ObjectEnd") {
    requireWorld(s);
    objectEnd(s);
  } else if (d == "ObjectInstance") {
    requireWorld(s);
    objectInstance(s);
  } else if (d == "MakeNamedMedium") {
    makeNamedMedium(s);  // anywhere, as in pbrt-v4
  } else if (d == "MediumInterface") {
    mediumInterface(s);
  } else {
    PT_CHECK(false, "pbrt directive without a handler: " + d);
  }
}

Scene Builder::finish(const Location& end) {
  if (!inWorld_) fail(end, "the file ends before WorldBegin (a scene needs a world block)");
  const auto reportDropped = [&] {
    if (droppedShapes_ == 0) return;
    const auto plural = [](std::size_t n, const char* word) {
      return std::to_string(n) + " " + word + (n == 1 ? "" : "s");
    };
    scene_.warnings.push_back(
        firstDrop_ + ": dropped " + plural(droppedTriangles_, "zero-area triangle") + " in " +
        plural(droppedShapes_, "shape") + (droppedShapes_ > 1 ? " (this is the first)" : ""));
  };
  if (!stack_.empty()) {
    const Pushed& open = stack_.back();
    fail(open.location, open.directive + " without a matching " +
                            (open.kind == 'o'                     ? std::string("ObjectEnd")
                             : open.directive == "TransformBegin" ? std::string("TransformEnd")
                                                                  : std::string("AttributeEnd")));
  }
  // Object instances, flattened: each use copies the definition's triangles under its CTM.
  for (const InstanceUse& use : instanceUses_) {
    const auto it = instances_.find(use.name);
    if (it == instances_.end() || !it->second.defined) {
      std::vector<std::string_view> names;
      for (const auto& [name, instance] : instances_) names.push_back(name);
      fail(use.location, "ObjectInstance: no object named " + singleQuoted(use.name) +
                             scene_detail::didYouMean(use.name, names));
    }
    for (const InstanceShape& shape : it->second.shapes) {
      emit(transformMesh(shape.mesh, use.m), shape.slot, shape.mediumInterface, use.location,
           "ObjectInstance " + singleQuoted(use.name));
    }
  }
  reportDropped();
  // Media: each interface a shape took, by medium index; the camera's medium.
  const std::vector<MediumInterface> interfaces = resolveMedia();
  scene_.cameraMedium = interfaces[cameraInterface_].outside;
  // Materials: each slot resolved, and only the materials some triangle uses are kept. The
  // triangles of "interface" materials stay where they bound a medium (their two sides
  // differ), as surfaces of kMaterialInterface; the others change nothing and are dropped.
  std::vector<Material> materials(slots_.size());
  std::vector<std::string> names(slots_.size());
  std::vector<bool> isInterface(slots_.size(), false);
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    const MaterialDef& def = resolve(slots_[i].ref);
    if (def.kind == MaterialDef::Kind::kInterface) {
      isInterface[i] = true;
      materials[i] = defaultMaterial(kMaterialInterface);
      names[i] = def.label.empty() ? "interface" : def.label;
      if (slots_[i].emission) {
        warnOnce("interface area light", slots_[i].ref.location,
                 "an area light on shapes with the \"interface\" material is ignored, as "
                 "pbrt-v4 ignores it");
      }
      continue;
    }
    materials[i] = def.material;
    names[i] = def.label;
    if (slots_[i].emission) {
      materials[i].emission = *slots_[i].emission;
      materials[i].twoSided = slots_[i].twoSided ? 1u : 0u;
      names[i] += " + " + slots_[i].lightLabel;
    }
  }
  std::vector<bool> used(slots_.size(), false);
  std::size_t kept = 0;
  scene_.mediumInterfaces.resize(scene_.triangles.size());
  for (std::size_t i = 0; i < scene_.triangles.size(); ++i) {
    Triangle t = scene_.triangles[i];
    const MediumInterface mi = interfaces[triangleInterfaces_[i]];
    if (isInterface[t.material] && mi.inside == mi.outside) continue;
    used[t.material] = true;
    t.primitive = static_cast<uint>(kept);
    scene_.triangles[kept] = t;
    if (!scene_.normals.empty()) scene_.normals[kept] = scene_.normals[i];
    if (!scene_.uvs.empty()) scene_.uvs[kept] = scene_.uvs[i];
    scene_.mediumInterfaces[kept] = mi;
    ++kept;
  }
  scene_.triangles.resize(kept);
  if (!scene_.normals.empty()) scene_.normals.resize(kept);
  if (!scene_.uvs.empty()) scene_.uvs.resize(kept);
  scene_.mediumInterfaces.resize(kept);
  keepUsedMedia(scene_);  // none used: every media field empty, as before media existed
  std::vector<uint> remap(slots_.size(), 0);
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    if (!used[i]) continue;
    remap[i] = static_cast<uint>(scene_.materials.size());
    scene_.materials.push_back(materials[i]);
    scene_.materialNames.push_back(names[i]);
    MaterialTextures textures = resolve(slots_[i].ref).textures;
    textures.alpha = isInterface[i] ? kNoTexture : slots_[i].alpha;
    setMaterialTextures(scene_, scene_.materials.size() - 1, textures);
  }
  for (Triangle& t : scene_.triangles) t.material = remap[t.material];
  for (auto& [sphere, slot] : sphereLights_) {
    if (!used[slot] || isInterface[slot]) continue;  // no triangle emits
    sphere.material = remap[slot];
    scene_.lights.push_back(sphere);
  }
  if (scene_.triangles.empty()) {
    fail(end, "the scene has no triangles to render" +
                  (skippedShapes_ > 0
                       ? " (" + std::to_string(skippedShapes_) + " shapes were skipped or empty)"
                       : std::string()));
  }
  return std::move(scene_);
}

}  // namespace pt::pbrt
