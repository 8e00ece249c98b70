// The media of a scene as the backends read them (shaders/medium.h): the media in world space
// after the scene's shift, their grids with a majorant grid each, the media on the sides of
// every triangle, and the camera's medium.
#pragma once

#include "render/prepare.h"

namespace pt {

// Moves the scene's media into `data` (media, mediumGrids, mediumInterfaces; params'
// cameraMedium and mediaPresent; effects.media). `shift` is what recentring subtracted from
// every point of the scene. Nothing changes for a scene without media.
void prepareMedia(Scene& scene, vec3 shift, SceneData& data);

// The majorant grid of grid medium m over its floats `grids` (kMajorantGridRes^3 values, x
// fastest): per cell, the largest coefficient the trilinear interpolation reaches there, in
// units of what MajorantWalk::sigmaMaj multiplies (uniformgrid: the density; rgbgrid: the
// largest sigma_t of any channel).
std::vector<float> majorantGrid(const Medium& m, const std::vector<float>& grids);

}  // namespace pt
