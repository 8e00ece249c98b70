// `pt converge`: the command line around host/converge; see cli/converge.h.
#include "cli/converge.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "cli/progress.h"
#include "common/check.h"
#include "converge/converge.h"
#include "scene/load_scene.h"
#include "scene/scene.h"

namespace pt {

int runConvergeCommand(const ConvergeArgs& args) {
  // Everything the user gave is checked before any time is spent rendering.
  if (args.label.find_first_of(",\"\n\r") != std::string::npos) {
    throw InputError("--label: must not contain commas, quotes or line breaks, got '" + args.label +
                     "'");
  }
  if (args.noSpecialize && args.backend != "vulkan") {
    throw InputError("--no-specialize applies to the Vulkan backend only");
  }
  if (imageFormatOf(args.reference) == ImageFormat::kPng) {
    throw InputError(args.reference + ": the reference must be a float image (.exr or .pfm)");
  }
  Scene scene = loadScene(args.scene);
  for (const std::string& w : scene.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());

  // The same overrides as `pt render`.
  const RenderSettings settings = args.overrides.toSettings(args.backend);
  const SceneData data = prepareScene(std::move(scene), settings);
  if (data.integrator == kIntegratorSppm) {
    throw InputError(args.scene +
                     ": converge adds samples to a render, which the sppm integrator's "
                     "iterations cannot (render each count with pt render instead)");
  }
  const Camera& cam = data.params.camera;

  const Image reference = readImage(args.reference);
  try {
    checkReference(reference, cam);
  } catch (const InputError& e) {
    throw InputError(args.reference + ": " + e.what());
  }
  std::ofstream csv(args.csv, std::ios::trunc);
  if (!csv) throw InputError(args.csv + ": cannot open for writing");
  csv << "label,backend,scene,width,height,spp,seconds,rmse,relmse,mrays_per_s\n" << std::flush;

  const std::string sceneName = std::filesystem::path(args.scene).stem().string();
  std::printf("converge %s backend=%s%s %ux%u label=%s\n", sceneName.c_str(), args.backend.c_str(),
              args.noSpecialize ? " (unspecialized)" : "", cam.width, cam.height,
              args.label.c_str());
  std::printf("%7s %10s %11s %11s %9s\n", "spp", "seconds", "rmse", "relmse", "Mrays/s");

  ConvergeOptions options;
  options.backend = args.backend;
  options.device = args.device;
  options.maxSpp = args.maxSpp;
  options.threads = args.threads;
  options.specialize = !args.noSpecialize;
  options.onRow = [&](const ConvergeRow& r) {
    // Default stream precision: 6 significant digits, like %g.
    csv << args.label << ',' << args.backend << ',' << sceneName << ',' << cam.width << ','
        << cam.height << ',' << r.spp << ',' << r.seconds << ',' << r.rmse << ',' << r.relMse << ','
        << r.mraysPerSecond << '\n'
        << std::flush;  // a run cut short keeps the levels it finished
    std::printf("%7d %10.4f %11.5g %11.5g %9.3f\n", r.spp, r.seconds, r.rmse, r.relMse,
                r.mraysPerSecond);
    std::fflush(stdout);
  };
  const std::vector<ConvergeRow> rows = runConvergence(data, reference, options);
  if (!csv) throw InputError(args.csv + ": write failed");

  const ConvergeRow& last = rows.back();
  if (last.invalidSamples > 0) {
    printInvalidSamples(last.invalidSamples, last.truncatedSamples);
    return kExitFailure;
  }
  return kExitOk;
}

}  // namespace pt
