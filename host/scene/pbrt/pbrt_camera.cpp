// pbrt-v4's scene-wide options before WorldBegin: Camera, Film, PixelFilter, Sampler,
// Integrator, Accelerator, ColorSpace, Option; and the camera set up at WorldBegin.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <string>

#include <glm/geometric.hpp>

#include "common/check.h"
#include "common/named_values.h"
#include "scene/camera_filter.h"
#include "scene/json_reader.h"
#include "scene/pbrt/pbrt_builder.h"

namespace pt::pbrt {

constexpr int kMaxResolution = 16384;  // as the JSON reader: keeps width * height inside int

void Builder::options(Statement& s) {
  const std::string& d = s.directive;
  if (d == "ColorSpace") {
    if (s.strings[0] != "srgb") {
      warnOnce("ColorSpace", s.location,
               "ColorSpace " + singleQuoted(s.strings[0]) +
                   " ignored: RGB values are taken as linear sRGB (Rec. 709 primaries)");
    }
    return;
  }
  if (d == "Option") {
    if (s.strings[0] == "seed") {
      double seed = 0.0;
      const std::string& v = s.strings[1];
      char* end = nullptr;
      seed = std::strtod(v.c_str(), &end);
      if (end == v.c_str() || *end != '\0' || seed < 0 || seed > 4294967295.0 ||
          seed != std::floor(seed)) {
        fail(s.stringLocations[1],
             "Option \"seed\": expected an integer from 0 to 4294967295, got " + singleQuoted(v));
      }
      scene_.integrator.seed = static_cast<uint>(seed);
    } else {
      warnOnce("Option " + s.strings[0], s.location,
               "Option " + singleQuoted(s.strings[0]) + " ignored");
    }
    return;
  }
  requireOptions(s);
  const std::string& type = s.strings[0];
  Params p(*this, s, nullptr, d + " \"" + type + "\"");
  if (d == "Camera") {
    // pbrt-v4: the camera's transform is the CTM (camera from world) and "camera" names the
    // coordinate system of its inverse.
    cameraFromWorld_ = gs_.ctm;
    cameraLocation_ = s.location;
    // pbrt-v4: the camera is in the outside medium of the current MediumInterface.
    cameraInterface_ = gs_.mediumInterface;
    mediumInterfaces_[cameraInterface_].used = true;
    coordinateSystems_["camera"] = Xform{gs_.ctm.inverse, gs_.ctm.m};
    if (type != "perspective") {
      warnOnce("Camera", s.location,
               "Camera " + singleQuoted(type) +
                   " is rendered as a perspective camera (the only one simulated)");
      p.markAllUsed();
    }
    if (auto v = p.bounded("fov", 0.0, true, 180.0, true,
                           "a field of view in degrees strictly "
                           "between 0 and 180")) {
      fov_ = *v;
    }
    // A thin lens as pbrt-v4's: a radius of 0 (its default) or less is a pinhole.
    if (auto v = p.number("lensradius")) {
      if (!std::isfinite(static_cast<float>(*v))) {
        fail(p.find("lensradius")->location, "lensradius must be a finite number");
      }
      scene_.camera.lensRadius = static_cast<float>(std::max(0.0, *v));
    }
    if (auto v = p.number("focaldistance")) {
      const float rounded = static_cast<float>(*v);
      if (!(rounded > 0.0f) || !std::isfinite(rounded)) {
        fail(p.find("focaldistance")->location,
             "focaldistance must be a positive distance, got " + scene_detail::formatNumber(*v));
      }
      scene_.camera.focalDistance = rounded;
    }
    if (auto v = p.number("frameaspectratio")) {
      frameAspect_ = *v;
      if (!(*v > 0.0) || !std::isfinite(static_cast<float>(*v)))
        fail(p.find("frameaspectratio")->location, "frameaspectratio must be positive");
    }
    if (const Param* q = p.find("screenwindow", {ParamType::kFloat})) {
      p.expectCount(*q, 4);
      std::array<float, 4> w{};
      for (std::size_t i = 0; i < 4; ++i) {
        w[i] = static_cast<float>(q->numbers[i]);
        if (!std::isfinite(w[i])) fail(q->location, "screenwindow: the numbers must be finite");
      }
      if (!(w[0] != w[1] && w[2] != w[3])) {
        fail(q->location, "screenwindow [x0 x1 y0 y1] must have some width and height");
      }
      screenWindow_ = w;
    }
    p.number("shutteropen");
    p.number("shutterclose");
  } else if (d == "Film") {
    if (type != "rgb") {
      warnOnce("Film", s.location,
               "Film " + singleQuoted(type) + " is rendered as an RGB film (\"rgb\")");
    }
    const auto resolution = [&](const char* name, int* out) {
      if (auto v = p.integer(name)) {
        if (*v < 1 || *v > kMaxResolution) {
          fail(p.find(name)->location, std::string(name) + ": expected an integer from 1 to " +
                                           std::to_string(kMaxResolution) + ", got " +
                                           std::to_string(*v));
        }
        *out = *v;
      }
    };
    resolution("xresolution", &scene_.camera.width);
    resolution("yresolution", &scene_.camera.height);
    p.string("filename");  // the images are the command line's --out
    // The crop, as pbrt-v4's film takes it: "cropwindow" (fractions of the film, ordered and
    // clamped to [0, 1]) wins over "pixelbounds" (pixels [x0, x1) x [y0, y1), clipped to the
    // film); the image is the crop.
    const Param* crop = p.find("cropwindow", {ParamType::kFloat});
    const Param* bounds = p.find("pixelbounds", {ParamType::kInteger});
    if (crop != nullptr) {
      p.expectCount(*crop, 4);
      std::array<float, 4> c{};
      for (std::size_t i = 0; i < 4; ++i) {
        c[i] = static_cast<float>(crop->numbers[i]);
        if (!std::isfinite(c[i])) fail(crop->location, "cropwindow: the numbers must be finite");
      }
      scene_.camera.cropWindow = c;
      if (bounds != nullptr) {
        warnOnce("pixelbounds and cropwindow", bounds->location,
                 "Film: both \"pixelbounds\" and \"cropwindow\" given: the crop window is used "
                 "(as pbrt-v4 does)");
      }
    } else if (bounds != nullptr) {
      p.expectCount(*bounds, 4);
      std::array<int, 4> b{};
      for (std::size_t i = 0; i < 4; ++i) b[i] = static_cast<int>(bounds->numbers[i]);
      const int w = scene_.camera.width, h = scene_.camera.height;
      if (std::min(b[0], b[1]) < 0 || std::max(b[0], b[1]) > w || std::min(b[2], b[3]) < 0 ||
          std::max(b[2], b[3]) > h) {
        warnOnce("pixelbounds", bounds->location,
                 "Film: \"pixelbounds\" reach beyond the " + std::to_string(w) + "x" +
                     std::to_string(h) + " film: clipped to it (as pbrt-v4 does)");
      }
      scene_.camera.pixelBounds = b;
    }
    if (crop != nullptr || bounds != nullptr) {
      const std::array<int, 4> c =
          cropPixels(scene_.camera, scene_.camera.width, scene_.camera.height);
      if (!(c[1] > c[0] && c[3] > c[2])) {
        fail((crop != nullptr ? crop : bounds)->location,
             std::string(crop != nullptr ? "cropwindow" : "pixelbounds") +
                 " selects no pixel of the " + std::to_string(scene_.camera.width) + "x" +
                 std::to_string(scene_.camera.height) + " film");
      }
    }
    if (auto v = p.number("iso"); v && *v != 100.0) {
      warnOnce("iso", s.location, "Film: \"iso\" ignored: the image is not scaled by exposure");
    }
    if (auto v = p.number("whitebalance"); v && *v != 0.0) {
      warnOnce("whitebalance", s.location, "Film: \"whitebalance\" ignored");
    }
    if (auto v = p.string("sensor"); v && *v != "cie1931") {
      warnOnce("sensor", s.location, "Film: \"sensor\" ignored: the RGB is the scene's own");
    }
    if (auto v = p.number("maxcomponentvalue"); v && std::isfinite(*v)) {
      warnOnce("maxcomponentvalue", s.location,
               "Film: \"maxcomponentvalue\" ignored: samples are not clamped");
    }
    p.number("diagonal");
    p.boolean("savefp16");
  } else if (d == "PixelFilter") {
    // pbrt-v4's filters, parameters and defaults (its filters.cpp); "sinc" is not simulated.
    const uint filterType = type == "box"        ? kFilterBox
                            : type == "triangle" ? kFilterTriangle
                            : type == "gaussian" ? kFilterGaussian
                            : type == "mitchell" ? kFilterMitchell
                                                 : ~0u;
    if (filterType == ~0u) {
      if (type != "sinc") {
        fail(s.stringLocations[0], "unknown PixelFilter type " + singleQuoted(type) +
                                       " (pbrt-v4 has \"box\", \"gaussian\", \"mitchell\", "
                                       "\"sinc\" and \"triangle\")");
      }
      warnOnce("PixelFilter", s.location,
               "PixelFilter \"sinc\" is rendered with pbrt-v4's default filter, \"gaussian\" "
               "(the windowed sinc is not simulated)");
      p.markAllUsed();
      scene_.camera.filter = defaultFilter(kFilterGaussian);
    } else {
      PixelFilterDesc filter = defaultFilter(filterType);
      const auto readFloat = [&](const char* name, float& out) {
        if (auto v = p.number(name)) {
          out = static_cast<float>(*v);
          if (!std::isfinite(out)) {
            fail(p.find(name)->location, std::string(name) + " must be finite");
          }
        }
      };
      readFloat("xradius", filter.radiusX);
      readFloat("yradius", filter.radiusY);
      if (filterType == kFilterGaussian) readFloat("sigma", filter.sigma);
      if (filterType == kFilterMitchell) {
        readFloat("B", filter.b);
        readFloat("C", filter.c);
      }
      Camera check{};
      try {
        setFilterConstants(check, filter, "");
      } catch (const InputError& e) {
        fail(s.location, "PixelFilter " + singleQuoted(type) + ": " + e.what());
      }
      scene_.camera.filter = filter;
    }
  } else if (d == "Sampler") {
    if (type == "stratified") {
      const int x = p.integer("xsamples").value_or(4);
      const int y = p.integer("ysamples").value_or(4);
      if (x < 1 || y < 1)
        fail(s.location, "Sampler \"stratified\": xsamples and ysamples must be positive");
      scene_.integrator.spp = x * y;
      p.boolean("jitter");
    } else if (auto v = p.integer("pixelsamples")) {
      if (*v < 1)
        fail(p.find("pixelsamples")->location,
             "pixelsamples must be at least 1, got " + std::to_string(*v));
      scene_.integrator.spp = *v;
    }
    if (auto v = p.integer("seed")) {
      if (*v < 0) fail(p.find("seed")->location, "seed must not be negative");
      scene_.integrator.seed = static_cast<uint>(*v);
    }
    p.string("randomization");  // which scrambling: the noise's pattern, not the image
  } else if (d == "Integrator") {
    const bool known = type == "path" || type == "volpath" || type == "bdpt" || type == "sppm";
    if (!known) {
      warnOnce("Integrator", s.location,
               "Integrator " + singleQuoted(type) +
                   " is rendered with the path tracer (\"path\": light and BSDF sampling with "
                   "MIS)");
    }
    scene_.integrator.integrator = type == "bdpt"   ? kIntegratorBdpt
                                   : type == "sppm" ? kIntegratorSppm
                                                    : kIntegratorPath;
    if (type == "sppm") {
      // pbrt-v4's SPPMIntegrator::Create: its own parameters and its seed.
      SppmSettings& sppm = scene_.integrator.sppm;
      if (auto v = p.bounded("radius", 0.0, true, INFINITY, true, "a positive radius")) {
        sppm.radius = static_cast<float>(*v);
      }
      if (auto v = p.integer("photonsperiteration")) {
        if (*v == 0 || *v < -1) {
          fail(p.find("photonsperiteration")->location,
               "photonsperiteration must be positive, or -1 for one photon per pixel, got " +
                   std::to_string(*v));
        }
        sppm.photonsPerIteration = *v;
      }
      if (auto v = p.integer("seed")) {
        if (*v < 0) fail(p.find("seed")->location, "seed must not be negative");
        scene_.integrator.seed = static_cast<uint>(*v);
      }
    }
    if (type == "bdpt") {
      // pbrt-v4's debugging outputs: --strategy renders one strategy alone instead.
      for (const char* name : {"visualizestrategies", "visualizeweights"}) {
        if (auto v = p.boolean(name); v && *v) {
          warnOnce(name, s.location,
                   std::string("Integrator \"bdpt\": \"") + name +
                       "\" ignored (render one strategy with --strategy S,T)");
        }
      }
    }
    if (auto v = p.integer("maxdepth")) {
      if (*v < 0) fail(p.find("maxdepth")->location, "maxdepth must not be negative");
      scene_.integrator.maxDepth = *v;
    }
    if (auto v = p.boolean("regularize"); v && *v) {
      warnOnce("regularize", s.location, "Integrator: \"regularize\" ignored");
    }
    if (auto v = p.string("lightsampler")) {
      // pbrt-v4's light samplers (its "exhaustive" is not one of ours: an error, as an
      // unknown name is in pbrt-v4).
      const auto sampler = valueNamed(kLightSamplerNames, *v);
      if (!sampler) {
        fail(p.find("lightsampler")->location, "unknown light sampler " + singleQuoted(*v) +
                                                   " (expected " + quotedNames(kLightSamplerNames) +
                                                   ")");
      }
      scene_.integrator.lightSampler = *sampler;
    }
    if (!known) p.markAllUsed();
  } else if (d == "Accelerator") {
    p.markAllUsed();  // the BVH is this renderer's own: nothing to take from the file
  }
  p.reportUnused();
}

// The camera as CameraDesc describes it. pbrt's camera space is left-handed: its +x is the
// image's right where CameraDesc's right is forward x up, i.e. a camera placed by LookAt alone
// shows the mirror image of what this renderer's camera at the same place shows. Where the
// camera is so (the determinant of its axes is positive), the whole world is mirrored in x
// (geometry, normals and camera: `mirrored_`), which gives pbrt's image exactly; files that
// start with Scale -1 1 1 (Bitterli's, converted from Mitsuba) need no mirroring.
void Builder::setupCamera(const Location& where) {
  const Location& at = cameraLocation_.file.empty() ? where : cameraLocation_;
  const glm::dmat4& c = cameraFromWorld_.inverse;
  glm::dvec3 position = transformPoint(c, glm::dvec3(0.0));
  glm::dvec3 right(c[0]), up(c[1]), forward(c[2]);
  const double det = glm::dot(right, glm::cross(up, forward));
  if (!(std::isfinite(det) && det != 0.0)) {
    fail(at, "the camera transform (the CTM at Camera) is singular");
  }
  mirrored_ = det > 0.0;
  if (mirrored_) {
    position.x = -position.x;
    right.x = -right.x;
    up.x = -up.x;
    forward.x = -forward.x;
  }
  const double lr = glm::length(right), lu = glm::length(up), lf = glm::length(forward);
  const double tolerance = 1e-6;
  if (std::abs(lr - lf) > tolerance * lf || std::abs(lu - lf) > tolerance * lf ||
      std::abs(glm::dot(right, up)) > tolerance * lr * lu ||
      std::abs(glm::dot(right, forward)) > tolerance * lr * lf ||
      std::abs(glm::dot(up, forward)) > tolerance * lu * lf) {
    warnOnce("camera shear", at,
             "the camera transform has a shear or a non-uniform scale: the camera takes its "
             "position, view direction and up direction only");
  }
  forward /= lf;
  up /= lu;
  const double sine = glm::length(glm::cross(forward, up));
  if (!(sine > 1e-6)) fail(at, "the camera's up direction is parallel to its view direction");
  // The target one scene-size away, so that rounding it to float moves the direction least.
  const double reach = std::max(1.0, glm::length(position));
  CameraDesc& desc = scene_.camera;
  desc.position = vec3(position);
  desc.target = vec3(position + forward * reach);
  desc.up = vec3(up);
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(desc.position[i]) || !std::isfinite(desc.target[i])) {
      fail(at, "the camera position is beyond the range of 32-bit floats");
    }
  }
  if (glm::dvec3(desc.target) == glm::dvec3(desc.position)) {
    fail(at, "the camera's view direction is lost to float rounding");
  }
  // The lens in world units: camera space's scaled by the camera transform's (uniform) scale.
  desc.lensRadius = static_cast<float>(double(desc.lensRadius) * lf);
  desc.focalDistance = static_cast<float>(double(desc.focalDistance) * lf);
  if (!std::isfinite(desc.lensRadius) || !(desc.focalDistance > 0.0f) ||
      !std::isfinite(desc.focalDistance)) {
    fail(at, "the lens (lensradius, focaldistance) is beyond the range of 32-bit floats");
  }
  // pbrt-v4's screen window: [-frame, frame] x [-1, 1] for a landscape frame, [-1, 1] x
  // [-1/frame, 1/frame] for a portrait one, times tan(fov / 2), the frame being the film's
  // aspect unless "frameaspectratio" says otherwise; or "screenwindow" times tan(fov / 2).
  // CameraDesc's is in units of tan(vfov / 2): the fov spans the shorter axis, so vfov is fov
  // for a landscape frame and 2 atan(tan(fov / 2) / frame) for a portrait one, and both give
  // [-frame, frame, -1, 1]: with the film's aspect that is CameraDesc's default, which keeps
  // the window's shape when --width and --height change the film's. An explicit
  // "screenwindow" keeps vfov = fov and its own numbers.
  const double frame =
      frameAspect_.value_or(static_cast<double>(desc.width) / static_cast<double>(desc.height));
  if (screenWindow_) {
    desc.screenWindow = screenWindow_;
  } else if (frameAspect_) {
    const float f = static_cast<float>(frame);
    desc.screenWindow = std::array<float, 4>{-f, f, -1.0f, 1.0f};
  }
  double vfov = fov_;
  if (frame < 1.0 && !screenWindow_) {
    const double halfRadians = fov_ * (3.14159265358979323846 / 360.0);
    vfov = 2.0 * std::atan(std::tan(halfRadians) / frame) * (180.0 / 3.14159265358979323846);
  }
  const float rounded = static_cast<float>(vfov);
  if (!(rounded > 0.0f && rounded < 180.0f)) {
    fail(at, "the vertical field of view (" + scene_detail::formatNumber(vfov) +
                 " degrees) is not strictly between 0 and 180");
  }
  desc.vfovDegrees = rounded;
}

}  // namespace pt::pbrt
