// readMaterialExtensions (gltf_material_extensions.h).
#include "scene/gltf/gltf_material_extensions.h"

#include <cmath>
#include <string>
#include <vector>

#include "scene/reader_helpers.h"

namespace pt::gltf {

namespace {

// The object of an extension, checked.
const tinygltf::Value& extensionObject(const tinygltf::Value& object, const std::string& where,
                                       const Context& context) {
  if (!object.IsObject()) context.fail(where, "expected an object");
  return object;
}

// A number of an extension object, or `fallback` where it is absent.
double extensionNumber(const tinygltf::Value& object, const char* key, double fallback,
                       const std::string& where, const Context& context) {
  if (!object.Has(key)) return fallback;
  const tinygltf::Value& v = object.Get(key);
  if (!v.IsNumber() || !std::isfinite(v.GetNumberAsDouble())) {
    context.fail(where + "." + key, "expected a number");
  }
  return v.GetNumberAsDouble();
}

// Three non-negative numbers of an extension object (at most 1 where `unit`), or `fallback`.
vec3 extensionColour(const tinygltf::Value& object, const char* key, vec3 fallback, bool unit,
                     const std::string& where, const Context& context) {
  if (!object.Has(key)) return fallback;
  const tinygltf::Value& v = object.Get(key);
  const std::string at = where + "." + key;
  if (!v.IsArray() || v.ArrayLen() != 3) context.fail(at, "expected 3 numbers");
  vec3 c;
  for (int i = 0; i < 3; ++i) {
    const tinygltf::Value& e = v.Get(i);
    const double x = e.IsNumber() ? e.GetNumberAsDouble() : -1.0;
    if (!(x >= 0.0 && std::isfinite(x)) || (unit && x > 1.0)) {
      context.fail(at + "[" + std::to_string(i) + "]",
                   unit ? "expected a number in [0, 1]" : "expected a non-negative number");
    }
    c[i] = float(x);
  }
  return c;
}

}  // namespace

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

bool MaterialExtensions::absorbs() const {
  return std::isfinite(attenuationDistance) && attenuationColour != vec3(1.0f);
}

MaterialExtensions readMaterialExtensions(const tinygltf::Material& m, const std::string& path,
                                          Context& context) {
  MaterialExtensions e;
  bool volume = false;
  for (const auto& [name, value] : m.extensions) {
    const std::string where = path + ".extensions." + name;
    if (name == "KHR_materials_emissive_strength") {
      const tinygltf::Value& o = extensionObject(value, where, context);
      e.emissiveStrength = extensionNumber(o, "emissiveStrength", 1.0, where, context);
      if (!(e.emissiveStrength >= 0.0)) {
        context.fail(where + ".emissiveStrength", "must be at least 0");
      }
    } else if (name == "KHR_materials_ior") {
      e.ior = extensionNumber(extensionObject(value, where, context), "ior", 1.5, where, context);
      if (!(e.ior == 0.0 || e.ior >= 1.0)) context.fail(where + ".ior", "must be 0 or at least 1");
    } else if (name == "KHR_materials_transmission") {
      const tinygltf::Value& o = extensionObject(value, where, context);
      e.transmission = unitFactor(extensionNumber(o, "transmissionFactor", 0.0, where, context),
                                  where + ".transmissionFactor", context);
      e.flags |= kGltfTransmission;
    } else if (name == "KHR_materials_volume") {
      const tinygltf::Value& o = extensionObject(value, where, context);
      e.thickness = extensionNumber(o, "thicknessFactor", 0.0, where, context);
      if (!(e.thickness >= 0.0)) context.fail(where + ".thicknessFactor", "must be at least 0");
      e.attenuationDistance = extensionNumber(
          o, "attenuationDistance", std::numeric_limits<double>::infinity(), where, context);
      if (!(e.attenuationDistance > 0.0)) {
        context.fail(where + ".attenuationDistance", "must be greater than 0");
      }
      e.attenuationColour =
          extensionColour(o, "attenuationColor", vec3(1.0f), true, where, context);
      // thicknessTexture, like thicknessFactor's value, serves rasterizers: a path tracer has
      // the mesh itself (ignored by design, not warned, as occlusionTexture is).
      volume = true;
    } else if (name == "KHR_materials_clearcoat") {
      const tinygltf::Value& o = extensionObject(value, where, context);
      e.clearcoat = unitFactor(extensionNumber(o, "clearcoatFactor", 0.0, where, context),
                               where + ".clearcoatFactor", context);
      e.clearcoatRoughness =
          unitFactor(extensionNumber(o, "clearcoatRoughnessFactor", 0.0, where, context),
                     where + ".clearcoatRoughnessFactor", context);
      // Its textures, the coat's normal map among them: gltf_extension_textures.h.
      if (e.clearcoat > 0.0) e.flags |= kGltfClearcoat;
    } else if (name == "KHR_materials_specular") {
      const tinygltf::Value& o = extensionObject(value, where, context);
      e.specular = unitFactor(extensionNumber(o, "specularFactor", 1.0, where, context),
                              where + ".specularFactor", context);
      e.specularColour =
          extensionColour(o, "specularColorFactor", vec3(1.0f), false, where, context);
      e.flags |= kGltfSpecular;
    } else if (name == "KHR_materials_sheen") {
      const tinygltf::Value& o = extensionObject(value, where, context);
      e.sheenColour = extensionColour(o, "sheenColorFactor", vec3(0.0f), true, where, context);
      e.sheenRoughness = unitFactor(extensionNumber(o, "sheenRoughnessFactor", 0.0, where, context),
                                    where + ".sheenRoughnessFactor", context);
      // A colour of 0 (the default) is no sheen, whatever its texture holds.
      if (e.sheenColour != vec3(0.0f)) e.flags |= kGltfSheen;
    } else {
      context.warnOnce("extension " + name, where,
                       "not simulated (the material renders without it)");
    }
  }
  // KHR_materials_volume acts through the transmission alone; thickness 0 is thin-walled.
  if (volume && (e.flags & kGltfTransmission) != 0u && e.thickness > 0.0) {
    if (e.ior >= 1.0) {
      e.flags |= kGltfVolume;
    } else {
      context.warnOnce("volume ior 0", path + ".extensions.KHR_materials_volume",
                       "a volume of ior 0 does not refract: rendered thin-walled");
    }
  }
  return e;
}

}  // namespace pt::gltf
