// Film states on the command line: the settings that determine a render's image (what
// resume and merge compare), `--samples FIRST:COUNT`, and the `merge` command.
#pragma once

#include <string>
#include <vector>

#include "image/film_state.h"
#include "render/prepare.h"

namespace pt {

// The settings that determine the image's bits, by name, so that a mismatch can be named:
// backend, resolution, seed, depth, roulette, strategy, sampler, intersection test, BVH
// builder and leaf size, and hashes of the camera, of the scene's content (triangles in
// load order, materials) and of the BVH (nodes, triangle order, emitter table). `backendExtra`
// is what the backend adds (vulkanImageSettings).
KeyValues imageSettings(const SceneData& data, const RenderSettings& settings,
                        const std::string& backend, const KeyValues& backendExtra);

// "FIRST:COUNT" (both unsigned, COUNT > 0, the range within 32-bit sample indices); an
// InputError naming `option` otherwise.
SampleRange parseSampleRange(const std::string& text, const std::string& option);

// The extension that makes `--out` write a film state instead of an image.
inline constexpr const char* kStateExtension = ".ptstate";
bool isStatePath(const std::string& path);

struct MergeArgs {
  std::vector<std::string> states;
  std::vector<std::string> outputs;  // images, or film states (.ptstate)
  bool partial = false;              // merge even when sample indices are missing
};

// `pt merge`: combines the states, names missing samples (refused without --partial),
// writes the outputs and prints one line of statistics.
int runMerge(const MergeArgs& args);

}  // namespace pt
