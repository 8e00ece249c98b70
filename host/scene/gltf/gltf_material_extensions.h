// The KHR_materials_* extensions of a glTF material that the renderer simulates: _ior,
// _emissive_strength, _transmission, _volume, _clearcoat, _specular and _sheen (their factors;
// their textures: gltf_extension_textures.h), each checked and read into MaterialExtensions. Any
// other extension of the material is warned, once per kind.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "scene/gltf/gltf_context.h"
#include "scene/gltf/tinygltf.h"

#include "common/shared.h"

namespace pt::gltf {

// What the extensions say, their specifications' defaults where absent. flags: kGltf* for each
// extension that changes the BSDF (shared_types.h).
struct MaterialExtensions {
  double ior = 1.5;
  double emissiveStrength = 1.0;
  double transmission = 0.0;
  double thickness = 0.0;  // KHR_materials_volume's thicknessFactor: > 0 bounds a volume
  vec3 attenuationColour = vec3(1.0f);
  double attenuationDistance = std::numeric_limits<double>::infinity();
  double clearcoat = 0.0;
  double clearcoatRoughness = 0.0;
  double specular = 1.0;
  vec3 specularColour = vec3(1.0f);
  vec3 sheenColour = vec3(0.0f);  // KHR_materials_sheen: a colour of 0 is no sheen
  double sheenRoughness = 0.0;
  uint flags = 0;
  // The volume absorbs (attenuationDistance finite and attenuationColor below 1).
  bool absorbs() const;
};

MaterialExtensions readMaterialExtensions(const tinygltf::Material& m, const std::string& path,
                                          Context& context);

// A factor in [0, 1], else an InputError naming `where`.
double unitFactor(double value, const std::string& where, const Context& context);
// `expected` (3 or 4) numbers in [0, 1], the first three as a colour.
vec3 unitColour(const std::vector<double>& values, std::size_t expected, const std::string& where,
                const Context& context);

}  // namespace pt::gltf
