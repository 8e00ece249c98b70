// Pearson's chi-square test of a direction sampler against its density, the way pbrt-v4's
// BSDF tests and Mitsuba 3's chi2 module check theirs: histogram N samples on a grid of cells
// over the sphere, integrate the density over each cell, compare the counts. The grid here is
// warped towards where pilot samples show the lobes (focusedGrid), so that a narrow lobe
// (alpha down to 1e-3) still spreads over many cells, and each cell is integrated by adaptive
// Gauss-Legendre quadrature. Failing tests write the two histograms as a PNG
// (writeHistogramPng).
#pragma once

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <numbers>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "image/image.h"

namespace pt::test {

// ---- Distributions ---------------------------------------------------------------------------

// The regularized upper incomplete gamma function Q(a, x) = Gamma(a, x) / Gamma(a), for
// chi-square p-values: Q(dof / 2, chi2 / 2). The power series of P = 1 - Q below x = a + 1,
// the continued fraction of Q (modified Lentz) above, as Numerical Recipes splits them.
inline double gammaQ(double a, double x) {
  if (!(x > 0.0)) return 1.0;
  const double logPrefix = a * std::log(x) - x - std::lgamma(a);
  if (x < a + 1.0) {
    double term = 1.0 / a, sum = term;
    for (int n = 1; n < 1000000; ++n) {
      term *= x / (a + n);
      sum += term;
      if (term < sum * 1e-16) break;
    }
    return std::clamp(1.0 - sum * std::exp(logPrefix), 0.0, 1.0);
  }
  constexpr double kTiny = 1e-300;
  double b = x + 1.0 - a, c = 1.0 / kTiny, d = 1.0 / b, h = d;
  for (int i = 1; i < 1000000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < 1e-16) break;
  }
  return std::clamp(std::exp(logPrefix) * h, 0.0, 1.0);
}

// The significance each of `tests` independent tests must use so that all of them together
// reject a correct sampler with probability `alpha` (Sidak's correction).
inline double sidakSignificance(double alpha, int tests) {
  return -std::expm1(std::log1p(-alpha) / tests);
}

struct Chi2Result {
  double statistic = 0.0;
  int dof = 0;
  double pValue = 1.0;
  int pooledCells = 0;           // cells whose expected count was too small on their own
  double zeroDensityHits = 0.0;  // samples in cells where the density integrates to 0
};

// Pearson's statistic of `observed` counts against `expected` ones (the same total). Cells
// expected to hold fewer than `minExpected` samples are pooled into one, smallest first, until
// the pool reaches minExpected (the statistic is only chi-square distributed for large
// expected counts). A sample in a cell of expected count 0 is a failure of its own:
// zeroDensityHits counts them, and pValue is then 0.
inline Chi2Result pearsonChi2(const std::vector<double>& observed,
                              const std::vector<double>& expected, double minExpected = 5.0) {
  std::vector<size_t> order(expected.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::sort(order.begin(), order.end(),
            [&](size_t a, size_t b) { return expected[a] < expected[b]; });
  Chi2Result result;
  double pooledObserved = 0.0, pooledExpected = 0.0;
  int cells = 0;
  for (size_t i : order) {
    if (expected[i] <= 0.0) {
      result.zeroDensityHits += observed[i];
    } else if (expected[i] < minExpected || pooledExpected < minExpected) {
      // Sorted ascending: once the pool is full, every later cell is large enough itself.
      pooledObserved += observed[i];
      pooledExpected += expected[i];
      ++result.pooledCells;
    } else {
      result.statistic += (observed[i] - expected[i]) * (observed[i] - expected[i]) / expected[i];
      ++cells;
    }
  }
  if (pooledExpected > 0.0) {
    result.statistic +=
        (pooledObserved - pooledExpected) * (pooledObserved - pooledExpected) / pooledExpected;
    ++cells;
  }
  result.dof = std::max(1, cells - 1);  // the total is fixed
  result.pValue =
      result.zeroDensityHits > 0.0 ? 0.0 : gammaQ(0.5 * result.dof, 0.5 * result.statistic);
  return result;
}

// ---- Quadrature ------------------------------------------------------------------------------

// Gauss-Legendre nodes and weights on [-1, 1], by Newton's method on the Legendre polynomial.
struct GaussLegendre {
  std::vector<double> nodes, weights;
  explicit GaussLegendre(int n) : nodes(size_t(n)), weights(size_t(n)) {
    for (int i = 0; i < n; ++i) {
      double x = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5));
      double derivative = 1.0;
      for (int iteration = 0; iteration < 100; ++iteration) {
        double p0 = 1.0, p1 = x;  // P_0 and P_1, then up to P_(n-1) and P_n
        for (int k = 2; k <= n; ++k) {
          const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
          p0 = p1;
          p1 = p2;
        }
        derivative = n * (x * p1 - p0) / (x * x - 1.0);
        const double step = p1 / derivative;
        x -= step;
        if (std::abs(step) < 1e-15) break;
      }
      nodes[size_t(i)] = x;
      weights[size_t(i)] = 2.0 / ((1.0 - x * x) * derivative * derivative);
    }
  }
};

// ---- The grid --------------------------------------------------------------------------------

// Cell edges on [lo, hi], dense near `center`: the quantiles of a mixture of a Cauchy density
// about center of width `scale` (weight kPeakWeight) and the uniform density, both truncated to
// [lo, hi]. Near a lobe of that width the cells are a small fraction of it, far away they are
// still no wider than the uniform part makes them. `extraEdges` (within [lo, hi]) are added.
class WarpedAxis {
 public:
  static constexpr double kPeakWeight = 0.6;

  WarpedAxis(double lo, double hi, double center, double scale, int cells,
             const std::vector<double>& extraEdges = {}) {
    const double a = std::atan((lo - center) / scale), b = std::atan((hi - center) / scale);
    auto cdf = [&](double x) {
      const double peak = (std::atan((x - center) / scale) - a) / (b - a);
      return kPeakWeight * peak + (1.0 - kPeakWeight) * (x - lo) / (hi - lo);
    };
    edges_ = {lo, hi};
    for (int i = 1; i < cells; ++i) {
      // The CDF is increasing: bisect for the quantile i / cells.
      const double target = double(i) / cells;
      double x0 = lo, x1 = hi;
      for (int step = 0; step < 80; ++step) {
        const double mid = 0.5 * (x0 + x1);
        (cdf(mid) < target ? x0 : x1) = mid;
      }
      edges_.push_back(0.5 * (x0 + x1));
    }
    edges_.insert(edges_.end(), extraEdges.begin(), extraEdges.end());
    std::sort(edges_.begin(), edges_.end());
  }
  int cells() const { return int(edges_.size()) - 1; }
  double edge(int i) const { return edges_[size_t(i)]; }
  int cellOf(double x) const {
    const auto it = std::upper_bound(edges_.begin() + 1, edges_.end() - 1, x);
    return int(it - edges_.begin()) - 1;
  }

 private:
  std::vector<double> edges_;
};

// Where to refine the grid of one hemisphere: a lobe about the direction (theta, phi), theta
// measured from that hemisphere's pole, about thetaScale wide in theta and phiScale in phi.
struct LobeFocus {
  double theta = 0.0;
  double phi = 0.0;
  double thetaScale = 10.0;  // wide: about uniform cells
  double phiScale = 10.0;
};

// Cells over the whole sphere: each hemisphere (0: z > 0, 1: z < 0) has a grid over theta from
// its own pole, so that the horizon, where densities are often cut off, is a cell edge, and
// over phi relative to the focus' phi; both axes warped towards the focus.
class SphereGrid {
 public:
  SphereGrid(const std::array<LobeFocus, 2>& focus, int thetaCells, int phiCells) : focus_(focus) {
    // Rows ever thinner towards the horizon (down to 1e-4 from it), where densities often
    // have a thin sliver of support at grazing incidence that a row of the warped grid would
    // hide between its quadrature nodes.
    std::vector<double> horizon;
    if (thetaCells > 1) {
      for (double d = 1e-4; d < 0.1; d *= 3.0) horizon.push_back(0.5 * std::numbers::pi - d);
    }
    for (int h = 0; h < 2; ++h) {
      const LobeFocus& f = focus[size_t(h)];
      theta_.emplace_back(0.0, 0.5 * std::numbers::pi, f.theta, f.thetaScale, thetaCells, horizon);
      phi_.emplace_back(-std::numbers::pi, std::numbers::pi, 0.0, f.phiScale, phiCells);
    }
  }
  // The (theta, phi) of w in the hemisphere h, theta from that hemisphere's pole, phi in
  // [-pi, pi) relative to the hemisphere's focus.
  std::pair<double, double> polar(int h, glm::vec3 w) const {
    const double x = w.x, y = w.y, z = w.z;
    const double theta = std::atan2(std::sqrt(x * x + y * y), std::abs(z));
    double phi = std::atan2(y, x) - focus_[size_t(h)].phi;
    phi -= 2.0 * std::numbers::pi * std::floor((phi + std::numbers::pi) / (2.0 * std::numbers::pi));
    return {theta, phi};
  }
  int thetaCells() const { return theta_[0].cells(); }
  int phiCells() const { return phi_[0].cells(); }
  int cellCount() const { return 2 * thetaCells() * phiCells(); }
  int cellIndex(int hemisphere, int thetaCell, int phiCell) const {
    return (hemisphere * thetaCells() + thetaCell) * phiCells() + phiCell;
  }

  int cellOf(glm::vec3 w) const {
    const int h = w.z > 0.0f ? 0 : 1;
    const auto [theta, phi] = polar(h, w);
    return cellIndex(h, theta_[size_t(h)].cellOf(theta), phi_[size_t(h)].cellOf(phi));
  }

  // Calls visit(cell, w, weight) for the nodes of an order x order Gauss-Legendre rule in
  // (theta, phi) on every cell: sum weight * g(w) over a cell's nodes integrates g over it
  // (per unit solid angle; the weights include sin theta).
  template <typename Visit>
  void forEachNode(int order, const Visit& visit) const {
    const GaussLegendre rule(order);
    for (int h = 0; h < 2; ++h) {
      const double sign = h == 0 ? 1.0 : -1.0;
      for (int i = 0; i < thetaCells(); ++i) {
        const double t0 = theta_[size_t(h)].edge(i), t1 = theta_[size_t(h)].edge(i + 1);
        for (int j = 0; j < phiCells(); ++j) {
          const double p0 = phi_[size_t(h)].edge(j), p1 = phi_[size_t(h)].edge(j + 1);
          const int cell = cellIndex(h, i, j);
          for (int a = 0; a < order; ++a) {
            const double theta = 0.5 * (t0 + t1) + 0.5 * (t1 - t0) * rule.nodes[size_t(a)];
            const double sinTheta = std::sin(theta), cosTheta = std::cos(theta);
            for (int b = 0; b < order; ++b) {
              const double phi =
                  0.5 * (p0 + p1) + 0.5 * (p1 - p0) * rule.nodes[size_t(b)] + focus_[size_t(h)].phi;
              const double weight = 0.25 * (t1 - t0) * (p1 - p0) * rule.weights[size_t(a)] *
                                    rule.weights[size_t(b)] * sinTheta;
              const glm::vec3 w(float(sinTheta * std::cos(phi)), float(sinTheta * std::sin(phi)),
                                float(sign * cosTheta));
              visit(cell, w, weight);
            }
          }
        }
      }
    }
  }

  // The integral of g(w) over every cell, by adaptive quadrature: a cell's Gauss-Legendre
  // estimate is compared with the sum of its quarters', which are split again while the two
  // differ by more than `tolerance(estimate)`. The densities tested here span orders of
  // magnitude within a cell (a lobe's tail, a lobe cut off at the horizon), which no fixed
  // rule integrates to the precision a million samples resolve.
  template <typename G, typename Tolerance>
  std::vector<double> integrate(const G& g, const Tolerance& tolerance) const {
    std::vector<double> sums(size_t(cellCount()), 0.0);
    for (int h = 0; h < 2; ++h) {
      for (int i = 0; i < thetaCells(); ++i) {
        for (int j = 0; j < phiCells(); ++j) {
          const Rect r{h, theta_[size_t(h)].edge(i), theta_[size_t(h)].edge(i + 1),
                       phi_[size_t(h)].edge(j), phi_[size_t(h)].edge(j + 1)};
          const double whole = gaussLegendre(g, r);
          sums[size_t(cellIndex(h, i, j))] = adaptive(g, r, whole, tolerance(whole), kMaxDepth);
        }
      }
    }
    return sums;
  }

 private:
  static constexpr int kOrder = 4;     // Gauss-Legendre nodes per axis of a rectangle
  static constexpr int kMaxDepth = 7;  // quarterings of a cell at most

  // A rectangle in (theta, phi) of hemisphere h, phi relative to the focus.
  struct Rect {
    int h;
    double t0, t1, p0, p1;
  };
  glm::vec3 directionAt(int h, double theta, double phi) const {
    const double sinTheta = std::sin(theta), cosTheta = std::cos(theta);
    phi += focus_[size_t(h)].phi;
    return glm::vec3(float(sinTheta * std::cos(phi)), float(sinTheta * std::sin(phi)),
                     float(h == 0 ? cosTheta : -cosTheta));
  }
  template <typename G>
  double gaussLegendre(const G& g, const Rect& r) const {
    static const GaussLegendre rule(kOrder);
    double sum = 0.0;
    for (int a = 0; a < kOrder; ++a) {
      const double theta = 0.5 * (r.t0 + r.t1) + 0.5 * (r.t1 - r.t0) * rule.nodes[size_t(a)];
      double inner = 0.0;
      for (int b = 0; b < kOrder; ++b) {
        const double phi = 0.5 * (r.p0 + r.p1) + 0.5 * (r.p1 - r.p0) * rule.nodes[size_t(b)];
        inner += rule.weights[size_t(b)] * g(directionAt(r.h, theta, phi));
      }
      sum += rule.weights[size_t(a)] * std::sin(theta) * inner;
    }
    return 0.25 * (r.t1 - r.t0) * (r.p1 - r.p0) * sum;
  }
  template <typename G>
  double adaptive(const G& g, const Rect& r, double whole, double tolerance, int depth) const {
    const double tm = 0.5 * (r.t0 + r.t1), pm = 0.5 * (r.p0 + r.p1);
    const std::array<Rect, 4> quarters = {
        Rect{r.h, r.t0, tm, r.p0, pm}, Rect{r.h, tm, r.t1, r.p0, pm}, Rect{r.h, r.t0, tm, pm, r.p1},
        Rect{r.h, tm, r.t1, pm, r.p1}};
    std::array<double, 4> parts;
    double sum = 0.0;
    for (size_t q = 0; q < 4; ++q) sum += parts[q] = gaussLegendre(g, quarters[q]);
    if (depth == 0 || std::abs(sum - whole) <= tolerance) return sum;
    double refined = 0.0;
    for (size_t q = 0; q < 4; ++q)
      refined += adaptive(g, quarters[q], parts[q], 0.5 * tolerance, depth - 1);
    return refined;
  }

  std::array<LobeFocus, 2> focus_;
  std::vector<WarpedAxis> theta_, phi_;
};

// A grid focused where pilot samples fell (directions drawn from the sampler under test,
// independent of the samples the test counts): per hemisphere, about the median polar angle
// and the mean azimuth, as wide as their interquartile ranges. The shape of a lobe depends on
// the BSDF and on wo in ways no formula here should have to know (at grazing incidence a
// reflection lobe is hundreds of times narrower in phi than in theta).
inline SphereGrid focusedGrid(const std::vector<glm::vec3>& pilot, int thetaCells, int phiCells) {
  constexpr double kMinScale = 1e-4;
  std::array<LobeFocus, 2> focus;
  for (int h = 0; h < 2; ++h) {
    std::vector<glm::vec3> mine;
    double x = 0.0, y = 0.0;
    for (glm::vec3 w : pilot) {
      if ((w.z > 0.0f) == (h == 0)) {
        mine.push_back(w);
        const double r = std::sqrt(double(w.x) * w.x + double(w.y) * w.y);
        if (r > 0.0) x += w.x / r, y += w.y / r;
      }
    }
    if (mine.size() < 64) continue;  // a lobe too small to matter: uniform cells
    focus[size_t(h)].phi = std::atan2(y, x);
    const SphereGrid centred(focus, 1, 1);
    std::vector<double> thetas, phis;
    for (glm::vec3 w : mine) {
      const auto [theta, phi] = centred.polar(h, w);
      thetas.push_back(theta);
      phis.push_back(phi);
    }
    auto quantile = [](std::vector<double>& v, double q) {
      const size_t i = std::min(v.size() - 1, size_t(q * double(v.size())));
      std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(i), v.end());
      return v[i];
    };
    focus[size_t(h)].theta = quantile(thetas, 0.5);
    // Not below kMinScale: cells must stay far wider than a float direction's rounding.
    focus[size_t(h)].thetaScale =
        std::max(kMinScale, 0.5 * (quantile(thetas, 0.75) - quantile(thetas, 0.25)));
    focus[size_t(h)].phiScale =
        std::max(kMinScale, 0.5 * (quantile(phis, 0.75) - quantile(phis, 0.25)));
  }
  return SphereGrid(focus, thetaCells, phiCells);
}

// The expected counts per cell of `samples` draws from `pdf`: samples * the integral of the
// pdf over each cell, each within a few hundredths of the count's standard deviation.
template <typename Pdf>
std::vector<double> expectedCounts(const SphereGrid& grid, const Pdf& pdf, int samples) {
  const double n = samples;
  std::vector<double> counts =
      grid.integrate(pdf, [n](double p) { return 0.05 * std::sqrt(std::max(p * n, 1.0)) / n; });
  for (double& c : counts) c *= n;
  return counts;
}

// Writes the observed and the expected histograms side by side, and their difference, as a
// PNG named after `name` in the system's temporary directory (kept: it is for a person to look
// at after a failure); returns its path. Each block shows the upper hemisphere above the lower
// one, theta down and phi across, in the grid's warped cells; grey levels are counts relative
// to the largest expected count; the difference is red where more samples fell than expected,
// blue where fewer, full at 5 standard deviations.
inline std::filesystem::path writeHistogramPng(const SphereGrid& grid,
                                               const std::vector<double>& observed,
                                               const std::vector<double>& expected,
                                               std::string name) {
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '.') c = '_';
  }
  constexpr int kPixelsPerCell = 4, kGap = 8;
  const int blockW = grid.phiCells() * kPixelsPerCell;
  const int blockH = 2 * grid.thetaCells() * kPixelsPerCell + kGap / 2;
  Image image(3 * blockW + 2 * kGap, blockH);
  double maxExpected = 0.0;
  for (int c = 0; c < grid.cellCount(); ++c)
    maxExpected = std::max(maxExpected, expected[size_t(c)]);
  for (int h = 0; h < 2; ++h) {
    for (int i = 0; i < grid.thetaCells(); ++i) {
      for (int j = 0; j < grid.phiCells(); ++j) {
        const size_t c = size_t(grid.cellIndex(h, i, j));
        const float o = float(observed[c] / maxExpected), e = float(expected[c] / maxExpected);
        const double z = (observed[c] - expected[c]) / std::sqrt(std::max(expected[c], 1.0));
        const float d = float(std::min(1.0, std::abs(z) / 5.0));
        const glm::vec3 diff = z > 0.0 ? glm::vec3(d, 0.0f, 0.0f) : glm::vec3(0.0f, 0.0f, d);
        for (int dy = 0; dy < kPixelsPerCell; ++dy) {
          for (int dx = 0; dx < kPixelsPerCell; ++dx) {
            const int y = (h * grid.thetaCells() + i) * kPixelsPerCell + h * kGap / 2 + dy;
            const int x = j * kPixelsPerCell + dx;
            image.at(x, y) = glm::vec3(o);
            image.at(blockW + kGap + x, y) = glm::vec3(e);
            image.at(2 * (blockW + kGap) + x, y) = diff;
          }
        }
      }
    }
  }
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("pt-chi2-" + name + ".png");
  writeImage(image, path);
  return path;
}

}  // namespace pt::test
