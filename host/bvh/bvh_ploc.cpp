// PLOC BVH builder: the bottom levels by Parallel Locally-Ordered Clustering (Meister and
// Bittner 2018, "Parallel Locally-Ordered Clustering for Bounding Volume Hierarchy
// Construction"), the top levels by binned SAH (Wald 2007) over the clusters it leaves.
// The triangles, in Morton order, start as clusters; each round, every cluster finds its
// nearest neighbour (the one whose merged box has the least surface area) among the kRadius
// clusters on either side in that order, mutual nearest neighbours merge, and the survivors
// are compacted in order. The rounds stop at a quarter of the triangle count (see
// kClusterShare), and binned SAH splits the remaining clusters top-down. The binary tree is
// collapsed into leaves by SAH as it is built and linearized depth first, in parallel, into
// the same 32-byte nodes as the other builders.
//
// Determinism: a cluster's neighbour is the least (distance, index) pair, whatever order the
// candidates are looked at in; merges and compaction are prefix sums over fixed chunks; the
// top-down splits combine bins exactly (min, max, sums) and give each subtree a fixed range
// of node ids. So the tree is the same for any thread count.
#include <algorithm>
#include <array>
#include <cstring>
#include <memory>
#include <utility>
#include <vector>

#include "bvh/bvh_build.h"
#include "common/check.h"

namespace pt {
namespace {

// The Morton order is by the top 33 bits of the codes (11 per axis, a 2048^3 grid; three
// radix passes instead of six): the clustering looks at kRadius neighbours either way and so
// does not need the order within a cell.
constexpr int kSkipBits = 30;
// Neighbours looked at on either side. The paper finds quality close to saturated by r = 16
// (its Figure 6); larger windows cost build time for little gain.
// (Measured here: r = 8 builds about 5 % faster, with about 4 % more nodes and a 1 % higher
// SAH cost, and primary rays traced a few per cent slower in noisy measurements, so r stays
// at 16.)
constexpr size_t kRadius = 16;
// Clusters per chunk of a parallel loop.
constexpr size_t kChunk = size_t(1) << 12;
// A round that merges fewer than count / kMinMergeShare pairs pairs neighbours 2k and 2k + 1
// instead, so that the number of rounds stays logarithmic whatever the input. Coincident
// triangles (all areas tie, and everyone's neighbour is the lowest index in reach) and
// nested ones (each one's neighbour is the next larger) merge one pair per round; the
// bunny's and the dragon's rounds merge 19 to 39 % of their clusters.
constexpr size_t kMinMergeShare = 16;
// The rounds stop at n / kClusterShare clusters, and binned SAH builds the levels above them
// top-down. Clustering up to the root gives an SAH cost close to the binned-SAH builder's,
// but its upper levels are worse for rays: 15 % more node visits per ray than the binned-SAH
// tree on the bunny, 20 % on the dragon (where agglomerative merging of large clusters lets
// siblings overlap, top-down splits separate them). With the top-down levels above clusters
// of about four triangles the visits are within 2 % of binned SAH's, and fewer clusters
// (n / 8, n / 16) lose 2 to 5 %.
constexpr size_t kClusterShare = 4;
// Bins per axis of the top-down splits, all three axes binned.
constexpr int kTopBins = 16;
// Smallest top-level subtree (in clusters) handed to one worker.
constexpr size_t kTopPieceMin = 1024;
// Top-level ranges of at most this many clusters are finished bottom-up (clusterSmall): the
// many small ranges near the bottom would cost more to bin than to cluster exhaustively.
constexpr size_t kTopSmall = 8;
// The collapse's cost model: a node visit costs kCollapseTraversalCost, a triangle test
// kCollapseTriangleCost. With the SAH's unit costs (kSahTraversalCost = kSahTriangleCost = 1)
// the collapse keeps many leaves of one or two triangles, and the CPU traversal runs about 7 %
// slower on the bunny and the dragon than with leaves of up to maxLeafSize: a node visit is a
// node fetch, two box tests and stack work, more than one triangle test. At 0.3 nearly every
// subtree of at most maxLeafSize triangles becomes a leaf (no fewer do at any lower value).
constexpr float kCollapseTraversalCost = 1.0f;
constexpr float kCollapseTriangleCost = 0.3f;
// Subtrees of at most this many triangles are linearized by one worker.
constexpr size_t kPieceSize = size_t(1) << 12;

// Boxes without the Bounds initialisers: the arrays below are filled before they are read.
struct Box {
  vec3 lo, hi;
};

Box unite(const Box& a, const Box& b) {
  return Box{min(a.lo, b.lo), max(a.hi, b.hi)};
}

// Half the surface area: the SAH only compares areas.
float halfArea(const Box& b) {
  const vec3 d = b.hi - b.lo;
  return d.x * d.y + d.y * d.z + d.z * d.x;
}

Box triangleBox(const Triangle& t) {
  const Bounds b = triangleBounds(t);
  return Box{b.lo, b.hi};
}

// What the SAH collapse and the linearization need of a cluster's subtree.
struct Summary {
  uint32_t count;  // triangles in it
  uint32_t size;   // nodes its collapsed form emits (1: it is collapsed into one leaf)
  int height;      // depth of its deepest leaf below it, collapsed
  float cost;      // SAH cost of the collapsed form times half the area of its box
};

// A merge of two clusters. Ids below the triangle count n are triangles (by Morton rank);
// id n + k is inner node k, created in merge order, so children have smaller ids.
struct Inner {
  Box box;
  uint32_t left, right;  // the left one was first in Morton order
  uint32_t count, size;  // as in Summary
  int height;
};

// Lanes through the GCC and Clang vector extensions (SSE on x86-64, NEON on ARM): the -O2
// build does not vectorize the neighbour search's selects (eight lanes) nor the binning (a
// box in four) by itself.
using Float4 = float __attribute__((vector_size(16)));
using Float8 = float __attribute__((vector_size(32)));
using Int8 = int32_t __attribute__((vector_size(32)));
Float4 splat4(float x) {
  return Float4{x, x, x, x};
}
// As std::min and std::max, lane by lane (the first operand where either is NaN); they
// compile to minps and maxps.
Float4 min4(Float4 a, Float4 b) {
  return b < a ? b : a;
}
Float4 max4(Float4 a, Float4 b) {
  return a < b ? b : a;
}

// The clusters of a round as a structure of arrays, so that the neighbour search loads eight
// at a time. Cluster i is at i + kPadding; the padding on both sides (enough for the last
// eight lanes too) holds infinite boxes, whose merged area is infinite: never anyone's
// nearest neighbour.
constexpr size_t kPadding = kRadius + 8;
// (The arrays are not value-initialised: every entry is written before it is read.)
struct Clusters {
  std::unique_ptr<float[]> lo[3], hi[3];
  std::unique_ptr<uint32_t[]> id;
  std::unique_ptr<Summary[]> summary;

  explicit Clusters(size_t n)
      : id(std::make_unique_for_overwrite<uint32_t[]>(n)),
        summary(std::make_unique_for_overwrite<Summary[]>(n)) {
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::make_unique_for_overwrite<float[]>(n + 2 * kPadding);
      hi[a] = std::make_unique_for_overwrite<float[]>(n + 2 * kPadding);
      std::fill_n(lo[a].get(), kPadding, -INFINITY);
      std::fill_n(hi[a].get(), kPadding, INFINITY);
    }
    pad(n);
  }
  Box box(size_t i) const {
    const size_t p = i + kPadding;
    return Box{vec3(lo[0][p], lo[1][p], lo[2][p]), vec3(hi[0][p], hi[1][p], hi[2][p])};
  }
  void set(size_t i, const Box& b, uint32_t clusterId, const Summary& s) {
    for (int a = 0; a < 3; ++a) {
      lo[a][i + kPadding] = b.lo[a];
      hi[a][i + kPadding] = b.hi[a];
    }
    id[i] = clusterId;
    summary[i] = s;
  }
  // Pads after the first `count` clusters.
  void pad(size_t count) {
    for (int a = 0; a < 3; ++a) {
      std::fill_n(lo[a].get() + count + kPadding, kPadding, -INFINITY);
      std::fill_n(hi[a].get() + count + kPadding, kPadding, INFINITY);
    }
  }
};

// neighbour[i] for i in [begin, end): the cluster j within kRadius places of i with the least
// area of the merged box, the lower index on a tie; i itself when every area is infinite or
// NaN. Eight clusters at a time, one per lane; the candidates are offered from the lowest
// index up, so "strictly less" keeps the lower index on ties. This loop is most of the build
// time, so it is also compiled for AVX2 (picked at load time where the CPU has it): eight
// lanes in one register instead of two; the arithmetic, and so the tree, is the same. (No
// helper function takes or returns 32-byte vectors by value: that would change its calling
// convention between the two versions.)
__attribute__((target_clones("avx2", "default"))) void findNeighbours(const Clusters& c,
                                                                      size_t begin, size_t end,
                                                                      uint32_t* neighbour) {
  const float *lx = c.lo[0].get(), *ly = c.lo[1].get(), *lz = c.lo[2].get();
  const float *hx = c.hi[0].get(), *hy = c.hi[1].get(), *hz = c.hi[2].get();
  // The boxes of the clusters at positions q .. q + 7, lane by lane.
  auto load = [&](size_t q, Float8& x0, Float8& y0, Float8& z0, Float8& x1, Float8& y1,
                  Float8& z1) {
    std::memcpy(&x0, lx + q, sizeof x0);
    std::memcpy(&y0, ly + q, sizeof y0);
    std::memcpy(&z0, lz + q, sizeof z0);
    std::memcpy(&x1, hx + q, sizeof x1);
    std::memcpy(&y1, hy + q, sizeof y1);
    std::memcpy(&z1, hz + q, sizeof z1);
  };
  const Int8 laneOffsets = {0, 1, 2, 3, 4, 5, 6, 7};
  for (size_t i = begin; i < end; i += 8) {
    const size_t p = i + kPadding;  // cluster i's position in the padded arrays
    Float8 x0, y0, z0, x1, y1, z1;
    load(p, x0, y0, z0, x1, y1, z1);
    Float8 bestArea = {INFINITY, INFINITY, INFINITY, INFINITY,
                       INFINITY, INFINITY, INFINITY, INFINITY};
    Int8 best = laneOffsets + int32_t(i);
    // Offers the clusters at positions q .. q + 7, indices j .. j + 7.
    auto offer = [&](size_t q, int32_t j) {
      Float8 qx0, qy0, qz0, qx1, qy1, qz1;
      load(q, qx0, qy0, qz0, qx1, qy1, qz1);
      // max(a, b) - min(a, b) per axis as a < b ? b : a and b < a ? b : a (maxps, minps).
      const Float8 dx = (x1 < qx1 ? qx1 : x1) - (qx0 < x0 ? qx0 : x0);
      const Float8 dy = (y1 < qy1 ? qy1 : y1) - (qy0 < y0 ? qy0 : y0);
      const Float8 dz = (z1 < qz1 ? qz1 : z1) - (qz0 < z0 ? qz0 : z0);
      const Float8 area = dx * dy + dy * dz + dz * dx;
      const Int8 better = area < bestArea;
      bestArea = better ? area : bestArea;
      best = better ? laneOffsets + j : best;
    };
    for (size_t k = kRadius; k > 0; --k) offer(p - k, int32_t(i - k));
    for (size_t k = 1; k <= kRadius; ++k) offer(p + k, int32_t(i + k));
    for (size_t lane = 0; lane < 8 && i + lane < end; ++lane) {
      neighbour[i + lane] = uint32_t(best[lane]);
    }
  }
}

class PlocBuilder {
 public:
  PlocBuilder(const std::vector<Triangle>& triangles, size_t leafSize, int depthLimit,
              Workers& workers)
      : triangles_(triangles),
        n_(triangles.size()),
        leafSize_(leafSize),
        depthLimit_(depthLimit),
        workers_(workers) {}

  Bvh build() {
    order_ = sortByMorton(triangles_, kSkipBits, workers_).order;
    const uint32_t root = cluster();
    return linearize(root);
  }

 private:
  // ---- Clustering ------------------------------------------------------------------------

  // Runs the rounds of nearest-neighbour merging; returns the root's id.
  uint32_t cluster() {
    Clusters clusters(n_), next(n_);
    const auto neighbour = std::make_unique_for_overwrite<uint32_t[]>(n_);
    workers_.forChunks(n_, kChunk, [&](size_t begin, size_t end) {
      for (size_t i = begin; i < end; ++i) {
        const Box box = triangleBox(triangles_[order_[i]]);
        clusters.set(i, box, uint32_t(i), Summary{1, 1, 0, kCollapseTriangleCost * halfArea(box)});
      }
    });
    // Not value-initialised: every entry is written before it is read.
    inner_.reset(new Inner[n_ - 1]);
    size_t count = n_;
    uint32_t created = 0;  // inner nodes so far
    std::vector<uint32_t> merges, survivors;
    // The rounds stop at n / kClusterShare clusters (see kClusterShare).
    const size_t target = std::max<size_t>(1, n_ / kClusterShare);
    while (count > target) {
      const size_t chunks = (count + kChunk - 1) / kChunk;
      merges.assign(chunks, 0);
      survivors.assign(chunks, 0);
      workers_.forChunks(count, kChunk, [&](size_t begin, size_t end) {
        findNeighbours(clusters, begin, end, neighbour.get());
      });
      auto tally = [&](size_t begin, size_t end) {
        uint32_t m = 0, s = 0;
        for (size_t i = begin; i < end; ++i) {
          const uint32_t j = neighbour[i];
          const bool mutual = j != i && neighbour[j] == i;
          m += mutual && i < j;
          s += !mutual || i < j;
        }
        merges[begin / kChunk] = m;
        survivors[begin / kChunk] = s;
      };
      workers_.forChunks(count, kChunk, tally);
      size_t merged = 0;
      for (uint32_t m : merges) merged += m;
      if (merged < std::max<size_t>(1, count / kMinMergeShare)) {
        // Too little progress: merge clusters 2k and 2k + 1 this round.
        workers_.forChunks(count, kChunk, [&](size_t begin, size_t end) {
          for (size_t i = begin; i < end; ++i) {
            neighbour[i] = uint32_t((i ^ 1) < count ? i ^ 1 : i);
          }
        });
        workers_.forChunks(count, kChunk, tally);
      }
      // Exclusive prefix sums: where each chunk's new nodes and survivors go.
      uint32_t nodeSum = created, outSum = 0;
      for (size_t c = 0; c < chunks; ++c) {
        nodeSum += std::exchange(merges[c], nodeSum);
        outSum += std::exchange(survivors[c], outSum);
      }
      workers_.forChunks(count, kChunk, [&](size_t begin, size_t end) {
        uint32_t node = merges[begin / kChunk];
        uint32_t out = survivors[begin / kChunk];
        for (size_t i = begin; i < end; ++i) {
          const uint32_t j = neighbour[i];
          const bool mutual = j != i && neighbour[j] == i;
          if (!mutual) {
            next.set(out++, clusters.box(i), clusters.id[i], clusters.summary[i]);
          } else if (i < j) {
            Inner& parent = inner_[node];
            parent.left = clusters.id[i];
            parent.right = clusters.id[j];
            parent.box = unite(clusters.box(i), clusters.box(j));
            const Summary s = merge(parent, clusters.summary[i], clusters.summary[j]);
            next.set(out++, parent.box, uint32_t(n_) + node++, s);
          }
        }
      });
      created = nodeSum;
      count = outSum;
      next.pad(count);
      std::swap(clusters, next);
    }
    if (count == 1) return clusters.id[0];
    return buildTop(clusters, count, created);
  }

  // Subtree sizes by id; a triangle is a leaf of its own.
  uint32_t countOf(uint32_t id) const { return id < n_ ? 1u : inner_[id - n_].count; }
  uint32_t sizeOf(uint32_t id) const { return id < n_ ? 1u : inner_[id - n_].size; }
  int heightOf(uint32_t id) const { return id < n_ ? 0 : inner_[id - n_].height; }

  // Completes `parent` (box and children set) from its children's summaries, deciding the
  // SAH collapse bottom-up as the tree is made: a subtree of at most leafSize triangles
  // becomes one leaf when that costs no more than keeping its best split (costs times area:
  // a leaf costs count * Ci * A, a split Ct * A plus its children's).
  Summary merge(Inner& parent, const Summary& l, const Summary& r) const {
    const float area = halfArea(parent.box);
    const uint32_t count = l.count + r.count;
    const float splitCost = kCollapseTraversalCost * area + l.cost + r.cost;
    const float leafCost = kCollapseTriangleCost * float(count) * area;
    const Summary s =
        count <= leafSize_ && leafCost <= splitCost
            ? Summary{count, 1, 0, leafCost}
            : Summary{count, 1 + l.size + r.size, 1 + std::max(l.height, r.height), splitCost};
    parent.count = s.count;
    parent.size = s.size;
    parent.height = s.height;
    return s;
  }

  // ---- Top levels ------------------------------------------------------------------------

  // A cluster left by the rounds, as the top-down splits see and move it.
  struct TopRef {
    Float4 lo, hi;     // its box in lanes x, y, z
    uint32_t cluster;  // its index in the clusters of the last round
    uint32_t count;    // triangles
  };
  // The bins of one axis; the first binCount of them are cleared before use.
  struct AxisBins {
    Float4 lo[kTopBins], hi[kTopBins];
    uint32_t count[kTopBins];  // triangles
  };
  using Bins = std::array<AxisBins, 3>;
  // What a subtree of the top levels hands its parent.
  struct TopRoot {
    uint32_t id;
    Box box;
    Summary summary;
  };

  // Builds the levels above the `count` clusters top-down with binned SAH (Wald 2007), in
  // parallel over subtrees as in the LBVH; returns the root's id. A subtree over m clusters
  // owns the m - 1 inner ids from its `base` (its root last, after its children's), so the
  // ids do not depend on the order the subtrees are built in.
  uint32_t buildTop(const Clusters& clusters, size_t count, uint32_t base) {
    refs_ = std::make_unique_for_overwrite<TopRef[]>(count);
    scratch_ = std::make_unique_for_overwrite<TopRef[]>(count);
    binIndex_ = std::make_unique_for_overwrite<std::array<uint8_t, 3>[]>(count);
    topClusters_ = &clusters;
    workers_.forChunks(count, kChunk, [&](size_t begin, size_t end) {
      for (size_t i = begin; i < end; ++i) {
        const Box box = clusters.box(i);
        refs_[i] = TopRef{Float4{box.lo.x, box.lo.y, box.lo.z, 0.0f},
                          Float4{box.hi.x, box.hi.y, box.hi.z, 0.0f}, uint32_t(i),
                          clusters.summary[i].count};
      }
    });
    pieceSize_ = workers_.count() == 1
                     ? count
                     : std::max<size_t>(kTopPieceMin, count / size_t(8 * workers_.count()));
    plan_.clear();
    cut(0, count, base);
    std::vector<uint32_t> pieces;
    for (uint32_t i = 0; i < plan_.size(); ++i) {
      if (plan_[i].piece) pieces.push_back(i);
    }
    workers_.forChunks(pieces.size(), 1, [&](size_t p, size_t) {
      TopItem& item = plan_[pieces[p]];
      item.root = buildTopSerial(item.first, item.last, item.base);
    });
    for (size_t i = plan_.size(); i-- > 0;) {
      TopItem& item = plan_[i];
      if (!item.piece) {
        item.root = join(item.base + uint32_t(item.last - item.first) - 2, plan_[i + 1].root,
                         plan_[item.right].root);
      }
    }
    return plan_[0].root.id;
  }

  struct TopItem {
    size_t first, last;  // clusters refs_[first, last)
    uint32_t base;
    bool piece;          // built whole by one worker; else split here
    uint32_t right = 0;  // a split's right child in plan_ (the left one follows it)
    TopRoot root{};
  };

  // Plans the top levels over refs_[first, last) depth first, splitting (binning in
  // parallel) until the ranges are small enough to share out.
  void cut(size_t first, size_t last, uint32_t base) {
    const uint32_t item = uint32_t(plan_.size());
    const size_t m = last - first;
    plan_.push_back(TopItem{first, last, base, m <= pieceSize_ || m == 1});
    if (plan_[item].piece) return;
    const size_t middle = splitRange(first, last, true);
    cut(first, middle, base);
    plan_[item].right = uint32_t(plan_.size());
    cut(middle, last, base + uint32_t(middle - first) - 1);
  }

  TopRoot buildTopSerial(size_t first, size_t last, uint32_t base) {
    if (last - first <= kTopSmall) return clusterSmall(first, last, base);
    const size_t middle = splitRange(first, last, false);
    const TopRoot left = buildTopSerial(first, middle, base);
    const TopRoot right = buildTopSerial(middle, last, base + uint32_t(middle - first) - 1);
    return join(base + uint32_t(last - first) - 2, left, right);
  }

  // Finishes a range of at most kTopSmall clusters as the rounds would, had they a window
  // over all of it: merging the pair whose merged box has the least area until one is left.
  // On a tie the pair with fewer triangles merges (equal boxes make a balanced tree, not a
  // chain), then the first in range order. The last merge, the root, gets the last id.
  TopRoot clusterSmall(size_t first, size_t last, uint32_t base) {
    std::array<TopRoot, kTopSmall> part;
    size_t m = last - first;
    for (size_t k = 0; k < m; ++k) {
      const uint32_t c = refs_[first + k].cluster;
      part[k] = TopRoot{topClusters_->id[c], topClusters_->box(c), topClusters_->summary[c]};
    }
    for (; m > 1; --m) {
      size_t bestA = 0, bestB = 1;
      float bestArea = INFINITY;
      uint32_t bestCount = UINT32_MAX;
      for (size_t a = 0; a + 1 < m; ++a) {
        for (size_t b = a + 1; b < m; ++b) {
          const float area = halfArea(unite(part[a].box, part[b].box));
          const uint32_t count = part[a].summary.count + part[b].summary.count;
          if (area < bestArea || (area == bestArea && count < bestCount)) {
            bestArea = area, bestCount = count, bestA = a, bestB = b;
          }
        }
      }
      part[bestA] = join(base++, part[bestA], part[bestB]);
      std::copy(part.begin() + ptrdiff_t(bestB) + 1, part.begin() + ptrdiff_t(m),
                part.begin() + ptrdiff_t(bestB));
    }
    return part[0];
  }

  // Makes inner node `node` the parent of two subtrees.
  TopRoot join(uint32_t node, const TopRoot& left, const TopRoot& right) {
    Inner& parent = inner_[node];
    parent.left = left.id;
    parent.right = right.id;
    parent.box = unite(left.box, right.box);
    return TopRoot{uint32_t(n_) + node, parent.box, merge(parent, left.summary, right.summary)};
  }

  // Splits refs_[first, last) (at least two clusters) where the binned SAH says, keeping
  // Morton order on each side; returns where the right side starts. A range of m clusters
  // gets min(m, kTopBins) bins per axis: most ranges are small. With `parallel`, the bounds
  // and bins are gathered by chunks on all workers (exact merges: min, max, sums).
  size_t splitRange(size_t first, size_t last, bool parallel) {
    const size_t m = last - first;
    if (m == 2) return first + 1;
    parallel = parallel && m > kChunk;
    const size_t parts = parallel ? (m + kChunk - 1) / kChunk : 1;
    auto forParts = [&](auto&& body) {
      workers_.forChunks(m, kChunk,
                         [&](size_t b, size_t e) { body(b / kChunk, first + b, first + e); });
    };
    // Bounds of the centres (doubled: lo + hi).
    Float4 lo, hi;
    if (parallel) {
      std::vector<std::array<Float4, 2>> partBounds(parts);
      forParts([&](size_t part, size_t b, size_t e) { partBounds[part] = centerBounds(b, e); });
      lo = partBounds[0][0], hi = partBounds[0][1];
      for (const auto& [partLo, partHi] : partBounds) lo = min4(lo, partLo), hi = max4(hi, partHi);
    } else {
      const auto bounds = centerBounds(first, last);
      lo = bounds[0], hi = bounds[1];
    }
    const int binCount = int(std::min<size_t>(m, kTopBins));
    Float4 scale = splat4(0.0f);
    for (int a = 0; a < 3; ++a) {
      const float extent = hi[a] - lo[a];
      if (extent > 0.0f) scale[a] = float(binCount) / extent;
    }
    Bins bins;
    if (parallel) {
      std::vector<Bins> partBins(parts);
      forParts([&](size_t part, size_t b, size_t e) {
        binRange(b, e, lo, scale, binCount, partBins[part]);
      });
      bins = partBins[0];
      for (size_t p = 1; p < parts; ++p) {
        for (size_t a = 0; a < 3; ++a) {
          for (int k = 0; k < binCount; ++k) {
            bins[a].lo[k] = min4(bins[a].lo[k], partBins[p][a].lo[k]);
            bins[a].hi[k] = max4(bins[a].hi[k], partBins[p][a].hi[k]);
            bins[a].count[k] += partBins[p][a].count[k];
          }
        }
      }
    } else {
      binRange(first, last, lo, scale, binCount, bins);
    }
    // Sweep each axis for the least area(left) * count(left) + area(right) * count(right).
    uint32_t total = 0;
    for (int k = 0; k < binCount; ++k) total += bins[0].count[k];
    auto area = [](Float4 lo, Float4 hi) {
      const Float4 d = hi - lo;
      return d[0] * d[1] + d[1] * d[2] + d[2] * d[0];
    };
    int bestAxis = -1, bestBin = 0;
    float bestCost = INFINITY;
    for (int a = 0; a < 3; ++a) {
      if (scale[a] == 0.0f) continue;
      const AxisBins& axis = bins[size_t(a)];
      std::array<float, kTopBins> rightCost;
      Float4 accLo = splat4(INFINITY), accHi = splat4(-INFINITY);
      uint32_t count = 0;
      for (int k = binCount - 1; k > 0; --k) {
        accLo = min4(accLo, axis.lo[k]);
        accHi = max4(accHi, axis.hi[k]);
        count += axis.count[k];
        rightCost[size_t(k)] = area(accLo, accHi) * float(count);
      }
      accLo = splat4(INFINITY), accHi = splat4(-INFINITY);
      count = 0;
      for (int k = 1; k < binCount; ++k) {
        accLo = min4(accLo, axis.lo[k - 1]);
        accHi = max4(accHi, axis.hi[k - 1]);
        count += axis.count[k - 1];
        if (count == 0 || count == total) continue;
        const float cost = area(accLo, accHi) * float(count) + rightCost[size_t(k)];
        if (cost < bestCost) bestCost = cost, bestAxis = a, bestBin = k;
      }
    }
    // No split separates the centres (all in one bin on every axis): halve in Morton order.
    if (bestAxis < 0) return first + m / 2;
    // Stable partition through the same range of scratch_ (workers own disjoint ranges), so
    // that each side stays in Morton order.
    size_t left = first, right = first;
    for (size_t i = first; i < last; ++i) {
      if (binIndex_[i][size_t(bestAxis)] < bestBin) {
        refs_[left++] = refs_[i];
      } else {
        scratch_[right++] = refs_[i];
      }
    }
    std::copy(scratch_.get() + first, scratch_.get() + right, refs_.get() + left);
    PT_CHECK(left > first && left < last);
    return left;
  }

  std::array<Float4, 2> centerBounds(size_t begin, size_t end) const {
    Float4 lo = splat4(INFINITY), hi = splat4(-INFINITY);
    for (size_t i = begin; i < end; ++i) {
      const TopRef& c = refs_[i];
      const Float4 center = c.lo + c.hi;
      lo = min4(lo, center);
      hi = max4(hi, center);
    }
    return {lo, hi};
  }

  // Bins the clusters refs_[begin, end) on all three axes, noting each one's bins. Even and
  // odd positions fill separate bins, merged at the end: runs of clusters in one bin would
  // otherwise wait for each other's updates.
  void binRange(size_t begin, size_t end, Float4 lo, Float4 scale, int binCount, Bins& bins) {
    Bins odd;
    for (Bins* b : {&bins, &odd}) {
      for (AxisBins& axis : *b) {
        std::fill_n(axis.lo, binCount, splat4(INFINITY));
        std::fill_n(axis.hi, binCount, splat4(-INFINITY));
        std::fill_n(axis.count, binCount, 0u);
      }
    }
    const float lastBin = float(binCount - 1);
    for (size_t i = begin; i < end; ++i) {
      const TopRef& cluster = refs_[i];
      const Float4 x = (cluster.lo + cluster.hi - lo) * scale;
      Bins& target = i % 2 ? odd : bins;
      for (size_t a = 0; a < 3; ++a) {
        // std::min(lastBin, x) is lastBin for a NaN x, so the conversion stays defined.
        const int k = int(std::min(lastBin, x[a]));
        binIndex_[i][a] = uint8_t(k);
        AxisBins& axis = target[a];
        axis.lo[k] = min4(axis.lo[k], cluster.lo);
        axis.hi[k] = max4(axis.hi[k], cluster.hi);
        axis.count[k] += cluster.count;
      }
    }
    for (size_t a = 0; a < 3; ++a) {
      for (int k = 0; k < binCount; ++k) {
        bins[a].lo[k] = min4(bins[a].lo[k], odd[a].lo[k]);
        bins[a].hi[k] = max4(bins[a].hi[k], odd[a].hi[k]);
        bins[a].count[k] += odd[a].count[k];
      }
    }
  }

  // ---- Linearization ---------------------------------------------------------------------

  Bvh linearize(uint32_t root) {
    Bvh bvh;
    bvh.triangles.resize(n_);
    if (heightOf(root) <= depthLimit_) {
      bvh.nodes.resize(sizeOf(root));
      nodes_ = bvh.nodes.data();
      out_ = bvh.triangles.data();
      std::vector<Piece> pieces;
      place(root, 0, 0, &pieces);
      workers_.forChunks(pieces.size(), 1, [&](size_t p, size_t) {
        place(pieces[p].id, pieces[p].position, pieces[p].first, nullptr);
      });
      bvh.maxDepth = heightOf(root);
    } else {
      bvh.maxDepth = 0;
      out_ = bvh.triangles.data();
      placeWithinStack(root, 0, 0, bvh.nodes, bvh.maxDepth);
    }
    return bvh;
  }

  struct Piece {
    uint32_t id, position, first;
  };

  // Writes the collapsed subtree of `id` with its root at nodes_[position] and its triangles
  // from out_[first] on, depth first, left child first. With `pieces`, subtrees of at most
  // kPieceSize triangles are listed there for the workers instead of written.
  void place(uint32_t id, uint32_t position, uint32_t first, std::vector<Piece>* pieces) {
    if (id < n_) {
      const Triangle& t = triangles_[order_[id]];
      const Bounds b = triangleBounds(t);
      nodes_[position] = BvhNode{b.lo, first, b.hi, 1u};
      out_[first] = t;
      return;
    }
    const Inner& node = inner_[id - n_];
    if (node.size == 1) {  // collapsed into a leaf
      nodes_[position] = BvhNode{node.box.lo, first, node.box.hi, node.count};
      gather(id, first);
      return;
    }
    if (pieces && node.count <= kPieceSize) {
      pieces->push_back(Piece{id, position, first});
      return;
    }
    const uint32_t right = position + 1 + sizeOf(node.left);
    nodes_[position] = BvhNode{node.box.lo, right, node.box.hi, 0u};
    place(node.left, position + 1, first, pieces);
    place(node.right, right, first + countOf(node.left), pieces);
  }

  // The triangles of the subtree of `id`, in depth-first order, to out_[first] on.
  uint32_t gather(uint32_t id, uint32_t first) {
    if (id < n_) {
      out_[first] = triangles_[order_[id]];
      return first + 1;
    }
    const Inner& node = inner_[id - n_];
    return gather(node.right, gather(node.left, first));
  }

  // The rare tree deeper than the traversal stack (top-down splits that peel one cluster off
  // at a time, as nested boxes can make them): serially,
  // appending to `nodes`, keep the clustered splits while both children can still be
  // finished within the stack by balanced splits, and else emit the subtree's triangles (in
  // leaf order) with balanced splits. The precondition depth + balancedLevels(count) <=
  // depthLimit_ holds at the root (checked by buildPlocBvh) and for every child recursed into.
  void placeWithinStack(uint32_t id, int depth, uint32_t first, std::vector<BvhNode>& nodes,
                        int& maxDepth) {
    if (depth + heightOf(id) <= depthLimit_) {
      const size_t position = nodes.size();
      nodes.resize(position + sizeOf(id));
      nodes_ = nodes.data();
      place(id, uint32_t(position), first, nullptr);
      maxDepth = std::max(maxDepth, depth + heightOf(id));
      return;
    }
    const Inner& node = inner_[id - n_];  // not a leaf: its height is above 0
    const uint32_t leftCount = countOf(node.left), rightCount = countOf(node.right);
    auto fits = [&](uint32_t count) {
      return depth + 1 + balancedLevels(count, leafSize_) <= depthLimit_;
    };
    if (fits(leftCount) && fits(rightCount)) {
      const size_t position = nodes.size();
      nodes.push_back(BvhNode{node.box.lo, 0u, node.box.hi, 0u});
      maxDepth = std::max(maxDepth, depth);
      placeWithinStack(node.left, depth + 1, first, nodes, maxDepth);
      nodes[position].offset = uint32_t(nodes.size());
      placeWithinStack(node.right, depth + 1, first + leftCount, nodes, maxDepth);
      return;
    }
    gather(id, first);
    auto middle = [](size_t begin, size_t end, int) { return begin + (end - begin) / 2; };
    RangeEmitter<decltype(middle)> emitter(out_, leafSize_, middle, nodes);
    emitter.emit(first, first + leftCount + rightCount, depth);
    maxDepth = std::max(maxDepth, emitter.maxDepth());
  }

  const std::vector<Triangle>& triangles_;
  const size_t n_;
  const size_t leafSize_;
  const int depthLimit_;  // deepest leaf allowed: kBvhStackSize, less in tests
  Workers& workers_;
  std::unique_ptr<uint32_t[]> order_;  // Morton rank -> input index
  std::unique_ptr<Inner[]> inner_;
  // The top levels' state: the clusters left by the rounds, their order (permuted by the
  // splits), the plan of the subtrees shared out, and their size.
  const Clusters* topClusters_ = nullptr;
  std::unique_ptr<TopRef[]> refs_, scratch_;
  std::unique_ptr<std::array<uint8_t, 3>[]> binIndex_;  // by position in refs_: bin per axis
  std::vector<TopItem> plan_;
  size_t pieceSize_ = 0;
  BvhNode* nodes_ = nullptr;
  Triangle* out_ = nullptr;
};

}  // namespace

Bvh buildPlocBvh(const std::vector<Triangle>& triangles, size_t leafSize, Workers& workers,
                 int depthLimit) {
  PT_CHECK(triangles.size() < (size_t(1) << 31), "ids of triangles and merges share 32 bits");
  PT_CHECK(depthLimit >= balancedLevels(triangles.size(), leafSize));
  return PlocBuilder(triangles, leafSize, depthLimit, workers).build();
}

}  // namespace pt
