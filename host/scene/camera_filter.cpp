// The film's crop and pbrt-v4's pixel filters as the shader's constants (camera_filter.h);
// the GPU camera itself is render/camera.cpp's.
#include "scene/camera_filter.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "common/check.h"
#include "scene/json_reader.h"

namespace pt {

std::array<int, 4> cropPixels(const CameraDesc& desc, int width, int height) {
  if (desc.cropWindow) {
    // pbrt-v4's Film: the fractions ordered and clamped to [0, 1], the bounds rounded up, in
    // float as it computes them.
    const std::array<float, 4>& c = *desc.cropWindow;
    auto edge = [](int size, float fraction) {
      return static_cast<int>(
          std::ceil(static_cast<float>(size) * std::clamp(fraction, 0.0f, 1.0f)));
    };
    return {edge(width, std::min(c[0], c[1])), edge(width, std::max(c[0], c[1])),
            edge(height, std::min(c[2], c[3])), edge(height, std::max(c[2], c[3]))};
  }
  if (desc.pixelBounds) {
    // pbrt-v4's Film: the corners ordered, intersected with the film.
    const std::array<int, 4>& b = *desc.pixelBounds;
    return {std::clamp(std::min(b[0], b[1]), 0, width), std::clamp(std::max(b[0], b[1]), 0, width),
            std::clamp(std::min(b[2], b[3]), 0, height),
            std::clamp(std::max(b[2], b[3]), 0, height)};
  }
  return {0, width, 0, height};
}

namespace {

// Where the cubic c[0] t^3 + c[1] t^2 + c[2] t + c[3] changes sign strictly inside (a, b), in
// increasing order: the cubic is monotone between the roots of its derivative, so each such
// piece holds at most one sign change, found by bisection in double. Breakpoints between two
// segments of the same sign (a root the cubic only touches, or rounding at a piece's end)
// are dropped: what is left are the real sign changes, at most three.
std::vector<double> cubicSignChanges(const std::array<double, 4>& c, double a, double b) {
  auto p = [&](double t) { return ((c[0] * t + c[1]) * t + c[2]) * t + c[3]; };
  std::vector<double> cuts{a, b};
  const double qa = 3.0 * c[0], qb = 2.0 * c[1], qc = c[2];
  if (qa != 0.0) {
    const double disc = qb * qb - 4.0 * qa * qc;
    if (disc > 0.0) {
      for (double sign : {-1.0, 1.0}) cuts.push_back((-qb + sign * std::sqrt(disc)) / (2.0 * qa));
    }
  } else if (qb != 0.0) {
    cuts.push_back(-qc / qb);
  }
  std::erase_if(cuts, [&](double t) { return !(t >= a && t <= b); });
  std::sort(cuts.begin(), cuts.end());
  std::vector<double> points{a};
  for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
    double lo = cuts[i], hi = cuts[i + 1];
    if (!(hi > lo)) continue;
    // The sign just inside the piece's ends (a piece may end at a root).
    const double nudge = 1e-9 * (hi - lo);
    const double pl = p(lo) != 0.0 ? p(lo) : p(lo + nudge);
    const double ph = p(hi) != 0.0 ? p(hi) : p(hi - nudge);
    if (!((pl < 0.0 && ph > 0.0) || (pl > 0.0 && ph < 0.0))) continue;
    for (int step = 0; step < 200; ++step) {
      const double mid = 0.5 * (lo + hi);
      ((p(mid) < 0.0) == (pl < 0.0) ? lo : hi) = mid;
    }
    const double root = 0.5 * (lo + hi);
    if (root > a && root < b) points.push_back(root);
  }
  points.push_back(b);
  std::vector<double> changes;
  for (std::size_t i = 1; i + 1 < points.size(); ++i) {
    const bool before = p(0.5 * (points[i - 1] + points[i])) < 0.0;
    const bool after = p(0.5 * (points[i] + points[i + 1])) < 0.0;
    if (before != after) changes.push_back(points[i]);
  }
  return changes;
}

[[noreturn]] void filterError(const std::string& where, const std::string& problem) {
  throw InputError((where.empty() ? "" : where + ": ") + problem);
}

}  // namespace

PixelFilterDesc defaultFilter(uint type) {
  PixelFilterDesc filter;
  filter.type = type;
  const float radius = type == kFilterBox        ? 0.5f
                       : type == kFilterGaussian ? 1.5f
                                                 : 2.0f;  // triangle, mitchell
  filter.radiusX = filter.radiusY = radius;
  return filter;
}

void setFilterConstants(Camera& camera, const PixelFilterDesc& filter, const std::string& where) {
  for (float r : {filter.radiusX, filter.radiusY}) {
    if (!(r > 0.0f && r <= 4096.0f)) {
      filterError(
          where, "filter radius must be in (0, 4096] pixels, got " + scene_detail::formatNumber(r));
    }
  }
  PT_CHECK(filter.type <= kFilterMitchell, "unknown filter type");
  camera.filterType = filter.type;
  camera.filterRadiusX = filter.radiusX;
  camera.filterRadiusY = filter.radiusY;
  camera.filterWeight = 1.0f;
  camera.filterScale = 0.0f;
  camera.filterB = camera.filterC = 0.0f;
  camera.filterExpX = camera.filterExpY = 0.0f;
  camera.filterRootsNear = vec3(1.0f);
  camera.filterRootsFar = vec3(2.0f);
  if (filter.type == kFilterGaussian) {
    if (!(filter.sigma > 0.0f && std::isfinite(filter.sigma))) {
      filterError(where, "gaussian filter: sigma must be a positive number, got " +
                             scene_detail::formatNumber(filter.sigma));
    }
    // filter.h's constants, from the float values it works with.
    const float k = static_cast<float>(1.0 / (double(filter.sigma) * std::sqrt(2.0)));
    camera.filterScale = k;
    const double twoKOverRootPi = 2.0 * double(k) / std::sqrt(3.14159265358979323846);
    float* exps[2] = {&camera.filterExpX, &camera.filterExpY};
    const float radii[2] = {filter.radiusX, filter.radiusY};
    for (int axis = 0; axis < 2; ++axis) {
      const double kr = double(k) * double(radii[axis]);
      const double e = std::exp(-kr * kr) * twoKOverRootPi;
      *exps[axis] = static_cast<float>(e);
      // The CDF's whole range, erf(kr) twice minus the constant: where sigma dwarfs the
      // radius the filter is nearly constant and this difference of nearly equal numbers falls
      // to the erf approximation's error (3e-7), which would then shape the samples.
      const double total = 2.0 * std::erf(kr) - 2.0 * e * double(radii[axis]);
      if (!(total > 4e-4)) {
        filterError(where, "gaussian filter: sigma " + scene_detail::formatNumber(filter.sigma) +
                               " is too wide for radius " +
                               scene_detail::formatNumber(radii[axis]) +
                               " (the filter is within 0.1 % of a box there: use \"box\")");
      }
    }
  } else if (filter.type == kFilterMitchell) {
    const double b = filter.b, c = filter.c;
    if (!(std::isfinite(b) && std::isfinite(c) && std::abs(b) <= 100.0 && std::abs(c) <= 100.0)) {
      filterError(where, "mitchell filter: B and C must be numbers in [-100, 100], got " +
                             scene_detail::formatNumber(b) + " and " +
                             scene_detail::formatNumber(c));
    }
    camera.filterB = filter.b;
    camera.filterC = filter.c;
    // The two cubics (times 6) from the float B and C the sampler uses, their sign changes and
    // the integrals of |f| and f over t in [0, 2].
    const double fb = camera.filterB, fc = camera.filterC;
    const std::array<double, 4> nearCubic = {12.0 - 9.0 * fb - 6.0 * fc,
                                             -18.0 + 12.0 * fb + 6.0 * fc, 0.0, 6.0 - 2.0 * fb};
    const std::array<double, 4> farCubic = {-fb - 6.0 * fc, 6.0 * fb + 30.0 * fc,
                                            -12.0 * fb - 48.0 * fc, 8.0 * fb + 24.0 * fc};
    const std::vector<double> nearRoots = cubicSignChanges(nearCubic, 0.0, 1.0);
    const std::vector<double> farRoots = cubicSignChanges(farCubic, 1.0, 2.0);
    PT_CHECK(nearRoots.size() <= 3 && farRoots.size() <= 3, "a cubic changes sign 3 times at most");
    for (std::size_t i = 0; i < nearRoots.size(); ++i) {
      camera.filterRootsNear[int(i)] = static_cast<float>(nearRoots[i]);
    }
    for (std::size_t i = 0; i < farRoots.size(); ++i) {
      camera.filterRootsFar[int(i)] = static_cast<float>(farRoots[i]);
    }
    auto integral = [](const std::array<double, 4>& q, double lo, double hi) {
      auto antiderivative = [&](double t) {
        return t * (q[3] + t * (q[2] / 2.0 + t * (q[1] / 3.0 + t * q[0] / 4.0)));
      };
      return antiderivative(hi) - antiderivative(lo);
    };
    double absolute = 0.0, signed_ = 0.0;
    for (int piece = 0; piece < 2; ++piece) {
      const std::array<double, 4>& q = piece == 0 ? nearCubic : farCubic;
      std::vector<double> points = piece == 0 ? nearRoots : farRoots;
      points.insert(points.begin(), piece == 0 ? 0.0 : 1.0);
      points.push_back(piece == 0 ? 1.0 : 2.0);
      for (std::size_t i = 0; i + 1 < points.size(); ++i) {
        const double part = integral(q, points[i], points[i + 1]);
        absolute += std::abs(part);
        signed_ += part;
      }
    }
    // Mitchell1D integrates to 1 over [-2, 2] whatever B and C (pbrt-v4's Integral() is
    // radius^2 / 4): 3 here, half of it times 6.
    PT_CHECK(signed_ > 0.0, "the Mitchell filter's integral is positive");
    const double perAxis = absolute / signed_;
    camera.filterWeight = static_cast<float>(perAxis * perAxis);
  }
}

double filterIntegral(const Camera& camera) {
  const double rx = camera.filterRadiusX, ry = camera.filterRadiusY;
  switch (camera.filterType) {
    case kFilterTriangle:
      return rx * rx * ry * ry;
    case kFilterGaussian: {
      const double k = camera.filterScale;
      return (2.0 * std::erf(k * rx) - 2.0 * rx * double(camera.filterExpX)) *
             (2.0 * std::erf(k * ry) - 2.0 * ry * double(camera.filterExpY));
    }
    case kFilterMitchell:
      return 9.0 * rx * ry;
    default:
      return 4.0 * rx * ry;
  }
}

}  // namespace pt
