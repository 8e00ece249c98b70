// readMaterial (gltf_materials.h).
#include "scene/gltf/gltf_materials.h"

#include <string>

#include "gltf_material_fields.h"
#include "scene/reader_helpers.h"

namespace pt::gltf {

Material readMaterial(const tinygltf::Model& model, int index, Context& context,
                      MaterialExtensions* extensions) {
  // The specification's default material (its pbrMetallicRoughness defaults).
  vec3 baseColour(1.0f);
  double metallic = 1.0, roughness = 1.0;
  vec3 emission(0.0f);
  bool doubleSided = false;
  MaterialExtensions ext;
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
    ext = readMaterialExtensions(m, path, context);
    emission *= float(ext.emissiveStrength);
  }
  // Material's fields for glTF's material: shaders/bsdf.h (kMaterialGltf).
  Material out{};
  out.type = kMaterialGltf;
  out.reflectance = baseColour;
  out.eta = vec3(float(ext.ior), 0.0f, 0.0f);
  const float alpha = float(roughness * roughness);
  setRoughness(out, alpha, alpha, false);
  out.thickness = float(metallic);
  out.emission = emission;
  out.twoSided = doubleSided ? 1u : 0u;
  if (ext.flags != 0u) {
    // The extensions' fields (shaders/bsdf.h, gltfLayersOf); a material without keeps them 0.
    out.nSamples = ext.flags;
    out.transmittance = vec3(float(ext.transmission), float(ext.clearcoat),
                             float(ext.clearcoatRoughness * ext.clearcoatRoughness));
    out.k = ext.specularColour;
    out.eta.y = float(ext.specular);
    if ((ext.flags & kGltfSheen) != 0u) {
      out = gltfWithSheenRoughness(gltfWithSheenColour(out, ext.sheenColour),
                                   float(ext.sheenRoughness));
    }
  }
  if (extensions) *extensions = ext;
  return out;
}

}  // namespace pt::gltf
