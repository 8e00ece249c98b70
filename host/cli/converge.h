// `pt converge`: the command line around host/converge (error against time as samples
// double), writing a CSV that tools/accuracy.sh turns into docs/accuracy.md.
#pragma once

#include <string>

#include "cli/overrides.h"

namespace pt {

// The command line's arguments; empty strings and negative numbers mean "the scene's".
struct ConvergeArgs {
  std::string scene, reference, csv, label = "default";
  std::string backend = "vulkan", device;
  SceneOverrides overrides;
  int maxSpp = 256, threads = 0;
  bool noSpecialize = false;
};

// Loads the scene and the reference, runs the levels, writes the CSV (header
// `label,backend,scene,width,height,spp,seconds,rmse,relmse,mrays_per_s`, one row per level,
// flushed as it comes) and prints a table. Returns the exit status (1 if samples were
// invalid); throws InputError for bad input.
int runConvergeCommand(const ConvergeArgs& args);

}  // namespace pt
