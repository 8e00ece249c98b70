// The JSON format's participating media (docs/scene-format.md, Media): the top-level "media"
// array with pbrt-v4's types, parameter names and defaults, and the medium names that shapes
// ("interior", "exterior") and the camera ("medium") give.
#pragma once

#include <map>
#include <string>
#include <string_view>

#include "common/shared.h"
#include "scene/json_reader.h"
#include "scene/scene.h"

namespace pt::scene_detail {

class JsonMedia {
 public:
  explicit JsonMedia(Scene& scene) : scene_(scene) {}

  // Reads the "media" array into scene.media and scene.mediumGrids, checking every medium.
  void read(const JsonNode& node);

  // The medium that `parent`'s key `key` names (a string), or kNoMedium where it has no such
  // key; an unknown name fails at the key.
  uint find(const JsonNode& parent, std::string_view key) const;

 private:
  Scene& scene_;
  std::map<std::string, uint, std::less<>> index_;
};

}  // namespace pt::scene_detail
