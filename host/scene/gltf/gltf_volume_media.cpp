// addVolumeMedia (gltf_volume_media.h).
#include "scene/gltf/gltf_volume_media.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "scene/media.h"

namespace pt::gltf {

vec3 attenuationSigmaA(vec3 colour, double distance) {
  vec3 sigma;
  for (int i = 0; i < 3; ++i) {
    sigma[i] = float(-std::log(std::max(double(colour[i]), 1e-6)) / distance);
  }
  return sigma;
}

void addVolumeMedia(const std::vector<MaterialExtensions>& extensions, Scene& scene) {
  std::vector<uint> mediumOf(scene.materials.size(), kNoMedium);
  bool any = false;
  for (std::size_t i = 0; i < extensions.size() && i < scene.materials.size(); ++i) {
    const MaterialExtensions& e = extensions[i];
    if ((e.flags & kGltfVolume) == 0u || !e.absorbs()) continue;
    MediumParams p;
    p.type = kMediumHomogeneous;
    p.sigmaA = attenuationSigmaA(e.attenuationColour, e.attenuationDistance);
    p.sigmaS = vec3(0.0f);
    mediumOf[i] = addMedium(scene, "volume of " + scene.materialNames[i], p);
    any = true;
  }
  if (!any) return;
  scene.mediumInterfaces.assign(scene.triangles.size(), MediumInterface{kNoMedium, kNoMedium});
  for (std::size_t t = 0; t < scene.triangles.size(); ++t) {
    scene.mediumInterfaces[t].inside = mediumOf[scene.triangles[t].material];
  }
  keepUsedMedia(scene);
}

}  // namespace pt::gltf
