// The pbrt-v4 reader's entry points: the parser (pbrt_parser.h) feeding the builder
// (pbrt_builder.h) statement by statement.
#include "scene/pbrt/pbrt_scene.h"

#include <algorithm>
#include <cstddef>
#include <functional>
#include <string>
#include <utility>

#include "scene/json_reader.h"
#include "scene/pbrt/pbrt_builder.h"
#include "scene/pbrt/pbrt_parser.h"

namespace pt {

namespace fs = std::filesystem;

namespace {

using pbrt::Builder;
using pbrt::Location;
using pbrt::parseText;
using pbrt::Statement;
using pbrt::StatementHandler;

Scene build(const std::function<void(const StatementHandler&)>& parse, const fs::path& path,
            std::size_t lines, const SceneLoadOptions& options) {
  Builder builder(path, options.strict);
  parse([&](Statement& s) { builder.handle(s); });
  return builder.finish(Location{path.string(), static_cast<int>(lines), 1});
}

std::size_t lineCount(const std::string& text) {
  return 1 + static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n'));
}

}  // namespace

Scene loadPbrtSceneText(std::string text, const fs::path& path, const SceneLoadOptions& options) {
  const std::size_t lines = lineCount(text);
  return build([&](const StatementHandler& h) { parseText(std::move(text), path, h); }, path, lines,
               options);
}

Scene loadPbrtScene(const fs::path& path, const SceneLoadOptions& options) {
  std::string text, why;
  if (!scene_detail::readTextFile(path, &text, &why)) {
    scene_detail::throwInputError(path.string(), "", "cannot open scene file (" + why + ")");
  }
  return loadPbrtSceneText(std::move(text), path, options);
}

}  // namespace pt
