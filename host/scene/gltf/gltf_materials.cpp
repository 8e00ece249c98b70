// readMaterial (gltf_materials.h).
#include "scene/gltf/gltf_materials.h"

#include <cmath>
#include <string>
#include <vector>

#include "scene/reader_helpers.h"

namespace pt::gltf {

namespace {

// Extensions of materials that the mapping reads; any other is warned.
bool isReadExtension(const std::string& name) {
  return name == "KHR_materials_emissive_strength" || name == "KHR_materials_ior";
}

double unitFactor(double value, const std::string& where, const Context& context) {
  if (!(value >= 0.0 && value <= 1.0)) {
    context.fail(where, scene_detail::formatNumber(value) + " is not in [0, 1]");
  }
  return value;
}

vec3 unitColour(const std::vector<double>& values, std::size_t expected, const std::string& where,
                const Context& context) {
  if (values.size() != expected) {
    context.fail(where, "expected " + std::to_string(expected) + " numbers, got " +
                            std::to_string(values.size()));
  }
  vec3 c;
  for (int i = 0; i < 3; ++i) c[i] = float(unitFactor(values[std::size_t(i)], where, context));
  if (expected == 4) unitFactor(values[3], where, context);
  return c;
}

// A number of an extension object, or `fallback` where it is absent.
double extensionNumber(const tinygltf::Value& object, const char* key, double fallback,
                       const std::string& where, const Context& context) {
  if (!object.IsObject()) context.fail(where, "expected an object");
  if (!object.Has(key)) return fallback;
  const tinygltf::Value& v = object.Get(key);
  if (!v.IsNumber() || !std::isfinite(v.GetNumberAsDouble())) {
    context.fail(where + "." + key, "expected a number");
  }
  return v.GetNumberAsDouble();
}

}  // namespace

Material readMaterial(const tinygltf::Model& model, int index, Context& context) {
  // The specification's default material (its pbrMetallicRoughness defaults).
  vec3 baseColour(1.0f);
  double metallic = 1.0, roughness = 1.0, ior = 1.5;
  vec3 emission(0.0f);
  bool doubleSided = false;
  if (index >= 0) {
    if (std::size_t(index) >= model.materials.size()) {
      context.fail("", "material " + std::to_string(index) + " out of range");  // caller checks
    }
    const std::string path = indexed("materials", std::size_t(index));
    const tinygltf::Material& m = model.materials[std::size_t(index)];
    const tinygltf::PbrMetallicRoughness& pbr = m.pbrMetallicRoughness;
    const std::string pbrPath = path + ".pbrMetallicRoughness";
    baseColour = unitColour(pbr.baseColorFactor, 4, pbrPath + ".baseColorFactor", context);
    metallic = unitFactor(pbr.metallicFactor, pbrPath + ".metallicFactor", context);
    roughness = unitFactor(pbr.roughnessFactor, pbrPath + ".roughnessFactor", context);
    emission = unitColour(m.emissiveFactor, 3, path + ".emissiveFactor", context);
    doubleSided = m.doubleSided;
    if (m.alphaMode != "OPAQUE" && m.alphaMode != "MASK" && m.alphaMode != "BLEND") {
      context.fail(path + ".alphaMode", "'" + m.alphaMode + "' is not OPAQUE, MASK or BLEND");
    }
    if (!(m.alphaCutoff >= 0.0)) context.fail(path + ".alphaCutoff", "must be at least 0");
    // The textures and the alpha mode: gltf_material_textures.h. occlusionTexture: ambient
    // occlusion is what path tracing computes; ignored by design.
    for (const auto& [name, value] : m.extensions) {
      const std::string where = path + ".extensions." + name;
      if (name == "KHR_materials_emissive_strength") {
        const double strength = extensionNumber(value, "emissiveStrength", 1.0, where, context);
        if (!(strength >= 0.0)) context.fail(where + ".emissiveStrength", "must be at least 0");
        emission *= float(strength);
      } else if (name == "KHR_materials_ior") {
        ior = extensionNumber(value, "ior", 1.5, where, context);
        if (!(ior == 0.0 || ior >= 1.0)) context.fail(where + ".ior", "must be 0 or at least 1");
      } else if (!isReadExtension(name)) {
        context.warnOnce("extension " + name, where,
                         "not simulated (the material renders without it)");
      }
    }
  }
  // Material's fields for glTF's material: shaders/bsdf.h (kMaterialGltf).
  Material out{};
  out.type = kMaterialGltf;
  out.reflectance = baseColour;
  out.eta = vec3(float(ior), 0.0f, 0.0f);
  const float alpha = float(roughness * roughness);
  setRoughness(out, alpha, alpha, false);
  out.thickness = float(metallic);
  out.emission = emission;
  out.twoSided = doubleSided ? 1u : 0u;
  return out;
}

}  // namespace pt::gltf
