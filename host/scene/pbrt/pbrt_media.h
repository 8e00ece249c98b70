// pbrt-v4's media as the builder keeps them until the end of the file: the named media of
// MakeNamedMedium and the medium names of each MediumInterface, resolved at the end as pbrt-v4
// resolves them (so a name may be used before its definition). pbrt_media.cpp reads them.
#pragma once

#include <string>

#include "common/shared.h"
#include "scene/pbrt/pbrt_graphics_state.h"
#include "scene/pbrt/pbrt_parser.h"

namespace pt::pbrt {

// A MakeNamedMedium: its index in Scene::media, or kNoMedium for a type that is not simulated
// (left out: vacuum), and the CTM it was defined under (medium to world, pbrt-v4's
// renderFromMedium in world terms).
struct NamedMedium {
  uint index = kNoMedium;
  Location location;
  Xform worldFromMedium;
  // Defined before the Camera directive: pbrt-v4 then takes the CTM as its render space's, the
  // world moved to the camera's position (its default "cameraworld"), not the world's.
  bool beforeCamera = false;
};

// The names of one MediumInterface (both "" for the vacuum the file starts in), with where
// each was written; `used` once a shape or the camera takes it (only those are resolved).
struct MediumNames {
  std::string inside, outside;
  Location insideLocation, outsideLocation;
  bool used = false;
};

}  // namespace pt::pbrt
