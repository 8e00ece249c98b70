// pbrt-v4's AreaLightSource and LightSource (its lights.cpp Create functions): point, spot,
// distant and infinite lights (constant or an image). The emitting shapes are pbrt_shapes.cpp's.
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>

#include <glm/geometric.hpp>

#include "common/check.h"
#include "environment.h"
#include "image/image.h"
#include "scene/json_reader.h"
#include "scene/pbrt/pbrt_builder.h"

namespace pt::pbrt {

namespace fs = std::filesystem;

void Builder::areaLightSource(Statement& s) {
  const std::string& type = s.strings[0];
  if (type != "diffuse") {
    fail(s.stringLocations[0],
         "unknown area light type " + singleQuoted(type) + " (pbrt-v4 has only \"diffuse\")");
  }
  Params p(*this, s, &gs_.lightAttributes, "AreaLightSource \"diffuse\"");
  AreaLight light;
  light.location = s.location;
  if (auto L = spectrum(p, "L", Use::kIlluminant)) light.radiance = *L;
  if (auto v = p.number("scale")) light.scale = *v;
  if (auto v = p.number("power")) light.power = *v;
  light.twoSided = p.boolean("twosided").value_or(false);
  if (auto f = p.string("filename")) {
    warnOnce("area light image", s.location,
             "AreaLightSource \"diffuse\": \"filename\" ignored (image lights are later work): "
             "it emits \"L\"");
  }
  if (!(light.scale >= 0.0) || !std::isfinite(light.scale)) {
    fail(p.find("scale")->location, "AreaLightSource \"diffuse\": scale must not be negative");
  }
  p.reportUnused();
  gs_.areaLight = light;
}

// pbrt-v4's point, spot, distant and infinite lights (lights.cpp's Create functions): the
// same parameters and defaults, "scale", "power" and "illuminance" as it applies them. Light
// spectra come as RGB normalized as pbrt-v4 normalizes them (an RGB light keeps its RGB), so
// its division of the scale by SpectrumToPhotometric is already done. Positions and
// directions go through the CTM, and through the camera's mirror (see setupCamera).
void Builder::lightSource(Statement& s) {
  const std::string& type = s.strings[0];
  const std::string context = "LightSource " + singleQuoted(type);
  Params p(*this, s, &gs_.lightAttributes, context);
  if (type != "point" && type != "spot" && type != "distant" && type != "infinite") {
    p.markAllUsed();
    if (type != "goniometric" && type != "projection") {
      fail(s.stringLocations[0], "unknown light type " + singleQuoted(type) +
                                     " (pbrt-v4 has \"point\", \"spot\", \"goniometric\", "
                                     "\"projection\", \"distant\" and \"infinite\")");
    }
    warnOnce("LightSource " + type, s.location,
             context + " ignored: " + type +
                 " lights (an image over the directions) are not "
                 "simulated");
    return;
  }
  constexpr double kPi = 3.14159265358979323846;
  double scale = p.number("scale").value_or(1.0);
  if (!(scale >= 0.0) || !std::isfinite(scale)) {
    fail(p.find("scale")->location, context + ": \"scale\" must not be negative");
  }
  // A positive "power" or "illuminance" sets the scale that gives it (pbrt-v4 ignores <= 0).
  const auto target = [&](const char* name) -> std::optional<double> {
    const auto v = p.number(name);
    if (v && !std::isfinite(*v)) fail(p.find(name)->location, context + ": bad " + name);
    return v && *v > 0.0 ? v : std::nullopt;
  };
  const auto point3 = [&](const char* name, glm::dvec3 fallback) {
    const Param* q = p.find(name, {ParamType::kPoint3});
    if (q == nullptr) return fallback;
    p.expectCount(*q, 1, 3);
    return glm::dvec3(q->numbers[0], q->numbers[1], q->numbers[2]);
  };
  const glm::dmat4& m = gs_.ctm.m;
  const auto worldPoint = [&](glm::dvec3 v) {
    glm::dvec3 w = transformPoint(m, v);
    if (mirrored_) w.x = -w.x;
    return w;
  };
  // A unit direction in world space; fails where the transform or the points leave none.
  const auto worldDirection = [&](glm::dvec3 v, const char* what) {
    glm::dvec3 w = glm::dmat3(m) * v;
    if (mirrored_) w.x = -w.x;
    const double length = glm::length(w);
    if (!(length > 0.0) || !std::isfinite(length)) {
      fail(s.location, context + ": " + what +
                           " has no direction (\"from\" equals \"to\", or "
                           "the transform is singular)");
    }
    return w / length;
  };

  Light light{};
  vec3 emitted(1.0f);  // the colour space's illuminant: white
  double k = 1.0;      // pbrt-v4's k_e where power or illuminance is given
  std::optional<double> wanted;
  if (type == "point" || type == "spot") {
    if (auto I = spectrum(p, "I", Use::kIlluminant)) emitted = *I;
    const glm::dvec3 from = point3("from", glm::dvec3(0.0));
    light.position = vec3(worldPoint(from));
    wanted = target("power");
    if (type == "point") {
      light.type = kLightPoint;
      k = 4.0 * kPi;
    } else {
      light.type = kLightSpot;
      const double cone = p.number("coneangle").value_or(30.0);
      const double delta = p.number("conedeltaangle").value_or(5.0);
      if (!std::isfinite(cone) || !std::isfinite(delta)) {
        fail(s.location, context + ": the cone angles must be finite");
      }
      const double cosEnd = std::cos(cone * kPi / 180.0);
      const double cosStart = std::cos((cone - delta) * kPi / 180.0);
      light.cosFalloffEnd = static_cast<float>(cosEnd);
      light.cosFalloffStart = static_cast<float>(cosStart);
      light.direction = vec3(worldDirection(point3("to", glm::dvec3(0, 0, 1)) - from, "the spot"));
      k = 2.0 * kPi * ((1.0 - cosStart) + (cosStart - cosEnd) / 2.0);
    }
  } else if (type == "distant") {
    light.type = kLightDistant;
    if (auto L = spectrum(p, "L", Use::kIlluminant)) emitted = *L;
    const glm::dvec3 from = point3("from", glm::dvec3(0.0));
    const glm::dvec3 to = point3("to", glm::dvec3(0, 0, 1));
    light.direction = vec3(worldDirection(from - to, "the distant light"));
    wanted = target("illuminance");  // pbrt-v4: k_e = 1 (illuminance at normal incidence)
  } else {
    light.type = kLightInfinite;
    if (auto L = spectrum(p, "L", Use::kIlluminant)) emitted = *L;
    if (const Param* portal = p.find("portal")) {
      warnOnce("portal", portal->location,
               context +
                   ": \"portal\" ignored (it only guides "
                   "sampling in pbrt-v4)");
    }
    wanted = target("illuminance");
    k = kPi;
    if (auto file = p.string("filename")) {
      if (p.find("L")) {
        fail(p.find("L")->location, context + ": \"L\" and \"filename\" exclude each other");
      }
      imageInfiniteLight(p, *file, scale, wanted, context);
      p.reportUnused();
      return;
    }
  }
  if (wanted) scale *= *wanted / k;
  const glm::dvec3 radiance = glm::dvec3(emitted) * scale;
  for (int c = 0; c < 3; ++c) {
    if (!(static_cast<float>(radiance[c]) < std::numeric_limits<float>::infinity())) {
      fail(s.location, context + ": the emission (times its scale) does not fit a 32-bit float");
    }
  }
  light.radiance = vec3(radiance);
  p.reportUnused();
  scene_.lights.push_back(light);
}

// pbrt-v4's ImageInfiniteLight: an equal-area octahedral square image (its frame the CTM's
// rotation, +z in the image's centre), its radiance the nearest texel times `scale`, or scaled
// so that the upper hemisphere's illuminance (`wanted`) comes out as pbrt-v4 computes it.
void Builder::imageInfiniteLight(Params& p, const std::string& file, double scale,
                                 std::optional<double> wanted, const std::string& context) {
  const Param* f = p.find("filename");
  if (scene_.environment) {
    fail(f->location, context + ": a second image infinite light (one per scene is supported)");
  }
  const fs::path path = resolvePath(file, f->location, mainFile_);
  EnvironmentImage env;
  env.file = path.string();
  try {
    env.image = readImage(path);
  } catch (const InputError& e) {
    fail(f->location, context + ": " + e.what());
  }
  const Image& image = env.image;
  if (image.width != image.height) {
    fail(f->location, context + ": " + singleQuoted(file) + " is " + std::to_string(image.width) +
                          "x" + std::to_string(image.height) +
                          ", not square: pbrt-v4 takes only equal-area octahedral (square) "
                          "environment images");
  }
  for (const vec3& c : image.pixels) {
    if (!std::isfinite(c.x) || !std::isfinite(c.y) || !std::isfinite(c.z)) {
      fail(f->location, context + ": " + singleQuoted(file) +
                            " has infinite or not-a-number pixels, no use as a light");
    }
  }
  if (wanted) {
    // pbrt-v4's illuminance of the map over its upper hemisphere (z > 0 in the light's frame),
    // its texels' luminance times cos theta, times 2 pi / (texel count) as it writes it (a
    // texel's solid angle is 4 pi / count: pbrt-v4's own factor is kept, so that the same
    // parameter gives the same image).
    double illuminance = 0.0;
    const int n = image.width;
    for (int y = 0; y < n; ++y) {
      for (int x = 0; x < n; ++x) {
        const vec3 w = equalAreaSquareToSphere(
            vec2((float(x) + 0.5f) / float(n), (float(y) + 0.5f) / float(n)));
        if (w.z <= 0.0f) continue;
        const vec3 c = image.at(x, y);
        illuminance +=
            (0.2126 * double(c.x) + 0.7152 * double(c.y) + 0.0722 * double(c.z)) * double(w.z);
      }
    }
    illuminance *= 2.0 * 3.14159265358979323846 / (double(n) * double(n));
    if (illuminance > 0.0) scale *= *wanted / illuminance;
  }
  for (vec3& c : env.image.pixels) {
    const glm::dvec3 v = glm::max(glm::dvec3(c), glm::dvec3(0.0)) * scale;
    if (!(float(std::max(v.x, std::max(v.y, v.z))) < std::numeric_limits<float>::infinity())) {
      fail(f->location, context +
                            ": the image's radiance (times its scale) does not fit a 32-bit "
                            "float");
    }
    c = vec3(v);
  }
  // The light's frame: the CTM's rotation, through the camera's mirror. pbrt-v4 assumes a
  // rigid transform here; a uniform scale is harmless (the axes are normalized), anything else
  // has no direction-to-direction meaning and is refused.
  const glm::dmat3 m(gs_.ctm.m);
  glm::dvec3 axes[3];
  for (int i = 0; i < 3; ++i) {
    axes[i] = m[i];
    if (mirrored_) axes[i].x = -axes[i].x;
    const double length = glm::length(axes[i]);
    if (!(length > 0.0) || !std::isfinite(length)) {
      fail(f->location, context + ": the light's transform is singular");
    }
    axes[i] /= length;
  }
  for (int i = 0; i < 3; ++i) {
    if (std::fabs(glm::dot(axes[i], axes[(i + 1) % 3])) > 1e-4) {
      fail(f->location, context +
                            ": the light's transform is not a rotation (times a uniform "
                            "scale)");
    }
  }
  for (int i = 0; i < 3; ++i) env.toWorld[size_t(i)] = vec3(axes[i]);
  env.mapping = kEnvironmentOctahedral;
  scene_.environment = std::move(env);
}

}  // namespace pt::pbrt
