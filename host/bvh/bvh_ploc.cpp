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
//
// Memory: every page a build touches for the first time costs a page fault and the kernel's
// zeroing (about 0.2 ms per MB on the test machine, several times more when the host has not
// backed the memory yet), so the phases pass memory on (docs/bvh-build.md has the profile):
// the Morton keys live in the inner nodes' memory until the first merge; the centroids, then
// the first round's clusters in block 0; the input triangles, once copied in Morton order
// (sorted_), give their memory, already touched by the caller, to block 1, which holds the
// clusters of every other round and then the top levels' state, and at the end the output
// triangles, without the zeroing of a resize. The per-cluster data that only merges read
// (triangle counts, collapsed sizes, costs) lives in the inner nodes, where merges write it
// anyway; inner nodes keep no boxes (the linearization unites them again from the
// triangles); and the large arrays ask for huge pages (adviseHugePages). The neighbour
// search, the compaction and the pair marking of the rounds also run in sixteen AVX-512
// lanes where the CPU has them (the same arithmetic: the same tree).
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstring>
#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

#include "bvh/bvh_build.h"
#include "common/check.h"

#ifdef __linux__
#include <sys/mman.h>
#endif
#ifdef __x86_64__
#include <immintrin.h>
#endif

namespace pt {
namespace {

// The Morton order is by the top 33 bits of the codes (11 per axis, a 2048^3 grid; three
// radix passes instead of six): the clustering looks at kRadius neighbours either way and so
// does not need the order within a cell.
constexpr int kMortonBits = 33;
constexpr int kDigitBits = 11;  // per radix pass
// Neighbours looked at on either side. The paper finds quality close to saturated by r = 16
// (its Figure 6); larger windows cost build time for little gain.
// (Measured here: r = 8 builds about 5 % faster, with about 4 % more nodes and a 1 % higher
// SAH cost, and primary rays traced a few per cent slower in noisy measurements, so r stays
// at 16.)
constexpr size_t kRadius = 16;
// How many triangles ahead the passes that read them in Morton order fetch.
constexpr size_t kPrefetch = 16;
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
// Bins per axis of the top-down splits, all three axes binned: 32, as Embree's binned-SAH
// builders have. With 16, the splits near the root of a scene whose walls enclose its objects
// missed the one that sets the walls apart: the wide tree's node SAH cost (wideTreeSummary)
// was 6.32 on bunny-box and 4.67 on bunny-dragon, 5.20 and 4.33 with 32 (Embree's own tree for
// bunny-dragon: 4.14); the sphere and the dragon alone changed by under 1 %, the build took
// 1-4 % longer. (Greedy splits are not monotone in the bins: 24 gave 4.33, 48 and 64 gave 4.64
// and 4.63 on bunny-dragon.)
constexpr int kTopBins = 32;
// Ranges of at least this many clusters are binned into two sets of bins (see binClusters).
constexpr size_t kTopTwoBinSets = 64;
// Smallest top-level subtree (in clusters) handed to one worker.
constexpr size_t kTopPieceMin = 1024;
// Top-level ranges of at most this many clusters are finished bottom-up (clusterSmall): the
// many small ranges near the bottom would cost more to bin than to cluster exhaustively.
constexpr size_t kTopSmall = 8;
static_assert(kTopSmall >= 2, "splitRange needs more than two clusters");
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

// What the SAH collapse and the linearization need of a subtree.
struct Summary {
  uint32_t count;  // triangles in it
  uint32_t size;   // nodes its collapsed form emits (1: it is collapsed into one leaf)
  float cost;      // SAH cost of the collapsed form times half the area of its box
};

// A merge of two clusters. Ids below the triangle count n are triangles (by Morton rank);
// id n + k is inner node k, created in merge order, so children have smaller ids. Its box is
// not kept: the clusters carry their boxes while they are clustered, and the linearization
// unites the children's boxes again as it writes the nodes (the same min and max in the same
// order: the same box), which halves the memory the inner nodes take.
struct Inner {
  uint32_t left, right;  // the left one was first in Morton order
  Summary summary;
};

// Lanes through the GCC and Clang vector extensions (SSE on x86-64, NEON on ARM): the -O2
// build does not vectorize the neighbour search's selects (eight lanes) nor the binning (a
// box in four) by itself.
using Float4 = float __attribute__((vector_size(16)));
using Float8 = float __attribute__((vector_size(32)));
using Int4 = int32_t __attribute__((vector_size(16)));
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

// A box in lanes x, y, z of two vectors, lane 3 left as loaded, for the loops that unite
// many boxes: min4 and max4 are glm's min and max lane by lane, so these are the same boxes
// as unite and triangleBox make.
struct Box4 {
  Float4 lo, hi;
};
Box4 unite4(const Box4& a, const Box4& b) {
  return Box4{min4(a.lo, b.lo), max4(a.hi, b.hi)};
}
float halfArea4(const Box4& b) {
  const Float4 d = b.hi - b.lo;
  return d[0] * d[1] + d[1] * d[2] + d[2] * d[0];
}
// (Each vertex of a Triangle is the first 12 bytes of a 16-byte row.)
static_assert(offsetof(Triangle, v1) == 16 && offsetof(Triangle, v2) == 32);
Box4 triangleBox4(const Triangle& t) {
  Float4 v0, v1, v2;
  std::memcpy(&v0, &t.v0, sizeof v0);
  std::memcpy(&v1, &t.v1, sizeof v1);
  std::memcpy(&v2, &t.v2, sizeof v2);
  const Float4 lo = min4(min4(min4(splat4(INFINITY), v0), v1), v2);
  const Float4 hi = max4(max4(max4(splat4(-INFINITY), v0), v1), v2);
  return Box4{lo, hi};
}

// Asks the kernel to back [p, p + bytes) with huge pages (Linux's transparent huge pages,
// where they are enabled for regions that ask: the usual "madvise" setting) before the
// range is first touched. A build writes its arrays once and soon frees them, and the first
// touch of each 4 KiB page is a page fault: 35 000 to 40 000 of them for the 1M-triangle
// sphere, 50 to 100 ms of kernel time on the loaded test machine; with 2 MiB pages, 3 000
// and 15 to 25 ms. (A hint: nothing changes where the kernel does not take it.)
void adviseHugePages([[maybe_unused]] const void* p, [[maybe_unused]] size_t bytes) {
#ifdef __linux__
  constexpr uintptr_t kHugePage = uintptr_t(1) << 21;
  const uintptr_t begin = (reinterpret_cast<uintptr_t>(p) + kHugePage - 1) & ~(kHugePage - 1);
  const uintptr_t end = (reinterpret_cast<uintptr_t>(p) + bytes) & ~(kHugePage - 1);
  if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#endif
}

// Memory that the phases of a build hand on to each other: arrays of trivial types at byte
// offsets of one allocation (its own, or memory lent to it), not initialised.
class Block {
 public:
  explicit Block(size_t bytes)
      : owned_(std::make_unique_for_overwrite<uint64_t[]>((bytes + 7) / 8)),
        base_(reinterpret_cast<std::byte*>(owned_.get())) {
    adviseHugePages(base_, bytes);
  }
  // Over `memory` (8-byte aligned), which outlives the block.
  explicit Block(std::byte* memory) : base_(memory) {}
  // `count` objects of type T from byte `offset` on (a multiple of alignof(T)), their
  // lifetimes begun, their values undefined until written.
  template <typename T>
  T* array(size_t offset, size_t count) const {
    static_assert(std::is_trivially_default_constructible_v<T> && alignof(T) <= 8);
    T* const first = reinterpret_cast<T*>(base_ + offset);
    std::uninitialized_default_construct_n(first, count);
    return first;
  }

 private:
  std::unique_ptr<uint64_t[]> owned_;
  std::byte* base_;
};

// The clusters of a round in a Block: their boxes as a structure of arrays, so that the
// neighbour search loads a block of lanes at a time, and their ids. Cluster i is at
// i + kPadding of each box array; the padding on both sides (enough for the last block's
// sixteen lanes too) holds infinite
// boxes, whose merged area is infinite: never anyone's nearest neighbour. The pointers are
// at cluster 0 (the loops keep them in registers, which they could not do with members of a
// class that the stores might alias).
constexpr size_t kPadding = kRadius + 16;
struct ClusterArrays {
  float *lx, *ly, *lz, *hx, *hy, *hz;
  uint32_t* id;

  // Bytes for `n` clusters.
  static size_t bytes(size_t n) { return 6 * (n + 2 * kPadding) * sizeof(float) + n * 4; }
  // The arrays for `n` clusters in `block`, padded in front.
  ClusterArrays(const Block& block, size_t n) {
    float* rows[6];
    for (size_t r = 0; r < 6; ++r) {
      rows[r] = block.array<float>(r * (n + 2 * kPadding) * sizeof(float), n + 2 * kPadding);
      std::fill_n(rows[r], kPadding, r < 3 ? -INFINITY : INFINITY);
      rows[r] += kPadding;
    }
    lx = rows[0], ly = rows[1], lz = rows[2], hx = rows[3], hy = rows[4], hz = rows[5];
    id = block.array<uint32_t>(6 * (n + 2 * kPadding) * sizeof(float), n);
  }
  Box box(size_t i) const { return Box{vec3(lx[i], ly[i], lz[i]), vec3(hx[i], hy[i], hz[i])}; }
  void set(size_t i, const Box& b, uint32_t clusterId) const {
    lx[i] = b.lo.x, ly[i] = b.lo.y, lz[i] = b.lo.z;
    hx[i] = b.hi.x, hy[i] = b.hi.y, hz[i] = b.hi.z;
    id[i] = clusterId;
  }
  // Pads after the first `count` clusters.
  void pad(size_t count) const {
    for (float* row : {lx, ly, lz}) std::fill_n(row + count, kPadding, -INFINITY);
    for (float* row : {hx, hy, hz}) std::fill_n(row + count, kPadding, INFINITY);
  }
};

// found[i - begin] for i in [begin, end): the cluster j within kRadius places of i with the
// least area of the merged box, the lower index on a tie; i itself when every area is
// infinite or NaN. A block of clusters at a time, one per lane (kLanes of them: eight, or
// sixteen with AVX-512). Each pair's area is computed once, by its first cluster (j = i + 1
// .. i + kRadius), and offered to both: to i at once, and to j from a ring of the last
// blocks' areas, where the areas of j's pairs with j - kRadius .. j - 1 lie side by side.
// (The min and max of two numbers do not depend on their order, so it is the area j would
// compute, NaN coordinates aside: this halves the search's work.) The candidates before i
// are offered from the lowest index up, as are those after it, and those after win only
// when strictly less, so "strictly less" keeps the lower index on ties. This loop is much of
// the build time, so it is compiled three times, picked at load time by what the CPU has:
// eight lanes in two SSE registers, eight in one AVX2 register, sixteen in one AVX-512
// register (half the instructions of AVX2: 6 to 8 % of the build). Every version computes
// each pair's area with the same operations, so the tree is the same. (No helper function
// takes or returns vectors wider than 16 bytes by value: that would change its calling
// convention between the versions.)
template <typename FloatN, typename IntN>
[[gnu::always_inline]] inline void findNeighboursIn(const ClusterArrays& c, size_t begin,
                                                    size_t end, uint32_t* found) {
  constexpr size_t kLanes = sizeof(FloatN) / sizeof(float);
  static_assert(sizeof(IntN) == sizeof(FloatN) && kLanes <= kPadding - kRadius + 1);
  const float *lx = c.lx, *ly = c.ly, *lz = c.lz, *hx = c.hx, *hy = c.hy, *hz = c.hz;
  static_assert(kRadius % kLanes == 0);
  constexpr size_t kBehind = kRadius / kLanes;  // blocks that reach into a block
  constexpr size_t kSlots = kBehind + 2;        // with the current one, and room to wrap around
  // ring[k - 1][kLanes * slot + lane]: the area of cluster i + lane's pair with i + lane + k
  // for the block i in that slot, every block stored twice, kSlots slots apart, so that the
  // areas of any kBehind + 1 successive blocks lie side by side.
  alignas(64) float ring[kRadius][2 * kLanes * kSlots];
  IntN laneOffsets;
  FloatN infinity;
  for (size_t lane = 0; lane < kLanes; ++lane) {
    laneOffsets[lane] = int32_t(lane);
    infinity[lane] = INFINITY;
  }
  // The first kBehind blocks, before `begin`, only fill the ring (clusters before 0 are
  // padding: infinite areas).
  size_t block = 0;
  for (ptrdiff_t i = ptrdiff_t(begin) - ptrdiff_t(kRadius); i < ptrdiff_t(end);
       i += ptrdiff_t(kLanes), ++block) {
    // The boxes of the clusters i .. i + kLanes - 1, lane by lane.
    FloatN x0, y0, z0, x1, y1, z1;
    std::memcpy(&x0, lx + i, sizeof x0);
    std::memcpy(&y0, ly + i, sizeof y0);
    std::memcpy(&z0, lz + i, sizeof z0);
    std::memcpy(&x1, hx + i, sizeof x1);
    std::memcpy(&y1, hy + i, sizeof y1);
    std::memcpy(&z1, hz + i, sizeof z1);
    FloatN afterArea = infinity;
    IntN after = laneOffsets + int32_t(i);
    const size_t slot = kLanes * (block % kSlots);
#pragma GCC unroll 16
    for (size_t k = 1; k <= kRadius; ++k) {
      const ptrdiff_t q = i + ptrdiff_t(k);
      FloatN qx0, qy0, qz0, qx1, qy1, qz1;
      std::memcpy(&qx0, lx + q, sizeof qx0);
      std::memcpy(&qy0, ly + q, sizeof qy0);
      std::memcpy(&qz0, lz + q, sizeof qz0);
      std::memcpy(&qx1, hx + q, sizeof qx1);
      std::memcpy(&qy1, hy + q, sizeof qy1);
      std::memcpy(&qz1, hz + q, sizeof qz1);
      // max(a, b) - min(a, b) per axis as a < b ? b : a and b < a ? b : a (maxps, minps).
      const FloatN dx = (x1 < qx1 ? qx1 : x1) - (qx0 < x0 ? qx0 : x0);
      const FloatN dy = (y1 < qy1 ? qy1 : y1) - (qy0 < y0 ? qy0 : y0);
      const FloatN dz = (z1 < qz1 ? qz1 : z1) - (qz0 < z0 ? qz0 : z0);
      const FloatN area = dx * dy + dy * dz + dz * dx;
      std::memcpy(&ring[k - 1][slot], &area, sizeof area);
      std::memcpy(&ring[k - 1][slot + kLanes * kSlots], &area, sizeof area);
      const IntN better = area < afterArea;
      afterArea = better ? area : afterArea;
      after = better ? laneOffsets + int32_t(q) : after;
    }
    if (i < ptrdiff_t(begin)) continue;
    // The pairs with the kRadius clusters before, from the blocks kBehind back on.
    const size_t first = kLanes * ((block - kBehind) % kSlots);
    FloatN beforeArea = infinity;
    IntN before = laneOffsets + int32_t(i);
#pragma GCC unroll 16
    for (size_t k = kRadius; k > 0; --k) {
      FloatN area;
      std::memcpy(&area, &ring[k - 1][first + kRadius - k], sizeof area);
      const IntN better = area < beforeArea;
      beforeArea = better ? area : beforeArea;
      before = better ? laneOffsets + int32_t(i - ptrdiff_t(k)) : before;
    }
    const IntN best = afterArea < beforeArea ? after : before;
    if (size_t(i) + kLanes <= end) {
      std::memcpy(&found[size_t(i) - begin], &best, sizeof best);
    } else {
      for (size_t lane = 0; size_t(i) + lane < end; ++lane) {
        found[size_t(i) - begin + lane] = uint32_t(best[lane]);
      }
    }
  }
}
using Float16 = float __attribute__((vector_size(64)));
using Int16 = int32_t __attribute__((vector_size(64)));
__attribute__((target("default"))) void findNeighbours(const ClusterArrays& c, size_t begin,
                                                       size_t end, uint32_t* found) {
  findNeighboursIn<Float8, Int8>(c, begin, end, found);
}
__attribute__((target("avx2"))) void findNeighbours(const ClusterArrays& c, size_t begin,
                                                    size_t end, uint32_t* found) {
  findNeighboursIn<Float8, Int8>(c, begin, end, found);
}
__attribute__((target("avx512f"))) void findNeighbours(const ClusterArrays& c, size_t begin,
                                                       size_t end, uint32_t* found) {
  findNeighboursIn<Float16, Int16>(c, begin, end, found);
}

// kSpread11[x]: the 11 bits of x spread out so that bit i moves to bit 3i.
constexpr std::array<uint32_t, 2048> kSpread11 = [] {
  std::array<uint32_t, 2048> table{};
  for (uint32_t x = 0; x < table.size(); ++x) {
    for (uint32_t bit = 0; bit < 11; ++bit) table[x] |= (x >> bit & 1u) << 3 * bit;
  }
  return table;
}();

// The Morton code of a point in [0, 1]^3 (lanes x, y, z) by the top 11 bits of each axis'
// 21-bit cell, as mortonCode63(point) >> 30 (bvh.cpp) computes it: cells clamped in float,
// NaN to 0; the bits interleaved z y x from the top.
uint64_t mortonCode33(Float4 unitPoint) {
  constexpr float kCells = float(1 << 21);
  auto quantize = [](float x) {
    const float cell = std::clamp(x * kCells, 0.0f, kCells - 1.0f);
    return cell == cell ? uint64_t(kSpread11[uint32_t(cell) >> 10]) : 0;
  };
  return quantize(unitPoint[0]) | quantize(unitPoint[1]) << 1 | quantize(unitPoint[2]) << 2;
}

// A cluster left by the rounds, as the top levels' splits see and move it: its box, lo and
// -hi (see AxisBins), each in the first 12 bytes of a 16-byte row whose last 4 (its index,
// its triangle count) are masked off when the row is loaded. 32 bytes, so that a split moves
// two per cache line.
struct TopRef {
  float lo[3];
  uint32_t cluster;  // its index in the clusters of the last round
  float negHi[3];
  uint32_t count;  // triangles
};
Float4 topRow(const float* row) {
  Int4 bits;
  std::memcpy(&bits, row, sizeof bits);
  return Float4(bits & Int4{-1, -1, -1, 0});
}
Float4 topLo(const TopRef& r) {
  return topRow(r.lo);
}
Float4 topHi(const TopRef& r) {
  return -topRow(r.negHi);
}
// The centre, doubled: lo + hi (x - (-y) is x + y, to the bit).
Float4 topCenter(const TopRef& r) {
  return topRow(r.lo) - topRow(r.negHi);
}

// The bins of one axis of a top-level split; the first binCount of them are cleared before
// use. A bin's box is lo in lanes 0 to 2 and -hi in lanes 4 to 6: one 8-lane min grows both
// (min(-a, -b) is -max(a, b), to the bit and in which operand it keeps on ties and NaN).
struct AxisBins {
  // (32-byte vectors are only 16-byte aligned where AVX is not enabled, but the AVX2 version
  // of binClusters stores them as aligned.)
  alignas(32) Float8 box[kTopBins];
  uint64_t count[kTopBins];  // triangles in the low 32 bits, clusters in the high 32
};
using Bins = std::array<AxisBins, 3>;
// Grows bin box `acc` by `b` (see AxisBins), as two 4-lane halves: the rest of the top
// levels is compiled without AVX.
[[gnu::always_inline]] inline void grow8(Float8& acc, const Float8& b) {
  Float4 x[2], y[2];
  std::memcpy(x, &acc, sizeof x);
  std::memcpy(y, &b, sizeof y);
  x[0] = min4(x[0], y[0]), x[1] = min4(x[1], y[1]);
  std::memcpy(&acc, x, sizeof x);
}

// Bins the clusters refs[begin, end) on all three axes (centres from `lo` on, `scale` bins
// per unit), noting each one's bins in binIndex. In long ranges even and odd positions fill
// separate bins, merged at the end: runs of clusters in one bin would otherwise wait for
// each other's updates. Short ones (most of them) fill one set: there clearing and merging a
// second would cost more than the waits. Much of the top levels' time, so also compiled for
// AVX2 (picked at load time, below), where a bin grows by one 8-lane min instead of two
// 4-lane ones; the same arithmetic. (Without AVX the 8-lane min would be done lane by lane.)
template <bool kAvx2>
[[gnu::always_inline]] inline void binClustersIn(const TopRef* refs, size_t begin, size_t end,
                                                 Float4 lo, Float4 scale, int binCount, Bins& bins,
                                                 std::array<uint8_t, 3>* binIndex) {
  const Float8 empty = {INFINITY, INFINITY, INFINITY, INFINITY,
                        INFINITY, INFINITY, INFINITY, INFINITY};
  const Int8 mask = {-1, -1, -1, 0, -1, -1, -1, 0};
  const float lastBin = float(binCount - 1);
  Bins odd;
  const bool twoSets = end - begin >= kTopTwoBinSets;
  for (Bins* b : {&bins, &odd}) {
    if (b == &odd && !twoSets) break;
    for (AxisBins& axis : *b) {
      std::fill_n(axis.box, binCount, empty);
      std::fill_n(axis.count, binCount, 0u);
    }
  }
  auto binOne = [&](size_t i, Bins & target) __attribute__((always_inline)) {
    const TopRef& cluster = refs[i];
    Int8 bits;
    std::memcpy(&bits, &cluster, sizeof bits);
    const Float8 box = Float8(bits & mask);
    const Float4 x = (topCenter(cluster) - lo) * scale;
    const uint64_t count = cluster.count | uint64_t(1) << 32;
#pragma GCC unroll 3
    for (size_t a = 0; a < 3; ++a) {
      // std::min(lastBin, x) is lastBin for a NaN x, so the conversion stays defined.
      const int k = int(std::min(lastBin, x[a]));
      binIndex[i][a] = uint8_t(k);
      Float8& bin = target[a].box[k];
      if constexpr (kAvx2) {
        bin = box < bin ? box : bin;
      } else {
        grow8(bin, box);
      }
      target[a].count[k] += count;
    }
  };
  if (!twoSets) {
    for (size_t i = begin; i < end; ++i) binOne(i, bins);
    return;
  }
  // Even positions into `bins`, odd ones into `odd`, two at a time.
  size_t i = begin;
  if (i % 2) binOne(i++, odd);
  for (; i + 1 < end; i += 2) {
    binOne(i, bins);
    binOne(i + 1, odd);
  }
  if (i < end) binOne(i, bins);
  for (size_t a = 0; a < 3; ++a) {
    for (int k = 0; k < binCount; ++k) {
      grow8(bins[a].box[k], odd[a].box[k]);
      bins[a].count[k] += odd[a].count[k];
    }
  }
}
__attribute__((target("default"))) void binClusters(const TopRef* refs, size_t begin, size_t end,
                                                    Float4 lo, Float4 scale, int binCount,
                                                    Bins& bins, std::array<uint8_t, 3>* binIndex) {
  binClustersIn<false>(refs, begin, end, lo, scale, binCount, bins, binIndex);
}
__attribute__((target("avx2"))) void binClusters(const TopRef* refs, size_t begin, size_t end,
                                                 Float4 lo, Float4 scale, int binCount, Bins& bins,
                                                 std::array<uint8_t, 3>* binIndex) {
  binClustersIn<true>(refs, begin, end, lo, scale, binCount, bins, binIndex);
}

#ifdef __x86_64__
// Whether the CPU (and the system) runs AVX-512 (F): then the rounds take compactAvx512.
bool hasAvx512() {
  static const bool has = __builtin_cpu_supports("avx512f");
  return has;
}
#endif

// Per cluster i in [begin, end), given its nearest neighbour found[i - first]: the offset to
// its partner in a merge (partners[i], 0: none), the merges its chunk makes (m: mutual pairs
// counted at their first cluster) and the clusters that survive (s: those without a partner
// and the first of each pair). Also for AVX-512, sixteen clusters at a time, the same counts
// and offsets.
__attribute__((target("default"))) void markPairs(const uint32_t* found, size_t first, size_t begin,
                                                  size_t end, int8_t* partners, uint32_t& m,
                                                  uint32_t& s) {
  for (size_t i = begin; i < end; ++i) {
    const uint32_t j = found[i - first];
    const bool mutual = j != i && found[j - first] == i;
    m += mutual && i < j;
    s += !mutual || i < j;
    partners[i] = int8_t(mutual ? int(j) - int(i) : 0);
  }
}
#ifdef __x86_64__
__attribute__((target("avx512f"))) void markPairs(const uint32_t* found, size_t first, size_t begin,
                                                  size_t end, int8_t* partners, uint32_t& m,
                                                  uint32_t& s) {
  const __m512i lanes = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  const __m512i base = _mm512_set1_epi32(int(first));
  size_t i = begin;
  for (; i + 16 <= end; i += 16) {
    const __m512i self = _mm512_add_epi32(lanes, _mm512_set1_epi32(int(i)));
    const __m512i j = _mm512_loadu_si512(found + (i - first));
    // Every neighbour is within the searched range, whose neighbours `found` holds.
    const __m512i back = _mm512_mask_i32gather_epi32(_mm512_setzero_si512(), 0xFFFF,
                                                     _mm512_sub_epi32(j, base), found, 4);
    const __mmask16 mutual =
        _mm512_cmpneq_epi32_mask(j, self) & _mm512_cmpeq_epi32_mask(back, self);
    const __mmask16 after = _mm512_cmpgt_epu32_mask(j, self);
    m += uint32_t(__builtin_popcount(mutual & after));
    s += uint32_t(__builtin_popcount(__mmask16(~mutual | after)));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(partners + i),
                     _mm512_maskz_cvtepi32_epi8(0xFFFF, _mm512_maskz_sub_epi32(mutual, j, self)));
  }
  for (; i < end; ++i) {
    const uint32_t j = found[i - first];
    const bool mutual = j != i && found[j - first] == i;
    m += mutual && i < j;
    s += !mutual || i < j;
    partners[i] = int8_t(mutual ? int(j) - int(i) : 0);
  }
}
#endif

class PlocBuilder {
 public:
  PlocBuilder(std::vector<Triangle> triangles, size_t leafSize, int depthLimit, Workers& workers)
      : input_(std::move(triangles)),
        n_(input_.size()),
        leafSize_(leafSize),
        depthLimit_(depthLimit),
        workers_(workers),
        sorted_(std::make_unique_for_overwrite<Triangle[]>(n_)),
        innerBlock_(std::max((n_ - 1) * sizeof(Inner), 2 * n_ * sizeof(uint64_t))),
        blocks_{Block(ClusterArrays::bytes(n_)), inputBlock()} {
    adviseHugePages(sorted_.get(), n_ * sizeof(Triangle));
    PT_BVH_PHASE("allocate");
  }

  Bvh build() {
    const uint64_t* keys = mortonKeys();
    return linearize(cluster(keys));
  }

 private:
  // Block 1 in the memory of the input triangles, where it fits (from 77 triangles on): once
  // they are copied in Morton order (sorted_), the rounds' clusters use it, and at the end it
  // holds the output triangles (written as new objects: std::construct_at). Its pages are
  // already touched (the caller wrote the triangles), while fresh memory costs a page fault
  // and the kernel's zeroing of every page, and the vector needs no resize (which would
  // zero it again).
  Block inputBlock() {
    static_assert(alignof(Triangle) >= 4 && __STDCPP_DEFAULT_NEW_ALIGNMENT__ >= 8);
    if (n_ * sizeof(Triangle) < ClusterArrays::bytes(n_)) return Block(ClusterArrays::bytes(n_));
    return Block(reinterpret_cast<std::byte*>(input_.data()));
  }

  // ---- Morton order ----------------------------------------------------------------------

  // The centroid (v0 + v1 + v2) * (1 / 3) as sortByMorton (bvh.cpp) computes it, in lanes
  // x, y, z.
  static Float4 centroid(const Triangle& t) {
    Float4 v0, v1, v2;
    std::memcpy(&v0, &t.v0, sizeof v0);
    std::memcpy(&v1, &t.v1, sizeof v1);
    std::memcpy(&v2, &t.v2, sizeof v2);
    return (v0 + v1 + v2) * splat4(1.0f / 3.0f);
  }

  // The triangles in Morton order of their centroids, normalised to the centroids' bounding
  // box, as sortByMorton (bvh.cpp) orders them with skipBits 30 (its codes, its stable
  // order), here with 8 bytes a triangle: keys code << 31 | triangle index, in the memory
  // of the inner nodes (not written before the first round's merges). Returns the sorted
  // keys. One pass over the triangles stores their centroids (12 bytes a triangle, in block
  // 0, where the first round's clusters go next) and their bounds; the keys are made from
  // the centroids, not from the triangles again (a quarter of the bytes to read). Then a
  // stable LSD radix sort by the code, kDigitBits a pass: each worker counts the digits of
  // its own slice (the first pass's as the keys are made), the counts become output offsets
  // bucket by bucket and, within a bucket, slice by slice (earlier slices first, which keeps
  // the sort stable), and each worker scatters its slice. A pass in which every code has the
  // same digit would move nothing and is skipped.
  const uint64_t* mortonKeys() {
    const size_t n = n_;
    constexpr size_t kBuckets = size_t(1) << kDigitBits;
    constexpr int kFirstShift = 64 - kMortonBits;
    static_assert(kMortonBits % kDigitBits == 0 && kFirstShift >= 31);
    uint64_t* keys = innerBlock_.array<uint64_t>(0, n);
    uint64_t* sorted = innerBlock_.array<uint64_t>(n * sizeof(uint64_t), n);
    float* const centroids = blocks_[0].array<float>(0, 3 * n);
    const int slices = n < kChunk ? 1 : workers_.count();
    auto sliceBegin = [&](int s) { return n * size_t(s) / size_t(slices); };
    auto forSlices = [&](const auto& body) {
      if (slices == 1) {
        body(0);
      } else {
        workers_.run([&](int worker) { body(worker); });
      }
    };
    // The centroids (x, y, z of triangle i at 3i: stored as 16 bytes, the next centroid's x
    // overwriting the fourth, but for each slice's last) and their bounds.
    std::vector<Box4> sliceBounds(static_cast<size_t>(slices));
    forSlices([&](int s) {
      const Triangle* const triangles = input_.data();
      float* const out = centroids;
      const size_t sliceEnd = sliceBegin(s + 1);
      Box4 b{splat4(INFINITY), splat4(-INFINITY)};
      for (size_t i = sliceBegin(s); i < sliceEnd; ++i) {
        const Float4 c = centroid(triangles[i]);
        b = Box4{min4(b.lo, c), max4(b.hi, c)};
        std::memcpy(out + 3 * i, &c, i + 1 < sliceEnd ? sizeof c : 3 * sizeof(float));
      }
      sliceBounds[size_t(s)] = b;
    });
    PT_BVH_PHASE("centroids and their bounds");
    Box4 bounds{splat4(INFINITY), splat4(-INFINITY)};
    for (const Box4& b : sliceBounds) bounds = unite4(bounds, b);
    const Float4 extent = bounds.hi - bounds.lo;
    // A flat axis (all centroids in one plane) gets scale 0 instead of a division by zero.
    Float4 scale = splat4(0.0f);
    for (int a = 0; a < 3; ++a) scale[a] = extent[a] > 0 ? 1 / extent[a] : 0;

    std::vector<size_t> offsets(size_t(slices) * kBuckets);  // [slice][bucket]
    // The keys, in load order, and the counts of the first pass's digits.
    // (The loops take their bounds and pointers in locals: their 8-byte stores could
    // otherwise change the captured sizes, as far as the compiler knows.)
    forSlices([&](int s) {
      size_t* const counts = &offsets[size_t(s) * kBuckets];
      uint64_t* const out = keys;
      const float* const in = centroids;
      const size_t sliceEnd = sliceBegin(s + 1);
      for (size_t i = sliceBegin(s); i < sliceEnd; ++i) {
        const Float4 c = {in[3 * i], in[3 * i + 1], in[3 * i + 2], 0.0f};
        const uint64_t code = mortonCode33((c - bounds.lo) * scale);
        out[i] = code << kFirstShift | i;
        counts[code & (kBuckets - 1)]++;
      }
    });
    PT_BVH_PHASE("Morton keys and first counts");
    for (int shift = kFirstShift; shift < 64; shift += kDigitBits) {
      if (shift != kFirstShift) {
        forSlices([&](int s) {
          size_t* const counts = &offsets[size_t(s) * kBuckets];
          const uint64_t* const in = keys;
          const int digit = shift;
          const size_t sliceEnd = sliceBegin(s + 1);
          std::fill(counts, counts + kBuckets, 0);
          for (size_t i = sliceBegin(s); i < sliceEnd; ++i) {
            counts[(in[i] >> digit) & (kBuckets - 1)]++;
          }
        });
      }
      size_t sum = 0;
      bool oneBucket = false;
      for (size_t b = 0; b < kBuckets; ++b) {
        const size_t bucketStart = sum;
        for (int s = 0; s < slices; ++s) {
          sum += std::exchange(offsets[size_t(s) * kBuckets + b], sum);
        }
        oneBucket |= sum - bucketStart == n;
      }
      if (oneBucket) continue;
      forSlices([&](int s) {
        size_t* const next = &offsets[size_t(s) * kBuckets];
        const uint64_t* const in = keys;
        uint64_t* const out = sorted;
        const int digit = shift;
        const size_t sliceEnd = sliceBegin(s + 1);
        for (size_t i = sliceBegin(s); i < sliceEnd; ++i) {
          out[next[(in[i] >> digit) & (kBuckets - 1)]++] = in[i];
        }
      });
      PT_BVH_PHASE("radix pass (shift " + std::to_string(shift) + ")");
      std::swap(keys, sorted);
    }
    return keys;
  }

  // ---- Clustering ------------------------------------------------------------------------

  // Runs the rounds of nearest-neighbour merging over the triangles in the order of the
  // Morton keys; returns the root's id.
  uint32_t cluster(const uint64_t* keys) {
    // The triangles in Morton order (sorted_, for the linearization) and the first round's
    // clusters, their boxes, in block 0.
    const ClusterArrays triangleClusters(blocks_[0], n_);
    workers_.forChunks(n_, kChunk, [&](size_t begin, size_t end) {
      const ClusterArrays& c = triangleClusters;
      const Triangle* const in = input_.data();
      Triangle* const out = sorted_.get();
      for (size_t i = begin; i < end; ++i) {
        // The triangles are read in Morton order, all over memory: fetch ahead.
        if (i + kPrefetch < end) {
          const char* ahead =
              reinterpret_cast<const char*>(in + (keys[i + kPrefetch] & kIndexMask));
          __builtin_prefetch(ahead);
          __builtin_prefetch(ahead + sizeof(Triangle) - 1);
        }
        const Triangle& t = in[keys[i] & kIndexMask];
        out[i] = t;
        c.set(i, triangleBox(t), uint32_t(i));
      }
    });
    triangleClusters.pad(n_);
    PT_BVH_PHASE("gather in Morton order");
    // The input triangles and the keys are done with: block 1 holds the next round's
    // clusters, and the keys' memory the inner nodes. Not value-initialised: every entry is
    // written before it is read.
    const ClusterArrays clusters[2] = {triangleClusters, ClusterArrays(blocks_[1], n_)};
    inner_ = innerBlock_.array<Inner>(0, n_ - 1);
    // Per cluster of a round: the offset to its partner in a merge (0: none), from -kRadius
    // to kRadius.
    static_assert(kRadius <= 127);
    const auto partner = std::make_unique_for_overwrite<int8_t[]>(n_);
    [[maybe_unused]] int round = 0;
    int current = 0;
    size_t count = n_;
    uint32_t created = 0;  // inner nodes so far
    std::vector<uint32_t> merges, survivors;
    // The rounds stop at n / kClusterShare clusters (see kClusterShare).
    const size_t target = std::max<size_t>(1, n_ / kClusterShare);
    while (count > target) {
      const ClusterArrays &from = clusters[current], &to = clusters[1 - current];
      const size_t chunks = (count + kChunk - 1) / kChunk;
      merges.assign(chunks, 0);
      survivors.assign(chunks, 0);
      // Each chunk finds the neighbours of its clusters and of the kRadius on either side
      // (those its clusters can pair with), so that it can tell the mutual pairs at once,
      // without waiting for the other chunks.
      workers_.forChunks(count, kChunk, [&](size_t begin, size_t end) {
        const size_t first = begin > kRadius ? begin - kRadius : 0;
        const size_t last = std::min(count, end + kRadius);
        std::array<uint32_t, kChunk + 2 * kRadius> found;
        findNeighbours(from, first, last, found.data());
        // (Pointers in locals: the compiler must assume that byte stores change anything
        // else in memory.)
        uint32_t m = 0, s = 0;
        markPairs(found.data(), first, begin, end, partner.get(), m, s);
        merges[begin / kChunk] = m;
        survivors[begin / kChunk] = s;
      });
      PT_BVH_PHASE("round " + std::to_string(++round) + " neighbours (" + std::to_string(count) +
                   ")");
      size_t merged = 0;
      for (uint32_t m : merges) merged += m;
      if (merged < std::max<size_t>(1, count / kMinMergeShare)) {
        // Too little progress: merge clusters 2k and 2k + 1 this round.
        workers_.forChunks(count, kChunk, [&](size_t begin, size_t end) {
          int8_t* const partners = partner.get();
          uint32_t m = 0, s = 0;
          for (size_t i = begin; i < end; ++i) {
            const bool paired = (i ^ 1) < count;
            m += paired && i % 2 == 0;
            s += !paired || i % 2 == 0;
            partners[i] = int8_t(!paired ? 0 : i % 2 ? -1 : 1);
          }
          merges[begin / kChunk] = m;
          survivors[begin / kChunk] = s;
        });
      }
      // Exclusive prefix sums: where each chunk's new nodes and survivors go.
      uint32_t nodeSum = created, outSum = 0;
      for (size_t c = 0; c < chunks; ++c) {
        nodeSum += std::exchange(merges[c], nodeSum);
        outSum += std::exchange(survivors[c], outSum);
      }
      workers_.forChunks(count, kChunk, [&](size_t begin, size_t end) {
        compact(from, to, partner.get(), begin, end, count, merges[begin / kChunk],
                survivors[begin / kChunk]);
      });
      PT_BVH_PHASE("round " + std::to_string(round) + " compact");
      created = nodeSum;
      count = outSum;
      to.pad(count);
      current = 1 - current;
    }
    if (count == 1) return clusters[current].id[0];
    // The other block is free now: it holds the top levels' state.
    return buildTop(clusters[current], count, created, blocks_[1 - current]);
  }

  // Moves the clusters [begin, end) of `from` that do not merge to `to` from position `out`
  // on, in order, and makes the merges, as inner nodes from `node` on, in their place. With
  // AVX-512, sixteen clusters at a time (compactAvx512), the rest one by one.
  void compact(const ClusterArrays& from, const ClusterArrays& to, const int8_t* partner,
               size_t begin, size_t end, size_t count, uint32_t node, uint32_t out) const {
#ifdef __x86_64__
    if (hasAvx512()) {
      const size_t blocksEnd = begin + (end - begin) / 16 * 16;
      compactAvx512(from, to, partner, begin, blocksEnd, count, node, out);
      begin = blocksEnd;
    }
#endif
    compactOneByOne(from, to, partner, begin, end, count, node, out);
  }

#ifdef __x86_64__
  // compact for [begin, end), a whole number of blocks of sixteen clusters, each block with
  // a few vector instructions: the partners' boxes and ids permuted from the 32 clusters from
  // the block's first on (a partner is at most kRadius = 16 places on), the merged boxes
  // (min and max in the operand order of unite: the same boxes), the survivors and the
  // merges compressed into place in order; then the merges' inner nodes one by one, from
  // areas computed by lane (with halfArea's operations). Leaves `node` and `out` past what
  // it wrote.
  __attribute__((target("avx512f"))) void compactAvx512(const ClusterArrays& from,
                                                        const ClusterArrays& to,
                                                        const int8_t* const partner, size_t begin,
                                                        size_t end, size_t count, uint32_t& node,
                                                        uint32_t& out) const {
    static_assert(kRadius == 16, "the partners are permuted from two blocks of sixteen");
    Inner* const inner = inner_;
    const uint32_t n = uint32_t(n_);
    const float* const rows[6] = {from.lx, from.ly, from.lz, from.hx, from.hy, from.hz};
    float* const outRows[6] = {to.lx, to.ly, to.lz, to.hx, to.hy, to.hz};
    const uint32_t* const ids = from.id;
    uint32_t* const outIds = to.id;
    const __m512i lanes = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    const __m512i zero = _mm512_setzero_si512();
    alignas(64) float mergedArea[16], leftArea[16], rightArea[16];
    alignas(64) uint32_t leftId[16], rightId[16];
    for (size_t i = begin; i < end; i += 16) {
      // Partners of the next block: fetch the summaries of those that merge (made rounds
      // ago, by now out of the caches).
      if (i + 32 <= count) {
        const __m512i ahead = _mm512_maskz_cvtepi8_epi32(
            0xFFFF, _mm_loadu_si128(reinterpret_cast<const __m128i*>(partner + i + 16)));
        const __m512i aheadId = _mm512_loadu_si512(ids + i + 16);
        for (unsigned k = _mm512_cmpneq_epi32_mask(ahead, zero) &
                          _mm512_cmpge_epu32_mask(aheadId, _mm512_set1_epi32(int(n)));
             k != 0; k &= k - 1) {
          __builtin_prefetch(&inner[ids[i + 16 + unsigned(__builtin_ctz(k))] - n].summary);
        }
      }
      const __m512i offset = _mm512_maskz_cvtepi8_epi32(
          0xFFFF, _mm_loadu_si128(reinterpret_cast<const __m128i*>(partner + i)));
      const __mmask16 keep = _mm512_cmpge_epi32_mask(offset, zero);
      const __mmask16 merges = _mm512_cmpgt_epi32_mask(offset, zero);
      // Each lane's partner, or itself (the second of a pair is not kept).
      const __m512i index = _mm512_add_epi32(lanes, _mm512_maskz_max_epi32(0xFFFF, offset, zero));
      __m512 box[6], other[6], merged[6];
#pragma GCC unroll 6
      for (int r = 0; r < 6; ++r) {
        // (Rows are padded by more than sixteen after the last cluster.)
        box[r] = _mm512_loadu_ps(rows[r] + i);
        other[r] = _mm512_permutex2var_ps(box[r], index, _mm512_loadu_ps(rows[r] + i + 16));
        // unite(box, other): lo = other < box ? other : box (minps returns its first
        // operand where it is less, else the second), hi = box < other ? other : box.
        merged[r] = r < 3 ? _mm512_maskz_min_ps(0xFFFF, other[r], box[r])
                          : _mm512_maskz_max_ps(0xFFFF, other[r], box[r]);
      }
      const __m512i id = _mm512_loadu_si512(ids + i);
      const size_t rest = count - (i + 16);  // (ids are not padded)
      const __mmask16 nextValid = rest >= 16 ? __mmask16(0xFFFF) : __mmask16((1u << rest) - 1);
      const __m512i otherId =
          _mm512_permutex2var_epi32(id, index, _mm512_maskz_loadu_epi32(nextValid, ids + i + 16));
      // The merges' new ids, n + node on in lane order, in their lanes.
      const __m512i outId = _mm512_mask_expand_epi32(
          id, merges, _mm512_add_epi32(lanes, _mm512_set1_epi32(int(n + node))));
      // Compressed in registers, then stored under a mask of the first lanes (the same
      // values): AMD's Zen 4 runs the compressing store to memory (vcompressps with a memory
      // operand) as slow microcode. On an EPYC (Zen 4) the dragon's seven compactions took
      // 37 ms with it, 12 ms this way.
      const __mmask16 kept = __mmask16((1u << __builtin_popcount(keep)) - 1u);
#pragma GCC unroll 6
      for (int r = 0; r < 6; ++r) {
        _mm512_mask_storeu_ps(outRows[r] + out, kept, _mm512_maskz_compress_ps(keep, merged[r]));
      }
      _mm512_mask_storeu_epi32(outIds + out, kept, _mm512_maskz_compress_epi32(keep, outId));
      out += uint32_t(__builtin_popcount(keep));
      if (merges == 0) continue;
      halfArea16(merged, mergedArea);
      halfArea16(box, leftArea);
      halfArea16(other, rightArea);
      _mm512_store_si512(leftId, id);
      _mm512_store_si512(rightId, otherId);
      auto summaryOf = [&](uint32_t clusterId, float area) {
        return clusterId < n ? Summary{1, 1, kCollapseTriangleCost * area}
                             : inner[clusterId - n].summary;
      };
      for (unsigned k = merges; k != 0; k &= k - 1) {
        const unsigned lane = unsigned(__builtin_ctz(k));
        Inner& parent = inner[node++];
        parent.left = leftId[lane];
        parent.right = rightId[lane];
        parent.summary = merge(mergedArea[lane], summaryOf(leftId[lane], leftArea[lane]),
                               summaryOf(rightId[lane], rightArea[lane]));
      }
    }
  }

  // halfArea of sixteen boxes (lo, hi in b[0..2], b[3..5]), lane by lane, to `area`.
  [[gnu::always_inline]] __attribute__((target("avx512f"))) static inline void halfArea16(
      const __m512* b, float* area) {
    const __m512 dx = _mm512_sub_ps(b[3], b[0]), dy = _mm512_sub_ps(b[4], b[1]),
                 dz = _mm512_sub_ps(b[5], b[2]);
    _mm512_store_ps(area, _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(dx, dy), _mm512_mul_ps(dy, dz)),
                                        _mm512_mul_ps(dz, dx)));
  }
#endif

  // compact one cluster at a time. (Everything in arguments and locals, so that the loop
  // keeps it in registers.)
  void compactOneByOne(const ClusterArrays from, const ClusterArrays to,
                       const int8_t* const partner, size_t begin, size_t end, size_t count,
                       uint32_t node, uint32_t out) const {
    Inner* const inner = inner_;
    const uint32_t n = uint32_t(n_);
    auto summaryOf = [&](uint32_t id, const Box& box) {
      return id < n ? Summary{1, 1, kCollapseTriangleCost * halfArea(box)} : inner[id - n].summary;
    };
    for (size_t i = begin; i < end; ++i) {
      // A merge reads its children's summaries from nodes made rounds ago, by now out of
      // the caches: fetch ahead those of the clusters that will merge.
      if (i + kPrefetch < count && partner[i + kPrefetch] != 0) {
        const uint32_t ahead = from.id[i + kPrefetch];
        if (ahead >= n) __builtin_prefetch(&inner[ahead - n].summary);
      }
      const int offset = partner[i];
      if (offset == 0) {
        to.set(out++, from.box(i), from.id[i]);
      } else if (offset > 0) {  // the pair's first cluster makes the merge
        const size_t j = i + size_t(offset);
        const Box left = from.box(i), right = from.box(j), box = unite(left, right);
        Inner& parent = inner[node];
        parent.left = from.id[i];
        parent.right = from.id[j];
        parent.summary =
            merge(halfArea(box), summaryOf(parent.left, left), summaryOf(parent.right, right));
        to.set(out++, box, n + node++);
      }
    }
  }

  static constexpr uint64_t kIndexMask = 0x7fffffffu;

  // The summary of cluster `id` with box `box`: a triangle's is its own.
  Summary summaryOf(uint32_t id, const Box& box) const {
    return id < n_ ? Summary{1, 1, kCollapseTriangleCost * halfArea(box)} : inner_[id - n_].summary;
  }

  // Subtree sizes by id; a triangle is a leaf of its own.
  uint32_t countOf(uint32_t id) const {
    return id < n_ ? 1u : inner_[id - n_].summary.count;
  }
  uint32_t sizeOf(uint32_t id) const {
    return id < n_ ? 1u : inner_[id - n_].summary.size;
  }

  // The summary of a merge of half area `area` of subtrees summarised by `l` and `r`, deciding
  // the SAH collapse bottom-up as the tree is made: a subtree of at most leafSize triangles
  // becomes one leaf when that costs no more than keeping its best split (costs times area:
  // a leaf costs count * Ci * A, a split Ct * A plus its children's).
  Summary merge(float area, const Summary& l, const Summary& r) const {
    const uint32_t count = l.count + r.count;
    const float splitCost = kCollapseTraversalCost * area + l.cost + r.cost;
    const float leafCost = kCollapseTriangleCost * float(count) * area;
    return count <= leafSize_ && leafCost <= splitCost
               ? Summary{count, 1, leafCost}
               : Summary{count, 1 + l.size + r.size, splitCost};
  }

  // ---- Top levels ------------------------------------------------------------------------

  // The bounds of the clusters' centres (doubled: lo + hi) in lanes x, y, z.
  struct CenterBounds {
    Float4 lo = splat4(INFINITY), hi = splat4(-INFINITY);
    void grow(Float4 center) {
      lo = min4(lo, center);
      hi = max4(hi, center);
    }
    void grow(const CenterBounds& b) {
      lo = min4(lo, b.lo);
      hi = max4(hi, b.hi);
    }
  };
  // What a subtree of the top levels hands its parent.
  struct TopRoot {
    uint32_t id;
    Box4 box;
    Summary summary;
  };
  // A range of clusters to split: refs_[buffer][first, last), its centres within `bounds`.
  struct TopRange {
    size_t first, last;
    int buffer;
    CenterBounds bounds;
  };

  // Builds the levels above the `count` clusters top-down with binned SAH (Wald 2007), in
  // parallel over subtrees as in the LBVH; returns the root's id. A subtree over m clusters
  // owns the m - 1 inner ids from its `base` (its root last, after its children's), so the
  // ids do not depend on the order the subtrees are built in.
  uint32_t buildTop(const ClusterArrays& clusters, size_t count, uint32_t base,
                    const Block& block) {
    topClusters_ = &clusters;
    static_assert(sizeof(TopRef) % alignof(Summary) == 0);
    refs_[0] = block.array<TopRef>(0, count);
    refs_[1] = block.array<TopRef>(count * sizeof(TopRef), count);
    topSummaries_ = block.array<Summary>(2 * count * sizeof(TopRef), count);
    binIndex_ = block.array<std::array<uint8_t, 3>>(
        2 * count * sizeof(TopRef) + count * sizeof(Summary), count);
    std::vector<CenterBounds> chunkBounds((count + kChunk - 1) / kChunk);
    workers_.forChunks(count, kChunk, [&](size_t begin, size_t end) {
      CenterBounds bounds;
      for (size_t i = begin; i < end; ++i) {
        // The clusters' summaries are in nodes made in any round: fetch ahead.
        if (i + kPrefetch < end && clusters.id[i + kPrefetch] >= n_) {
          __builtin_prefetch(&inner_[clusters.id[i + kPrefetch] - n_].summary);
        }
        const Box box = clusters.box(i);
        topSummaries_[i] = summaryOf(clusters.id[i], box);
        TopRef& ref = refs_[0][i];
        ref = TopRef{{box.lo.x, box.lo.y, box.lo.z},
                     uint32_t(i),
                     {-box.hi.x, -box.hi.y, -box.hi.z},
                     topSummaries_[i].count};
        bounds.grow(topCenter(ref));
      }
      chunkBounds[begin / kChunk] = bounds;
    });
    PT_BVH_PHASE("top: references (" + std::to_string(count) + ")");
    TopRange all{0, count, 0, {}};
    for (const CenterBounds& b : chunkBounds) all.bounds.grow(b);
    pieceSize_ = workers_.count() == 1
                     ? count
                     : std::max<size_t>(kTopPieceMin, count / size_t(8 * workers_.count()));
    plan_.clear();
    cut(all, base);
    PT_BVH_PHASE("top: parallel splits");
    std::vector<uint32_t> pieces;
    for (uint32_t i = 0; i < plan_.size(); ++i) {
      if (plan_[i].piece) pieces.push_back(i);
    }
    workers_.forChunks(pieces.size(), 1, [&](size_t p, size_t) {
      TopItem& item = plan_[pieces[p]];
      item.root = buildTopSerial(item.range, item.base);
    });
    PT_BVH_PHASE("top: subtrees");
    for (size_t i = plan_.size(); i-- > 0;) {
      TopItem& item = plan_[i];
      if (!item.piece) {
        item.root = join(item.base + uint32_t(item.range.last - item.range.first) - 2,
                         plan_[i + 1].root, plan_[item.right].root);
      }
    }
    return plan_[0].root.id;
  }

  struct TopItem {
    TopRange range;
    uint32_t base;
    bool piece;          // built whole by one worker; else split here
    uint32_t right = 0;  // a split's right child in plan_ (the left one follows it)
    TopRoot root{};
  };

  // Plans the top levels over `range` depth first, splitting (binning and partitioning in
  // parallel) until the ranges are small enough to share out.
  void cut(const TopRange& range, uint32_t base) {
    const uint32_t item = uint32_t(plan_.size());
    const size_t m = range.last - range.first;
    plan_.push_back(TopItem{range, base, m <= pieceSize_ || m == 1});
    if (plan_[item].piece) return;
    TopRange left, right;
    splitRange(range, true, left, right);
    cut(left, base);
    plan_[item].right = uint32_t(plan_.size());
    cut(right, base + uint32_t(left.last - left.first) - 1);
  }

  TopRoot buildTopSerial(const TopRange& range, uint32_t base) {
    if (range.last - range.first <= kTopSmall) return clusterSmall(range, base);
    TopRange left, right;
    splitRange(range, false, left, right);
    const TopRoot l = buildTopSerial(left, base);
    const TopRoot r = buildTopSerial(right, base + uint32_t(left.last - left.first) - 1);
    return join(base + uint32_t(range.last - range.first) - 2, l, r);
  }

  // Finishes a range of at most kTopSmall clusters as the rounds would, had they a window
  // over all of it: merging the pair whose merged box has the least area until one is left.
  // On a tie the pair with fewer triangles merges (equal boxes make a balanced tree, not a
  // chain), then the first in range order. The last merge, the root, gets the last id.
  // The areas of all pairs are computed once and then only those of each new merge.
  TopRoot clusterSmall(const TopRange& range, uint32_t base) {
    std::array<TopRoot, kTopSmall> part;   // by slot
    std::array<uint8_t, kTopSmall> order;  // the slots still there, in range order
    // By slots, either way round: the pairs' areas and triangle counts as one number that
    // orders them as the comparison above does (see pairKey).
    std::array<std::array<uint64_t, kTopSmall>, kTopSmall> keys;
    size_t m = range.last - range.first;
    for (size_t k = 0; k < m; ++k) {
      const TopRef& ref = refs_[range.buffer][range.first + k];
      part[k] = TopRoot{topClusters_->id[ref.cluster], Box4{topLo(ref), topHi(ref)},
                        topSummaries_[ref.cluster]};
      order[k] = uint8_t(k);
    }
    // (The boxes are united in range order, as a merge would unite them.)
    auto key = [&](size_t first, size_t second) {
      return pairKey(halfArea4(unite4(part[first].box, part[second].box)),
                     part[first].summary.count + part[second].summary.count);
    };
    for (size_t a = 0; a + 1 < m; ++a) {
      for (size_t b = a + 1; b < m; ++b) keys[a][b] = keys[b][a] = key(a, b);
    }
    for (; m > 1; --m) {
      // The first least key (without branches: which pair wins is as good as random).
      uint64_t bestKey = UINT64_MAX;
      size_t best = 1;  // a * kTopSmall + b; the first pair when every area is NaN
      for (size_t a = 0; a + 1 < m; ++a) {
        const auto& row = keys[order[a]];
        for (size_t b = a + 1; b < m; ++b) {
          const uint64_t k = row[order[b]];
          const bool better = k < bestKey;
          bestKey = better ? k : bestKey;
          best = better ? a * kTopSmall + b : best;
        }
      }
      const size_t bestA = best / kTopSmall, bestB = best % kTopSmall;
      const size_t slot = order[bestA];
      part[slot] = join(base++, part[slot], part[order[bestB]]);
      std::copy(order.begin() + ptrdiff_t(bestB) + 1, order.begin() + ptrdiff_t(m),
                order.begin() + ptrdiff_t(bestB));
      for (size_t k = 0; k + 1 < m; ++k) {
        const size_t other = order[k];
        if (k == bestA) continue;
        keys[slot][other] = keys[other][slot] = k < bestA ? key(other, slot) : key(slot, other);
      }
    }
    return part[order[0]];
  }

  // A pair of clusterSmall as one number: lesser when its area is less, or equal with fewer
  // triangles, as floats compare (-0 is 0); NaN areas are never lesser than anything.
  static uint64_t pairKey(float area, uint32_t count) {
    const float a = area + 0.0f;  // -0 + 0 is +0
    if (a != a) return UINT64_MAX;
    uint32_t bits;
    std::memcpy(&bits, &a, sizeof bits);
    // Floats ordered as unsigned integers: negative ones (not areas, but still) reversed.
    bits = bits & 0x80000000u ? ~bits : bits | 0x80000000u;
    return uint64_t(bits) << 32 | count;
  }

  // Makes inner node `node` the parent of two subtrees.
  TopRoot join(uint32_t node, const TopRoot& left, const TopRoot& right) {
    Inner& parent = inner_[node];
    parent.left = left.id;
    parent.right = right.id;
    const Box4 box = unite4(left.box, right.box);
    parent.summary = merge(halfArea4(box), left.summary, right.summary);
    return TopRoot{uint32_t(n_) + node, box, parent.summary};
  }

  // Splits `range` (more than two clusters) where the binned SAH says, keeping Morton order
  // on each side, into `left` and `right`. A range of m clusters gets min(m, kTopBins) bins
  // per axis: most ranges are small. The clusters move to the other buffer, left side first
  // (each side's size is known from the bins, so one pass moves every cluster once), and the
  // pass gathers each side's centre bounds for its own split. With `parallel`, the bins are
  // gathered and the clusters moved by chunks on all workers (the bins merge exactly: min,
  // max, sums; each chunk's clusters go where the counts of the chunks before it say).
  void splitRange(const TopRange& range, bool parallel, TopRange& left, TopRange& right) {
    const size_t first = range.first, last = range.last, m = last - first;
    parallel = parallel && m > kChunk;
    const size_t parts = parallel ? (m + kChunk - 1) / kChunk : 1;
    auto forParts = [&](auto&& body) {
      workers_.forChunks(m, kChunk,
                         [&](size_t b, size_t e) { body(b / kChunk, first + b, first + e); });
    };
    const Float4 lo = range.bounds.lo, hi = range.bounds.hi;
    const int binCount = int(std::min<size_t>(m, kTopBins));
    Float4 scale = splat4(0.0f);
    for (int a = 0; a < 3; ++a) {
      const float extent = hi[a] - lo[a];
      if (extent > 0.0f) scale[a] = float(binCount) / extent;
    }
    const TopRef* from = refs_[range.buffer];
    Bins bins;
    std::vector<Bins> partBins(parallel ? parts : 0);
    if (parallel) {
      forParts([&](size_t part, size_t b, size_t e) {
        binClusters(from, b, e, lo, scale, binCount, partBins[part], binIndex_);
      });
      bins = partBins[0];
      for (size_t p = 1; p < parts; ++p) {
        for (size_t a = 0; a < 3; ++a) {
          for (int k = 0; k < binCount; ++k) {
            grow8(bins[a].box[k], partBins[p][a].box[k]);
            bins[a].count[k] += partBins[p][a].count[k];
          }
        }
      }
    } else {
      binClusters(from, first, last, lo, scale, binCount, bins, binIndex_);
    }
    // Sweep each axis for the least area(left) * count(left) + area(right) * count(right).
    uint32_t total = 0;
    for (int k = 0; k < binCount; ++k) total += uint32_t(bins[0].count[k]);
    // (hi is -(-hi), to the bit.)
    auto area = [](const Float8& box) {
      Float4 lo, negHi;
      std::memcpy(&lo, &box, sizeof lo);
      std::memcpy(&negHi, reinterpret_cast<const char*>(&box) + sizeof lo, sizeof negHi);
      const Float4 d = -negHi - lo;
      return d[0] * d[1] + d[1] * d[2] + d[2] * d[0];
    };
    const Float8 empty = {INFINITY, INFINITY, INFINITY, INFINITY,
                          INFINITY, INFINITY, INFINITY, INFINITY};
    // The three axes side by side, so that their dependency chains (each bin's box grows
    // the last one's) overlap. An empty bin changes neither side: the cost of the right side
    // from it on is the one from the next bin on, and a split after it costs what the split
    // before it costs (not chosen: the first of equal costs wins), so every bin is taken as
    // it comes, without branches.
    std::array<std::array<float, kTopBins>, 3> rightCost, cost;
    Float8 acc[3] = {empty, empty, empty};
    uint32_t count[3] = {0, 0, 0};
    for (int k = binCount - 1; k > 0; --k) {
#pragma GCC unroll 3
      for (size_t a = 0; a < 3; ++a) {
        grow8(acc[a], bins[a].box[k]);
        count[a] += uint32_t(bins[a].count[k]);
        rightCost[a][size_t(k)] = area(acc[a]) * float(count[a]);
      }
    }
    for (size_t a = 0; a < 3; ++a) acc[a] = empty, count[a] = 0;
    for (int k = 1; k < binCount; ++k) {
#pragma GCC unroll 3
      for (size_t a = 0; a < 3; ++a) {
        grow8(acc[a], bins[a].box[k - 1]);
        count[a] += uint32_t(bins[a].count[k - 1]);
        // (NaN: not a split, both sides must have triangles)
        cost[a][size_t(k)] = count[a] == 0 || count[a] == total
                                 ? NAN
                                 : area(acc[a]) * float(count[a]) + rightCost[a][size_t(k)];
      }
    }
    int bestAxis = -1, bestBin = 0;
    float bestCost = INFINITY;
    for (int a = 0; a < 3; ++a) {
      if (scale[a] == 0.0f) continue;
      for (int k = 1; k < binCount; ++k) {
        const float c = cost[size_t(a)][size_t(k)];
        if (c < bestCost) bestCost = c, bestAxis = a, bestBin = k;
      }
    }
    if (bestAxis < 0) {
      // No split separates the centres (all in one bin on every axis): halve in Morton
      // order, in place.
      left = TopRange{first, first + m / 2, range.buffer, centerBounds(from, first, first + m / 2)};
      right = TopRange{first + m / 2, last, range.buffer, centerBounds(from, first + m / 2, last)};
      return;
    }
    auto leftClusters = [&](const Bins& b) {
      size_t sum = 0;
      for (int k = 0; k < bestBin; ++k) sum += size_t(b[size_t(bestAxis)].count[k] >> 32);
      return sum;
    };
    const size_t middle = first + leftClusters(bins);
    PT_CHECK(middle > first && middle < last);
    const int to = 1 - range.buffer;
    left = TopRange{first, middle, to, {}};
    right = TopRange{middle, last, to, {}};
    if (parallel) {
      std::vector<std::array<CenterBounds, 2>> partBounds(parts);
      std::vector<size_t> leftStart(parts), rightStart(parts);
      for (size_t p = 0, l = first, r = middle; p < parts; ++p) {
        leftStart[p] = l, rightStart[p] = r;
        const size_t leftHere = leftClusters(partBins[p]);
        l += leftHere;
        r += std::min(m, (p + 1) * kChunk) - p * kChunk - leftHere;
      }
      forParts([&](size_t part, size_t b, size_t e) {
        partition(from, b, e, bestAxis, bestBin, to, leftStart[part], rightStart[part],
                  partBounds[part]);
      });
      for (const auto& [l, r] : partBounds) left.bounds.grow(l), right.bounds.grow(r);
    } else {
      std::array<CenterBounds, 2> bounds;
      partition(from, first, last, bestAxis, bestBin, to, first, middle, bounds);
      left.bounds = bounds[0], right.bounds = bounds[1];
    }
  }

  CenterBounds centerBounds(const TopRef* refs, size_t begin, size_t end) const {
    CenterBounds bounds;
    for (size_t i = begin; i < end; ++i) bounds.grow(topCenter(refs[i]));
    return bounds;
  }

  // Moves the clusters refs[begin, end) to buffer `to`, those left of the split to
  // positions from `left` on and the others from `right` on, in order; gathers each side's
  // centre bounds.
  void partition(const TopRef* refs, size_t begin, size_t end, int axis, int bin, int to,
                 size_t left, size_t right, std::array<CenterBounds, 2>& bounds) {
    TopRef* out = refs_[to];
    for (size_t i = begin; i < end; ++i) {
      const TopRef& cluster = refs[i];
      const Float4 center = topCenter(cluster);
      if (binIndex_[i][size_t(axis)] < bin) {
        out[left++] = cluster;
        bounds[0].grow(center);
      } else {
        out[right++] = cluster;
        bounds[1].grow(center);
      }
    }
  }

  // ---- Linearization ---------------------------------------------------------------------

  Bvh linearize(uint32_t root) {
    Bvh bvh;
    bvh.triangles = std::move(input_);  // (its memory, block 1, is free again)
    out_ = bvh.triangles.data();
    bvh.nodes.reserve(sizeOf(root));
    adviseHugePages(bvh.nodes.data(), sizeOf(root) * sizeof(BvhNode));
    bvh.nodes.resize(sizeOf(root));
    nodes_ = bvh.nodes.data();
    PT_BVH_PHASE("alloc nodes");
    std::vector<Piece> pieces;
    int maxDepth = plan(root, 0, 0, 0, pieces);
    std::vector<int> pieceDepths(pieces.size());
    workers_.forChunks(pieces.size(), 1, [&](size_t p, size_t) {
      pieceDepths[p] = place(pieces[p].id, pieces[p].position, pieces[p].first, pieces[p].depth);
    });
    PT_BVH_PHASE("linearize");
    for (int depth : pieceDepths) maxDepth = std::max(maxDepth, depth);
    if (maxDepth <= depthLimit_) {
      uniteAbovePieces(root, 0);
      bvh.maxDepth = maxDepth;
      return bvh;
    }
    // Too deep for the traversal stack (rare): start over within it, with every inner node's
    // height and box at hand (children have smaller ids than their parents).
    heights_ = std::make_unique_for_overwrite<int[]>(n_ - 1);
    boxes_ = std::make_unique_for_overwrite<Box[]>(n_ - 1);
    for (size_t k = 0; k + 1 < n_; ++k) {
      const Inner& node = inner_[k];
      heights_[k] =
          node.summary.size == 1 ? 0 : 1 + std::max(heightOf(node.left), heightOf(node.right));
      boxes_[k] = unite(boxOf(node.left), boxOf(node.right));
    }
    bvh.nodes.clear();
    bvh.maxDepth = 0;
    placeWithinStack(root, 0, 0, bvh.nodes, bvh.maxDepth);
    return bvh;
  }

  struct Piece {
    uint32_t id, position, first;
    int depth;
  };

  // The top of the collapsed tree of `id`, at `depth`, with its root at nodes_[position] and
  // its triangles from out_[first] on: lists the subtrees of at most kPieceSize triangles
  // (and the leaves above them) in `pieces` for the workers to place, and notes the right
  // children of the inner nodes above them (their boxes are left to uniteAbovePieces).
  // Returns the depth of the deepest leaf above the pieces (or of one below depthLimit_:
  // then the tree is too deep and not all listed).
  int plan(uint32_t id, uint32_t position, uint32_t first, int depth, std::vector<Piece>& pieces) {
    if (depth > depthLimit_) return depth;
    if (!aboveThePieces(id)) {
      pieces.push_back(Piece{id, position, first, depth});
      return depth;
    }
    const Inner& node = inner_[id - n_];
    const uint32_t right = position + 1 + sizeOf(node.left);
    nodes_[position] = BvhNode{vec3(0.0f), right, vec3(0.0f), 0u};
    const int leftDepth = plan(node.left, position + 1, first, depth + 1, pieces);
    return std::max(leftDepth,
                    plan(node.right, right, first + countOf(node.left), depth + 1, pieces));
  }

  bool aboveThePieces(uint32_t id) const {
    return id >= n_ && inner_[id - n_].summary.size > 1 &&
           inner_[id - n_].summary.count > kPieceSize;
  }

  // The boxes of the inner nodes above the pieces, once the pieces are written.
  Box uniteAbovePieces(uint32_t id, uint32_t position) {
    BvhNode& out = nodes_[position];
    if (aboveThePieces(id)) {
      const Inner& node = inner_[id - n_];
      const Box box = unite(uniteAbovePieces(node.left, position + 1),
                            uniteAbovePieces(node.right, out.offset));
      out.boundsMin = box.lo;
      out.boundsMax = box.hi;
    }
    return Box{out.boundsMin, out.boundsMax};
  }

  // Writes the collapsed subtree of `id`, at `depth` in the tree, with its root at
  // nodes_[position] and its triangles from out_[first] on, depth first, left child first;
  // returns the depth of its deepest leaf.
  int place(uint32_t id, uint32_t position, uint32_t first, int depth) {
    return placeNodes(id, position, first, depth).depth;
  }

  // The triangles of the subtree of `id` in depth-first order, to out_[first] on.
  void copyTriangles(uint32_t id, uint32_t first) {
    leafBox(id, first);
  }

  // What placeNodes hands its caller: the subtree's box (Box4) and the depth of its deepest
  // leaf.
  struct Placed {
    Box4 box;
    int depth;
  };

  // The nodes and triangles of place. The triangles of a subtree lie close together in
  // sorted_ (in Morton order), so the copies mostly hit the caches.
  Placed placeNodes(uint32_t id, uint32_t position, uint32_t first, int depth) {
    if (id < n_) {
      const Box4 box = copyTriangle(id, first);
      writeNode(position, box, first, 1);
      return Placed{box, depth};
    }
    const Inner& node = inner_[id - n_];
    if (node.right >= n_) __builtin_prefetch(&inner_[node.right - n_]);
    if (node.summary.size == 1) {  // collapsed into a leaf
      uint32_t next = first;
      const Box4 box = leafBox(id, next);
      writeNode(position, box, first, node.summary.count);
      return Placed{box, depth};
    }
    const uint32_t right = position + 1 + sizeOf(node.left);
    const Placed l = placeNodes(node.left, position + 1, first, depth + 1);
    const Placed r = placeNodes(node.right, right, first + countOf(node.left), depth + 1);
    const Box4 box = unite4(l.box, r.box);
    writeNode(position, box, right, 0);
    return Placed{box, std::max(l.depth, r.depth)};
  }

  // Copies the triangles of the subtree of `id` to out_ from `first` on (`first` moves past
  // them) and returns their box, united as the merges united them.
  Box4 leafBox(uint32_t id, uint32_t& first) {
    if (id < n_) return copyTriangle(id, first++);
    const Inner& node = inner_[id - n_];
    const Box4 left = leafBox(node.left, first);
    return unite4(left, leafBox(node.right, first));
  }

  // Copies the triangle of Morton rank `rank` to out_[at]; returns its box.
  Box4 copyTriangle(uint32_t rank, uint32_t at) {
    const Triangle& t = sorted_[rank];
    std::construct_at(out_ + at, t);
    return triangleBox4(t);
  }

  void writeNode(uint32_t position, const Box4& box, uint32_t offset, uint32_t count) {
    Int4 lo = Int4(box.lo), hi = Int4(box.hi);  // (bit casts)
    lo[3] = int32_t(offset);
    hi[3] = int32_t(count);
    static_assert(sizeof(BvhNode) == sizeof lo + sizeof hi);
    std::memcpy(reinterpret_cast<char*>(&nodes_[position]), &lo, sizeof lo);
    std::memcpy(reinterpret_cast<char*>(&nodes_[position]) + sizeof lo, &hi, sizeof hi);
  }

  // The box of `id` (boxes_ is set).
  Box boxOf(uint32_t id) const {
    return id < n_ ? triangleBox(sorted_[id]) : boxes_[id - n_];
  }

  // The depth of the deepest leaf below `id` in its collapsed form (heights_ is set).
  int heightOf(uint32_t id) const {
    return id < n_ ? 0 : heights_[id - n_];
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
      place(id, uint32_t(position), first, depth);
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
      const Box& box = boxes_[id - n_];
      nodes.push_back(BvhNode{box.lo, 0u, box.hi, 0u});
      maxDepth = std::max(maxDepth, depth);
      placeWithinStack(node.left, depth + 1, first, nodes, maxDepth);
      nodes[position].offset = uint32_t(nodes.size());
      placeWithinStack(node.right, depth + 1, first + leftCount, nodes, maxDepth);
      return;
    }
    copyTriangles(id, first);
    auto middle = [](size_t begin, size_t end, int) { return begin + (end - begin) / 2; };
    RangeEmitter<decltype(middle)> emitter(out_, leafSize_, middle, nodes);
    emitter.emit(first, first + leftCount + rightCount, depth);
    maxDepth = std::max(maxDepth, emitter.maxDepth());
  }

  // The triangles as given, until they are copied in Morton order; then the memory of block
  // 1; then the output.
  std::vector<Triangle> input_;
  const size_t n_;
  const size_t leafSize_;
  const int depthLimit_;  // deepest leaf allowed: kBvhStackSize, less in tests
  Workers& workers_;
  std::unique_ptr<Triangle[]> sorted_;  // the triangles in Morton order (by id)
  // The Morton keys, then the inner nodes (inner_).
  Block innerBlock_;
  // Scratch memory: the centroids, then the clusters of the rounds (ping-ponging between the
  // two blocks), then the top levels' state.
  Block blocks_[2];
  Inner* inner_ = nullptr;
  // By inner node, only for a tree too deep for the stack: heights and boxes.
  std::unique_ptr<int[]> heights_;
  std::unique_ptr<Box[]> boxes_;
  // The top levels' state: the clusters left by the rounds, the references to them that the
  // splits move between two buffers, their bins by position, the plan of the subtrees shared
  // out, and their size.
  const ClusterArrays* topClusters_ = nullptr;
  TopRef* refs_[2] = {nullptr, nullptr};
  Summary* topSummaries_ = nullptr;             // by cluster
  std::array<uint8_t, 3>* binIndex_ = nullptr;  // by position: bin per axis
  std::vector<TopItem> plan_;
  size_t pieceSize_ = 0;
  BvhNode* nodes_ = nullptr;
  Triangle* out_ = nullptr;
};

}  // namespace

Bvh buildPlocBvh(std::vector<Triangle> triangles, size_t leafSize, Workers& workers,
                 int depthLimit) {
  PT_CHECK(triangles.size() < (size_t(1) << 31), "ids of triangles and merges share 32 bits");
  PT_CHECK(depthLimit >= balancedLevels(triangles.size(), leafSize));
  return PlocBuilder(std::move(triangles), leafSize, depthLimit, workers).build();
}

}  // namespace pt
