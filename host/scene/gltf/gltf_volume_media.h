// KHR_materials_volume's attenuation as the renderer's participating media (docs/media.md): the
// triangles of a material whose volume absorbs bound a homogeneous medium that only absorbs,
// sigma_a = -ln(attenuationColor) / attenuationDistance per channel, inside the mesh (behind
// the front faces), vacuum outside.
#pragma once

#include <vector>

#include "scene/gltf/gltf_context.h"
#include "scene/gltf/gltf_material_extensions.h"
#include "scene/scene.h"

namespace pt::gltf {

// `extensions` parallel to scene.materials. Adds one medium per absorbing material whose
// transmission refracts, and the interfaces of its triangles; a scene without such a
// material is left as it is (no media).
void addVolumeMedia(const std::vector<MaterialExtensions>& extensions, Scene& scene);

// The absorption coefficient of an attenuation colour and distance (a colour channel of 0,
// which no distance passes, as 1e-6 of it).
vec3 attenuationSigmaA(vec3 colour, double distance);

}  // namespace pt::gltf
