// pbrt-v4's materials and textures as the builder keeps them until the end of the file:
// definitions (inline, named, mix, interface), the scene's material slots, Texture directives.
// Reading their parameters is pbrt_materials.cpp's, pbrt_textures.cpp's and
// pbrt_spectrum_params.cpp's.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "common/shared.h"
#include "scene/pbrt/pbrt_graphics_state.h"
#include "scene/pbrt/pbrt_parser.h"
#include "scene/textures.h"

namespace pt::pbrt {

// How a spectrum parameter is used: pbrt-v4's SpectrumType. Spectra become RGB accordingly
// (host/scene/pbrt/spectra.h): a reflectance as its colour under D65, a light's emission
// normalized to luminance 1, an index as its per-channel average.
enum class Use { kAlbedo, kUnbounded, kIlluminant };

// A material as defined; a mix or an interface until resolved.
struct MaterialDef {
  enum class Kind { kSurface, kInterface, kMix };
  Kind kind = Kind::kSurface;
  Material material{};
  std::string label;
  Location location;
  std::array<std::string, 2> mix;                    // kMix: the named materials
  Location mixLocation;                              // of "string materials"
  double amount = 0.5;                               // kMix: pbrt-v4's probability of the second
  MaterialTextures textures = noMaterialTextures();  // parameters given by textures
};

// A scene material: a reference to a definition, with an area light's emission for the
// shapes that have one (each such shape gets its own).
struct Slot {
  MaterialRef ref;
  std::optional<vec3> emission;
  std::string lightLabel;
  bool twoSided = false;    // the emission leaves both sides
  uint alpha = kNoTexture;  // the shapes' "alpha" (a cut-out), a texture
};

struct Texture {
  std::string className;
  std::vector<Param> params;
  Location location;
};

}  // namespace pt::pbrt
