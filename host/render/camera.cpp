// Builds the GPU camera (camera.h). The readers' checks of the same film are
// scene/camera_filter.h's.
#include "render/camera.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "common/check.h"
#include "differentials.h"
#include "scene/camera_filter.h"
#include "texture.h"

namespace pt {

Camera makeCamera(const CameraDesc& desc, int width, int height) {
  PT_CHECK(width > 0 && height > 0, "film size must be positive");
  // Double precision so that far-away or nearly-degenerate setups round only once.
  const glm::dvec3 position(desc.position);
  const glm::dvec3 forward = glm::normalize(glm::dvec3(desc.target) - position);
  const glm::dvec3 right = glm::normalize(glm::cross(forward, glm::dvec3(desc.up)));
  const glm::dvec3 up = glm::cross(right, forward);
  const double tanHalfFovY = std::tan(glm::radians(static_cast<double>(desc.vfovDegrees)) / 2.0);

  Camera camera{};
  camera.position = desc.position;
  camera.forward = glm::vec3(forward);
  camera.right = glm::vec3(right);
  camera.up = glm::vec3(up);
  camera.tanHalfFovY = static_cast<float>(tanHalfFovY);
  camera.aspect = static_cast<float>(static_cast<double>(width) / static_cast<double>(height));
  // The screen window: by default centred and tan(vfov / 2) high, so that windowCenter is
  // forward itself (the pinhole's rays of the renderer before screen windows, bit for bit).
  camera.windowCenter = camera.forward;
  if (desc.screenWindow) {
    const std::array<float, 4>& w = *desc.screenWindow;
    const double halfWidth = 0.5 * (double(w[1]) - double(w[0])) * tanHalfFovY;
    const double halfHeight = 0.5 * (double(w[3]) - double(w[2])) * tanHalfFovY;
    const double cx = 0.5 * (double(w[0]) + double(w[1])) * tanHalfFovY;
    const double cy = 0.5 * (double(w[2]) + double(w[3])) * tanHalfFovY;
    PT_CHECK(halfWidth != 0.0 && halfHeight != 0.0, "screen window of no area");
    camera.tanHalfFovY = static_cast<float>(halfHeight);
    camera.aspect = static_cast<float>(halfWidth / halfHeight);
    camera.windowCenter = glm::vec3(forward + cx * right + cy * up);
  }
  // The film, and the image: its crop.
  const std::array<int, 4> crop = cropPixels(desc, width, height);
  if (!(crop[1] > crop[0] && crop[3] > crop[2])) {
    throw InputError("the crop window selects no pixel of the " + std::to_string(width) + "x" +
                     std::to_string(height) + " film");
  }
  camera.filmWidth = static_cast<uint>(width);
  camera.filmHeight = static_cast<uint>(height);
  camera.cropX = static_cast<uint>(crop[0]);
  camera.cropY = static_cast<uint>(crop[2]);
  camera.width = static_cast<uint>(crop[1] - crop[0]);
  camera.height = static_cast<uint>(crop[3] - crop[2]);
  // The lens and the filter.
  camera.lensRadius = desc.lensRadius;
  camera.focalDistance = desc.focalDistance;
  setFilterConstants(camera, desc.filter, "camera");
  PT_CHECK(std::isfinite(camera.right.x + camera.right.y + camera.right.z + camera.forward.x +
                         camera.forward.y + camera.forward.z + camera.tanHalfFovY),
           "camera basis is degenerate (up parallel to the view direction?)");
  PT_CHECK(std::isfinite(camera.windowCenter.x + camera.windowCenter.y + camera.windowCenter.z +
                         camera.aspect + camera.tanHalfFovY),
           "screen window beyond the float range");
  return camera;
}

void setCameraDifferentials(RenderParams& params, int spp) {
  const Camera& cam = params.camera;
  const float infinity = std::numeric_limits<float>::infinity();
  vec3 minPosX(infinity), minPosY(infinity), minDirX(infinity), minDirY(infinity);
  constexpr int kPoints = 512;
  for (int i = 0; i < kPoints; ++i) {
    const vec2 film(float(i) / float(kPoints - 1) * float(cam.filmWidth),
                    float(i) / float(kPoints - 1) * float(cam.filmHeight));
    const vec3 direction = normalize(cameraFilmVector(cam, film));
    const RayDifferential rd =
        cameraRayDifferential(cam, film, vec3(0.0f), cam.position, direction, 1.0f);
    const vec3 dox = worldToCamera(cam, rd.rxOrigin - cam.position);
    const vec3 doy = worldToCamera(cam, rd.ryOrigin - cam.position);
    if (glm::length(dox) < glm::length(minPosX)) minPosX = dox;
    if (glm::length(doy) < glm::length(minPosY)) minPosY = doy;
    // The offset directions in the frame about the ray's (pbrt-v4's Frame::FromZ).
    const vec3 d = worldToCamera(cam, direction);
    vec3 x, y;
    coordinateSystem(d, x, y);
    const auto toLocal = [&](vec3 v) { return vec3(dot(v, x), dot(v, y), dot(v, d)); };
    const vec3 df = toLocal(d);
    const vec3 dxf = normalize(toLocal(worldToCamera(cam, normalize(rd.rxDirection))));
    const vec3 dyf = normalize(toLocal(worldToCamera(cam, normalize(rd.ryDirection))));
    if (glm::length(dxf - df) < glm::length(minDirX)) minDirX = dxf - df;
    if (glm::length(dyf - df) < glm::length(minDirY)) minDirY = dyf - df;
  }
  params.minPosDifferentialX = minPosX;
  params.minPosDifferentialY = minPosY;
  params.minDirDifferentialX = minDirX;
  params.minDirDifferentialY = minDirY;
  params.differentialScale = std::max(0.125f, 1.0f / std::sqrt(float(std::max(spp, 1))));
}

}  // namespace pt
