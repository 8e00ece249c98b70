// The GPU camera (shared.h's Camera) from a scene's CameraDesc for the film being rendered;
// the crop and filter maths it uses is scene/camera_filter.h's.
#pragma once

#include "common/shared.h"
#include "scene/scene.h"

namespace pt {

// Builds the GPU camera for a film of width x height pixels: the image is the crop of it (the
// whole film without a crop window). Throws InputError when the crop selects no pixel of that
// film (the readers check the file's own film; --width and --height can make another).
Camera makeCamera(const CameraDesc& desc, int width, int height);

// The camera's smallest ray differentials, which stand in for a ray's own where it has none
// (differentials.h's approximateDpdxy), and their scale for a render of spp samples per pixel:
// pbrt-v4's CameraBase::FindMinimumDifferentials (512 film points along the film's diagonal,
// through the lens's centre) and max(1/8, 1/sqrt(spp)). Sets them in params.
void setCameraDifferentials(RenderParams& params, int spp);

}  // namespace pt
