// LBVH construction on all cores, and buildBvh. Why 63-bit codes: with 21 bits per axis a
// scanned mesh of a million triangles inside a large room still gets distinct codes for
// almost all centroids, where 30-bit codes (1024 cells per axis) put many small triangles in
// one cell and leave their order, and thus the tree, to the midpoint fallback.
//
// Every parallel step gives the result of its serial form exactly (the centroid bounds are a
// min/max, the sort is a stable sort, the hierarchy is cut where the serial recursion cuts
// it), so the tree is the same for any thread count and the same as the serial builder's.
#include "bvh/bvh.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <memory>
#include <thread>
#include <utility>

#include "bvh/bvh_build.h"
#include "common/check.h"

#ifdef PT_BVH_PROFILE
#include <cstdio>
#include <cstdlib>
#endif

namespace pt {
namespace {

// Items per chunk of a parallel loop: enough work that handing out a chunk costs little.
constexpr size_t kGrain = size_t(1) << 14;

// Spreads the low 21 bits of x so that bit i moves to bit 3i, two zero bits after each:
//   x   = ---- ---- ---- ---- ---- ---- ---- ---- ---- ---- ---- ---- ---- ---- ---- dcba
//   out = ---- ---- ---- ---- ---- ---- ---- ---- ---- ---- ---- ---- ---- d--c --b- -a
// (shown for the low four bits). Each step moves the upper half of every group of bits
// left by 32, 16, 8, 4 and 2 places and masks off what is left behind.
uint64_t spreadBits3(uint64_t x) {
  x &= 0x1fffffull;
  x = (x | x << 32) & 0x1f00000000ffffull;
  x = (x | x << 16) & 0x1f0000ff0000ffull;
  x = (x | x << 8) & 0x100f00f00f00f00full;
  x = (x | x << 4) & 0x10c30c30c30c30c3ull;
  x = (x | x << 2) & 0x1249249249249249ull;
  return x;
}

// Runs body(slice) for slices 0 .. slices - 1 of an array cut into equal parts, one per
// worker (slices is 1 or workers.count()).
template <typename Body>
void forSlices(Workers& workers, int slices, const Body& body) {
  if (slices == 1) {
    body(0);
  } else {
    workers.run([&](int worker) { body(worker); });
  }
}

// Stable LSD radix sort of (code, index) pairs by code >> skipBits, 11 bits per pass (6
// passes cover 63 bits). Stable, so equal keys keep load order and the build is
// deterministic. In parallel: each worker counts the digits of its own slice, the counts
// become output offsets bucket by bucket and, within a bucket, slice by slice (earlier slices
// first, which keeps the sort stable), and each worker scatters its slice. A pass in which
// every code has the same digit would move nothing and is skipped.
void radixSort(std::unique_ptr<uint64_t[]>& codes, std::unique_ptr<uint32_t[]>& index, size_t n,
               int skipBits, Workers& workers) {
  constexpr int kBits = 11;
  constexpr size_t kBuckets = size_t(1) << kBits;
  const int slices = n < kGrain ? 1 : workers.count();
  auto sliceBegin = [&](int s) { return n * size_t(s) / size_t(slices); };
  auto codesTmp = std::make_unique_for_overwrite<uint64_t[]>(n);
  auto indexTmp = std::make_unique_for_overwrite<uint32_t[]>(n);
  std::vector<size_t> offsets(size_t(slices) * kBuckets);  // [slice][bucket]
  for (int shift = skipBits; shift < 64; shift += kBits) {
    forSlices(workers, slices, [&](int s) {
      size_t* counts = &offsets[size_t(s) * kBuckets];
      std::fill(counts, counts + kBuckets, 0);
      for (size_t i = sliceBegin(s); i < sliceBegin(s + 1); ++i) {
        counts[(codes[i] >> shift) & (kBuckets - 1)]++;
      }
    });
    size_t sum = 0;
    bool oneBucket = false;
    for (size_t b = 0; b < kBuckets; ++b) {
      const size_t bucketStart = sum;
      for (int s = 0; s < slices; ++s) sum += std::exchange(offsets[size_t(s) * kBuckets + b], sum);
      oneBucket |= sum - bucketStart == n;
    }
    if (oneBucket) continue;
    forSlices(workers, slices, [&](int s) {
      size_t* next = &offsets[size_t(s) * kBuckets];
      for (size_t i = sliceBegin(s); i < sliceBegin(s + 1); ++i) {
        const size_t dst = next[(codes[i] >> shift) & (kBuckets - 1)]++;
        codesTmp[dst] = codes[i];
        indexTmp[dst] = index[i];
      }
    });
    codes.swap(codesTmp);
    index.swap(indexTmp);
  }
}

// Where the LBVH cuts a range of Morton-sorted triangles.
class MortonSplit {
 public:
  MortonSplit(const uint64_t* codes, size_t leafSize) : codes_(codes), leafSize_(leafSize) {}

  size_t operator()(size_t first, size_t last, int depth) const {
    const size_t middle = first + (last - first) / 2;
    // Guarantee the traversal stack: when the Morton split could make this subtree deeper
    // than the stack allows, fall back to a balanced split, which needs the fewest levels.
    if (depth + 1 + balancedLevels(last - first, leafSize_) >= int(kBvhStackSize)) return middle;
    const uint64_t a = codes_[first];
    const uint64_t b = codes_[last - 1];
    // Equal codes (coincident or very close centroids) must still split: halve the range.
    if (a == b) return middle;
    // Karras 2012: the codes are sorted, so the range's first and last code differ in the
    // highest bit any pair in the range differs in; split where that bit turns from 0 to 1.
    const int bit = 63 - std::countl_zero(a ^ b);
    const uint64_t mask = uint64_t(1) << bit;
    const uint64_t* it = std::partition_point(codes_ + first, codes_ + last,
                                              [mask](uint64_t c) { return (c & mask) == 0; });
    return size_t(it - codes_);
  }

 private:
  const uint64_t* codes_;
  size_t leafSize_;
};

// The LBVH in parallel. The top of the tree is cut serially (a handful of nodes) until the
// ranges are small enough to share out; each such range is then emitted by one worker into
// a vector of its own, exactly as the serial recursion would emit it, and the pieces are
// copied into place in depth-first order, their child indices shifted by where they land.
class ParallelLbvh {
 public:
  ParallelLbvh(const std::vector<Triangle>& sorted, const MortonSplit& split, size_t leafSize,
               Workers& workers)
      : sorted_(sorted), split_(split), leafSize_(leafSize), workers_(workers) {
    // With one worker the whole tree is one piece: the serial builder.
    pieceSize_ = workers.count() == 1
                     ? sorted.size()
                     : std::max(kGrain, sorted.size() / size_t(16 * workers.count()));
  }

  void build(std::vector<BvhNode>& nodes, int& maxDepth) {
    cut(0, sorted_.size(), 0);
    std::vector<uint32_t> pieces;
    for (uint32_t i = 0; i < plan_.size(); ++i) {
      if (plan_[i].piece) pieces.push_back(i);
    }
    std::vector<std::vector<BvhNode>> pieceNodes(pieces.size());
    std::vector<int> pieceDepth(pieces.size());
    workers_.forChunks(pieces.size(), 1, [&](size_t p, size_t) {
      const Item& item = plan_[pieces[p]];
      pieceNodes[p].reserve(2 * (item.last - item.first));
      RangeEmitter<MortonSplit> emitter(sorted_.data(), leafSize_, split_, pieceNodes[p]);
      emitter.emit(item.first, item.last, item.depth);
      pieceDepth[p] = emitter.maxDepth();
    });
    // Depth-first positions: a cut node takes one slot, a piece as many as it emitted.
    size_t next = 0;
    maxDepth = 0;
    for (size_t i = 0, p = 0; i < plan_.size(); ++i) {
      plan_[i].position = uint32_t(next);
      if (plan_[i].piece) {
        next += pieceNodes[p].size();
        maxDepth = std::max(maxDepth, pieceDepth[p++]);
      } else {
        next += 1;
        maxDepth = std::max(maxDepth, plan_[i].depth);
      }
    }
    nodes.resize(next);
    workers_.forChunks(pieces.size(), 1, [&](size_t p, size_t) {
      const uint32_t base = plan_[pieces[p]].position;
      BvhNode* out = nodes.data() + base;
      for (const BvhNode& node : pieceNodes[p]) {
        *out = node;
        if (node.count == 0) out->offset += base;  // a right child's index, not a triangle's
        ++out;
      }
    });
    // Cut nodes bottom-up: children come after their parent in the plan.
    for (size_t i = plan_.size(); i-- > 0;) {
      if (plan_[i].piece) continue;
      const BvhNode& left = nodes[plan_[i + 1].position];
      const BvhNode& right = nodes[plan_[plan_[i].right].position];
      Bounds bounds;
      bounds.grow(Bounds{left.boundsMin, left.boundsMax});
      bounds.grow(Bounds{right.boundsMin, right.boundsMax});
      nodes[plan_[i].position] = BvhNode{bounds.lo, plan_[plan_[i].right].position, bounds.hi, 0u};
    }
  }

 private:
  struct Item {
    size_t first, last;
    int depth;
    bool piece;          // emitted whole by one worker; else a node cut in two
    uint32_t right = 0;  // a cut node's right child in plan_ (the left one follows it)
    uint32_t position = 0;
  };

  // Plans the subtree of [first, last) in depth-first order.
  void cut(size_t first, size_t last, int depth) {
    const uint32_t item = uint32_t(plan_.size());
    const size_t count = last - first;
    plan_.push_back(Item{first, last, depth, count <= pieceSize_ || count <= leafSize_});
    if (plan_[item].piece) return;
    const size_t split = split_(first, last, depth);
    PT_CHECK(first < split && split < last);
    cut(first, split, depth + 1);
    plan_[item].right = uint32_t(plan_.size());
    cut(split, last, depth + 1);
  }

  const std::vector<Triangle>& sorted_;
  const MortonSplit& split_;
  size_t leafSize_;
  Workers& workers_;
  size_t pieceSize_;
  std::vector<Item> plan_;
};

Bvh buildLbvh(const std::vector<Triangle>& triangles, size_t leafSize, Workers& workers) {
  const MortonOrder morton = sortByMorton(triangles, 0, workers);
  Bvh bvh;
  bvh.triangles.resize(triangles.size());
  workers.forChunks(triangles.size(), kGrain, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) bvh.triangles[i] = triangles[morton.order[i]];
  });
  const MortonSplit split(morton.codes.get(), leafSize);
  ParallelLbvh(bvh.triangles, split, leafSize, workers).build(bvh.nodes, bvh.maxDepth);
  return bvh;
}

}  // namespace

uint64_t mortonCode63(vec3 unitPoint) {
  constexpr float kCells = float(1 << 21);
  auto quantize = [](float x) {
    // Clamp in float first: x = 1 maps to the last cell, not one past it; NaN maps to 0.
    float cell = std::clamp(x * kCells, 0.0f, kCells - 1.0f);
    return cell == cell ? uint64_t(cell) : 0;
  };
  return spreadBits3(quantize(unitPoint.x)) | spreadBits3(quantize(unitPoint.y)) << 1 |
         spreadBits3(quantize(unitPoint.z)) << 2;
}

MortonOrder sortByMorton(const std::vector<Triangle>& triangles, int skipBits, Workers& workers) {
  const size_t n = triangles.size();
  // Morton codes of the centroids, normalised to the centroids' bounding box (tighter than
  // the scene box, so the 21 bits per axis are spent where the triangles are).
  const auto centroids = std::make_unique_for_overwrite<vec3[]>(n);
  const size_t chunks = (n + kGrain - 1) / kGrain;
  std::vector<Bounds> chunkBounds(chunks);
  workers.forChunks(n, kGrain, [&](size_t begin, size_t end) {
    Bounds b;
    for (size_t i = begin; i < end; ++i) {
      const Triangle& t = triangles[i];
      centroids[i] = (t.v0 + t.v1 + t.v2) * (1.0f / 3.0f);
      b.grow(centroids[i]);
    }
    chunkBounds[begin / kGrain] = b;
  });
  Bounds centroidBounds;
  for (const Bounds& b : chunkBounds) centroidBounds.grow(b);
  const vec3 extent = centroidBounds.hi - centroidBounds.lo;
  // A flat axis (all centroids in one plane) gets scale 0 instead of a division by zero.
  const vec3 scale = vec3(extent.x > 0 ? 1 / extent.x : 0, extent.y > 0 ? 1 / extent.y : 0,
                          extent.z > 0 ? 1 / extent.z : 0);
  MortonOrder morton;
  morton.codes = std::make_unique_for_overwrite<uint64_t[]>(n);
  morton.order = std::make_unique_for_overwrite<uint32_t[]>(n);
  workers.forChunks(n, kGrain, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      morton.codes[i] = mortonCode63((centroids[i] - centroidBounds.lo) * scale);
      morton.order[i] = uint32_t(i);
    }
  });
  radixSort(morton.codes, morton.order, n, skipBits, workers);
  return morton;
}

double sahCostOf(const std::vector<BvhNode>& nodes, Workers& workers) {
  constexpr size_t kChunk = size_t(1) << 15;
  auto area = [](const BvhNode& node) {
    const dvec3 d = max(dvec3(node.boundsMax) - dvec3(node.boundsMin), dvec3(0.0));
    return d.x * d.y + d.y * d.z + d.z * d.x;  // half the surface area: only ratios matter
  };
  // A root without area (every triangle a point, or all on one line) has children without
  // area too: every ray that reaches the root reaches every node, so each ratio counts as 1.
  const double rootArea = area(nodes[0]);
  std::vector<double> partial((nodes.size() + kChunk - 1) / kChunk);
  workers.forChunks(nodes.size(), kChunk, [&](size_t begin, size_t end) {
    double sum = 0.0;
    for (size_t i = begin; i < end; ++i) {
      const double share = rootArea > 0.0 ? area(nodes[i]) / rootArea : 1.0;
      sum += share *
             (nodes[i].count > 0 ? kSahTriangleCost * double(nodes[i].count) : kSahTraversalCost);
    }
    partial[begin / kChunk] = sum;
  });
  double total = 0.0;
  for (double p : partial) total += p;
  return total;
}

Bvh buildBvh(std::vector<Triangle> triangles, const BvhBuildOptions& options) {
  PT_CHECK(!triangles.empty(), "a BVH needs at least one triangle");
  PT_CHECK(options.maxLeafSize >= 1);
  PT_CHECK(options.threads >= 0);
  PT_CHECK(triangles.size() < size_t(UINT32_MAX));
  PT_BVH_PROFILE_BEGIN();
  const auto start = std::chrono::steady_clock::now();
  const size_t leafSize = size_t(options.maxLeafSize);
  // Threads beyond one per chunk of work would only wait.
  int threads = options.threads > 0 ? options.threads
                                    : int(std::max(1u, std::thread::hardware_concurrency()));
  threads = int(std::min(size_t(threads), triangles.size() / kGrain + 1));
#ifdef PT_BVH_PROFILE
  if (const char* forced = std::getenv("PT_BVH_THREADS")) threads = std::atoi(forced);
#endif
  Workers workers(threads);
  PT_BVH_PHASE("start the threads");
  Bvh bvh;
  switch (options.builder) {
    case BvhBuilder::kLbvh:
      bvh = buildLbvh(triangles, leafSize, workers);
      break;
    case BvhBuilder::kBinnedSah:
      bvh = buildBinnedSahBvh(std::move(triangles), leafSize);
      break;
    case BvhBuilder::kPloc:
      bvh = buildPlocBvh(std::move(triangles), leafSize, workers);
      break;
  }
  PT_CHECK(bvh.maxDepth <= int(kBvhStackSize));
  PT_BVH_PHASE("(builder's end)");
  bvh.sahCost = sahCostOf(bvh.nodes, workers);
  PT_BVH_PHASE("SAH cost");
  bvh.buildSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  PT_BVH_PROFILE_END("buildBvh");
#ifdef PT_BVH_PROFILE
  if (std::getenv("PT_BVH_HASH")) {
    // The tree's identity, to check that a change kept it: FNV-1a over the nodes and the
    // triangles' load-order indices.
    uint64_t hash = 1469598103934665603ull;
    auto add = [&hash](const void* data, size_t size) {
      const unsigned char* p = static_cast<const unsigned char*>(data);
      for (size_t i = 0; i < size; ++i) hash = (hash ^ p[i]) * 1099511628211ull;
    };
    add(bvh.nodes.data(), bvh.nodes.size() * sizeof(BvhNode));
    for (const Triangle& t : bvh.triangles) add(&t.primitive, sizeof t.primitive);
    std::fprintf(stderr, "tree hash %016llx nodes %zu sah %.6f depth %d\n",
                 static_cast<unsigned long long>(hash), bvh.nodes.size(), bvh.sahCost,
                 bvh.maxDepth);
  }
#endif
  return bvh;
}

}  // namespace pt
