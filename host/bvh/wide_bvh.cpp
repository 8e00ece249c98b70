// Collapse of the binary BVH into the wide one; see wide_bvh.h. (The traversal is in
// wide_traverse.cpp, compiled once per instruction set.)
#include "bvh/wide_bvh.h"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <thread>
#include <type_traits>
#include <vector>

#ifdef __linux__
#include <sys/mman.h>
#include <unistd.h>
#endif
#ifdef PT_BVH_PROFILE
#include <cstdio>
#include <cstdlib>
#endif

#include "bvh/workers.h"
#include "common/check.h"

namespace pt {
namespace {

// The lanes of the wide node of binary node `index`, found greedily from the node's two
// children on: each step takes the lane whose opening or splitting saves the most, until
// eight lanes are full or no lane can be opened or split (the first of equal ones). Opening
// an interior lane puts its two children in its place (the collapse of Embree's and of
// Ylitie et al.'s wide BVHs, greedy on area: a ray enters a child in proportion to its area,
// so the large ones are worth testing together); it saves the lane's area, the chance of a
// visit to a wide node of its own. Splitting a leaf of two packets or more puts its triangles
// in two lanes, the same packets each under a box of its own (splitPlan); it saves the
// packet tests of the rays that enter the leaf's box but not a part's. The lanes keep the
// binary tree's depth-first order, so that each binary node in between (and each split
// leaf) covers a range of consecutive lanes; laneShape records those ranges for the
// traversal of degenerate rays (WideBvh::shapes). (The root of a tree that is one leaf is
// its own node's only lane.)
//
// Counted (traversal counters in a local build, over ray_bench's primary, bounce and shadow
// rays, per query): bunny-dragon's wide tree tested 3.08 packets in 3.97 nodes before leaves
// were split, 2.02 in 4.26 after (SAH cost in Embree's form, nodes + packets: 4.32 + 3.93
// before, 4.67 + 2.97 after); the sphere's 1.82 in 6.96 before, 1.58 in 6.97 after.
// Splitting leaves only into lanes left over once no interior lane could be opened gave 2.89
// in 3.97 on bunny-dragon; callgrind counted 5 % more instructions per query than this.
struct Lane {
  uint32_t node;       // the binary node, or the leaf that a split lane is part of
  uint32_t first;      // a leaf lane's triangles: [first, first + triangles) of
  uint32_t triangles;  // Bvh::triangles; 0 for an interior lane
  vec3 lo, hi;         // the lane's box
  float gain;          // what opening or splitting it saves; < 0: neither can be done
  uint32_t cut;        // a leaf's split: its first part's triangles (splitPlan)
  bool planned;        // gain and cut are set (a leaf's are left until they may matter)
};
struct NodeLanes {
  Lane lane[kWideLanes];
  int count = 0;                    // lanes in use
  uint32_t opened[kWideLanes - 1];  // the binary nodes in between, `index` first, and the
  int openedCount = 0;              // split leaves, in the order they were opened
};

float halfArea(vec3 lo, vec3 hi) {
  const vec3 e = hi - lo;
  return e.x * e.y + e.y * e.z + e.z * e.x;
}

uint32_t packetsOf(uint32_t triangles) {
  return (triangles + kPacketLanes - 1) / kPacketLanes;
}

// The box of triangles [begin, end) of Bvh::triangles.
void boxOf(const Bvh& bvh, uint32_t begin, uint32_t end, vec3& lo, vec3& hi) {
  lo = vec3(INFINITY);
  hi = vec3(-INFINITY);
  for (uint32_t i = begin; i < end; ++i) {
    const Triangle& t = bvh.triangles[i];
    lo = min(min(lo, t.v0), min(t.v1, t.v2));
    hi = max(max(hi, t.v0), max(t.v1, t.v2));
  }
}

// A leaf lane's split into two lanes of consecutive triangles: among the cuts that keep the
// packets as many (at a multiple of four from either end), the one whose parts' areas times
// their packets add up least (the first such). Sets `cut` and `gain`, the SAH cost it saves
// (packets times area, before less after), or gain -1 where no cut saves anything. (With
// the CPU's leaves of up to eight triangles, a leaf of five to eight becomes two of up to
// four.) Leaves of more than kMaxSplitLeaf triangles are left whole.
constexpr uint32_t kMaxSplitLeaf = 64;
void splitPlan(const Bvh& bvh, Lane& lane) {
  lane.gain = -1.0f;
  lane.planned = true;
  const uint32_t n = lane.triangles;
  if (packetsOf(n) < 2 || n > kMaxSplitLeaf) return;
  // The boxes of the triangles, then of those after each cut k (at k).
  vec3 lo[kMaxSplitLeaf], hi[kMaxSplitLeaf], afterLo[kMaxSplitLeaf], afterHi[kMaxSplitLeaf];
  for (uint32_t i = 0; i < n; ++i) {
    const Triangle& t = bvh.triangles[lane.first + i];
    lo[i] = min(min(t.v0, t.v1), t.v2);
    hi[i] = max(max(t.v0, t.v1), t.v2);
  }
  afterLo[n - 1] = lo[n - 1];
  afterHi[n - 1] = hi[n - 1];
  for (uint32_t k = n - 1; k-- > 1;) {
    afterLo[k] = min(lo[k], afterLo[k + 1]);
    afterHi[k] = max(hi[k], afterHi[k + 1]);
  }
  const float whole = float(packetsOf(n)) * halfArea(lane.lo, lane.hi);
  vec3 beforeLo = lo[0], beforeHi = hi[0];  // of the triangles before cut k
  for (uint32_t k = 1; k < n; ++k) {
    beforeLo = min(beforeLo, lo[k - 1]);
    beforeHi = max(beforeHi, hi[k - 1]);
    if (packetsOf(k) + packetsOf(n - k) != packetsOf(n)) continue;
    const float gain = whole - (float(packetsOf(k)) * halfArea(beforeLo, beforeHi) +
                                float(packetsOf(n - k)) * halfArea(afterLo[k], afterHi[k]));
    if (gain > std::max(lane.gain, 0.0f)) {
      lane.gain = gain;
      lane.cut = k;
    }
  }
}

void laneNodes(const Bvh& bvh, uint32_t index, NodeLanes& lanes) {
  auto laneOf = [&](uint32_t n) {
    const BvhNode& node = bvh.nodes[n];
    const float area = halfArea(node.boundsMin, node.boundsMax);
    Lane lane{n, 0, 0, node.boundsMin, node.boundsMax, area, 0, true};
    if (node.count > 0) {  // a split saves at most its packets times its area
      lane.first = node.offset;
      lane.triangles = node.count;
      lane.gain = packetsOf(node.count) >= 2 ? float(packetsOf(node.count)) * area : -1.0f;
      lane.planned = lane.gain < 0.0f;
    }
    return lane;
  };
  lanes.count = 1;
  lanes.openedCount = 0;
  lanes.lane[0] = laneOf(index);
  if (bvh.nodes[index].count > 0) return;
  // Lane i becomes lanes i and i + 1; returns them.
  auto insertAfter = [&](int i) -> Lane* {
    std::copy_backward(lanes.lane + i + 1, lanes.lane + lanes.count, lanes.lane + lanes.count + 1);
    ++lanes.count;
    lanes.opened[lanes.openedCount++] = lanes.lane[i].node;
    return lanes.lane + i;
  };
  for (;;) {
    // (A leaf's plan is made only where its bound beats the best so far: the choice is the
    // one that planning every leaf would give.)
    int best = -1;
    for (int i = 0; i < lanes.count; ++i) {
      Lane& lane = lanes.lane[i];
      if (best >= 0 && !(lane.gain > lanes.lane[best].gain)) continue;
      if (!lane.planned) splitPlan(bvh, lane);
      if (best < 0 || lane.gain > lanes.lane[best].gain) best = i;
    }
    if (lanes.lane[best].gain < 0.0f) break;
    Lane* pair = insertAfter(best);
    if (pair[0].triangles == 0) {  // open
      const uint32_t n = pair[0].node;
      pair[0] = laneOf(n + 1);
      pair[1] = laneOf(bvh.nodes[n].offset);
    } else {  // split
      const uint32_t cut = pair[0].cut;
      pair[1].first = pair[0].first + cut;
      pair[1].triangles = pair[0].triangles - cut;
      pair[0].triangles = cut;
      for (int part = 0; part < 2; ++part) {
        boxOf(bvh, pair[part].first, pair[part].first + pair[part].triangles, pair[part].lo,
              pair[part].hi);
        pair[part].gain = -1.0f;  // (split once)
        pair[part].planned = true;
      }
    }
    if (lanes.count == kWideLanes) break;
  }
}

// The wide_shape of the lanes of binary node `index`: for each binary node in between and
// each split leaf, in depth-first order, how many lanes its left child (first part) covers,
// and which are split leaves.
uint64_t laneShape(const Bvh& bvh, uint32_t index, const NodeLanes& lanes) {
  uint64_t shape = wide_shape::make(lanes.count);
  const uint32_t* opened = lanes.opened;
  const uint32_t* openedEnd = lanes.opened + lanes.openedCount;
  int split = 0;
  auto record = [&](auto& self, uint32_t n) -> int {
    if (std::find(opened, openedEnd, n) == openedEnd) return 1;
    const int at = split++;
    if (bvh.nodes[n].count > 0) {  // a leaf in two lanes
      shape = wide_shape::withLeafSplit(wide_shape::withSplit(shape, at, 1), at);
      return 2;
    }
    const int left = self(self, n + 1);
    shape = wide_shape::withSplit(shape, at, left);
    return left + self(self, bvh.nodes[n].offset);
  };
  PT_CHECK(record(record, index) == lanes.count);
  return shape;
}

// What Collapse::fill allocates below a wide node: wide nodes (not the node itself), and
// triangle packets (of its leaf lanes and below).
struct Counts {
  size_t nodes = 0, packets = 0;
};

// What Collapse::fill may allocate below binary node `index` (interior), without collapsing
// it: at most one wide node per interior binary node under it (each wide node below it
// stands for a distinct one), and exactly the packets of its leaves (a leaf split into two
// lanes holds the leaf's packets between them). The subtree is the depth-first range from
// `index` to its last node, the end of its rightmost path.
Counts boundBelow(const Bvh& bvh, uint32_t index) {
  uint32_t last = index;
  while (bvh.nodes[last].count == 0) last = bvh.nodes[last].offset;
  Counts bound;
  bound.nodes = size_t(last - index) / 2 - 1;  // (nodes - 1) / 2 interior ones, less `index`
  for (uint32_t n = index; n <= last; ++n) {
    if (bvh.nodes[n].count > 0) bound.packets += packetsOf(bvh.nodes[n].count);
  }
  return bound;
}

// Fills the wide tree depth first: a node's interior children take consecutive slots
// (allocated as the node is filled, before anything below them), and its leaf children's
// packets are consecutive, so that the children a ray visits after one another tend to share
// pages and cache lines. The subtrees below kPieceDepth are filled by the workers: each
// one's packets start where the serial order would put them (the packets of the subtrees
// before it), its slots after the bounds of the slots of those (boundBelow); buildWideBvh
// then closes the gaps, so the tree is the same for any number of workers.
class Collapse {
 public:
  // Wide nodes this deep are the roots of the pieces the workers fill (at most 8^2 = 64).
  static constexpr int kPieceDepth = 2;

  Collapse(const Bvh& bvh, WideBvh& wide, size_t nextNode, size_t nextPacket)
      : bvh_(bvh), wide_(wide), nextNode_(nextNode), nextPacket_(nextPacket) {}

  // A subtree below the top levels: its root `at` (allocated by its parent) over binary node
  // `index`, and where its allocations start.
  struct Piece {
    uint32_t at, index;
    int depth;
    Counts counts;  // boundBelow: its packets, and room for its nodes
    size_t firstNode = 0, firstPacket = 0;
  };

  // With `write`, fills wide node `at` (already allocated) from binary node `index`
  // (interior, or the root when the whole tree is one leaf), then everything below it; but
  // a child at kPieceDepth is listed in `pieces` instead (without `write`: only that,
  // allocating nothing; with it: the piece, already listed in this order, gets its start).
  void fillTop(uint32_t at, uint32_t index, int depth, bool write, std::vector<Piece>& pieces,
               size_t& piece) {
    NodeLanes lanes;
    laneNodes(bvh_, index, lanes);
    if (write) fillNode(at, index, depth, lanes);
    for (int i = 0; i < lanes.count; ++i) {
      if (lanes.lane[i].triangles > 0) continue;
      const uint32_t child = write ? wide_.nodes[at].child[i] : 0;
      if (depth + 1 < kPieceDepth) {
        fillTop(child, lanes.lane[i].node, depth + 1, write, pieces, piece);
      } else if (!write) {
        pieces.push_back(Piece{0, lanes.lane[i].node, depth + 1, {}});
      } else {
        Piece& p = pieces[piece++];
        p.at = child;
        p.firstNode = nextNode_;
        p.firstPacket = nextPacket_;
        nextNode_ += p.counts.nodes;
        nextPacket_ += p.counts.packets;
      }
    }
  }

  // Fills wide node `at` and everything below it.
  void fill(uint32_t at, uint32_t index, int depth) {
    NodeLanes lanes;
    laneNodes(bvh_, index, lanes);
    const WideNode& wide = fillNode(at, index, depth, lanes);
    for (int i = 0; i < kWideLanes; ++i) {
      if (wide.child[i] != kWideEmpty && !(wide.child[i] & kWideLeaf)) {
        fill(wide.child[i], lanes.lane[i].node, depth + 1);
      }
    }
  }

  size_t nodesAllocated() const { return nextNode_; }
  size_t packetsAllocated() const { return nextPacket_; }
  int maxDepth() const { return maxDepth_; }

 private:
  // Wide node `at` from `lanes`, those of binary node `index`, allocating its interior
  // children's slots and packing its leaf children's triangles.
  const WideNode& fillNode(uint32_t at, uint32_t index, int depth, const NodeLanes& lanes) {
    maxDepth_ = std::max(maxDepth_, depth);
    WideNode& wide = wide_.nodes[at];
    wide_.shapes[at] = laneShape(bvh_, index, lanes);
    for (int i = 0; i < kWideLanes; ++i) {
      wide.child[i] = kWideEmpty;
      wide.packetCount[i] = 0;
      // An unused lane's box is inverted, lo = +inf and hi = -inf: no ray enters it, and its
      // slab entry distances, +inf, leave the minima over its group to the others.
      vec3 lo(INFINITY), hi(-INFINITY);
      if (i < lanes.count) {
        const Lane& lane = lanes.lane[i];
        lo = lane.lo;
        hi = lane.hi;
        if (lane.triangles > 0) {
          wide.child[i] = kWideLeaf | uint32_t(nextPacket_);
          wide.packetCount[i] = emitPackets(lane.first, lane.triangles);
        } else {
          wide.child[i] = uint32_t(nextNode_++);
        }
      }
      for (int axis = 0; axis < 3; ++axis) {
        wide.bounds[axis][i] = lo[axis];
        wide.bounds[axis + 3][i] = hi[axis];
      }
    }
    return wide;
  }

  // Packs triangles [first, first + count) four at a time; returns the number of packets.
  uint32_t emitPackets(uint32_t first, uint32_t count) {
    uint32_t packets = 0;
    for (uint32_t begin = first; begin < first + count; begin += kPacketLanes, ++packets) {
      TrianglePacket& p = wide_.packets[nextPacket_++];
      p.first = begin;
      p.count = std::min(uint32_t(kPacketLanes), first + count - begin);
      for (uint32_t lane = 0; lane < uint32_t(kPacketLanes); ++lane) {
        const Triangle& t = bvh_.triangles[begin + std::min(lane, p.count - 1)];
        p.primitive[lane] = t.primitive;
        for (int axis = 0; axis < 3; ++axis) {
          p.v[0][axis][lane] = t.v0[axis];
          p.v[1][axis][lane] = t.v1[axis];
          p.v[2][axis][lane] = t.v2[axis];
        }
      }
    }
    return packets;
  }

  const Bvh& bvh_;
  WideBvh& wide_;
  size_t nextNode_, nextPacket_;  // the next slot and packet to allocate
  int maxDepth_ = 0;
};

// The Counts below the wide node of binary node `index` at `depth` in the top levels, from
// those of the pieces below it (bounds, for nodes; from pieces[piece] on, in the order
// fillTop lists them; `piece` moves past them).
Counts countTop(const Bvh& bvh, uint32_t index, int depth,
                const std::vector<Collapse::Piece>& pieces, size_t& piece) {
  NodeLanes lanes;
  laneNodes(bvh, index, lanes);
  Counts counts;
  for (int i = 0; i < lanes.count; ++i) {
    const Lane& lane = lanes.lane[i];
    if (lane.triangles > 0) {
      counts.packets += packetsOf(lane.triangles);
      continue;
    }
    const Counts below = depth + 1 < Collapse::kPieceDepth
                             ? countTop(bvh, lane.node, depth + 1, pieces, piece)
                             : pieces[piece++].counts;
    counts.nodes += 1 + below.nodes;
    counts.packets += below.packets;
  }
  return counts;
}

// Asks Linux for transparent huge pages over a vector's reserved storage, before it is first
// touched (the usual setting gives them to regions that ask). The traversal's reads jump
// about arrays of tens of megabytes on large scenes; with 4 KiB pages most of them would
// miss the TLB as well (measured: incoherent rays on the 1M-triangle bunny-dragon scene
// trace about 7 % faster). Only whole 2 MiB pages inside the storage are advised; nothing
// changes where the kernel does not take the hint.
template <typename T>
void adviseHugePages([[maybe_unused]] const std::vector<T>& v) {
#ifdef __linux__
  constexpr uintptr_t kHugePage = uintptr_t(1) << 21;
  const uintptr_t start = reinterpret_cast<uintptr_t>(v.data());
  const uintptr_t begin = (start + kHugePage - 1) & ~(kHugePage - 1);
  const uintptr_t end = (start + v.capacity() * sizeof(T)) & ~(kHugePage - 1);
  if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#endif
}

// Gives the pages of a vector's storage past its elements back to the system (Linux; the
// vector is not grown again): the pieces' slots past the gaps were written before the nodes
// moved down, and would otherwise stay resident (40 MB for the 1M-triangle sphere).
template <typename T>
void releaseTail([[maybe_unused]] std::vector<T>& v) {
#ifdef __linux__
  const uintptr_t page = uintptr_t(sysconf(_SC_PAGESIZE));
  const uintptr_t begin =
      (reinterpret_cast<uintptr_t>(v.data() + v.size()) + page - 1) & ~(page - 1);
  const uintptr_t end = reinterpret_cast<uintptr_t>(v.data() + v.capacity()) & ~(page - 1);
  if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_DONTNEED);
#endif
}

// Moves the nodes down over the slots the pieces left unused (piece p used the first
// used[p] of its counts.nodes from firstNode on; the pieces are in the order of their
// slots), and renumbers the interior children to match: one memmove per stretch of used
// slots, then every node's references in parallel.
void closeGaps(WideBvh& wide, const std::vector<Collapse::Piece>& pieces,
               const std::vector<size_t>& used, Workers& workers) {
  static_assert(std::is_trivially_copyable_v<WideNode>);
  // Old index i at or past gapEnd[k] (and before gapEnd[k + 1]) moves down by removed[k].
  std::vector<size_t> gapEnd(pieces.size()), removed(pieces.size());
  size_t from = 0, gone = 0;  // the stretch of used slots that starts at `from`
  auto moveDown = [&](size_t end) {
    if (gone > 0 && end > from) {
      std::memmove(&wide.nodes[from - gone], &wide.nodes[from], (end - from) * sizeof(WideNode));
      std::memmove(&wide.shapes[from - gone], &wide.shapes[from], (end - from) * sizeof(uint64_t));
    }
  };
  for (size_t p = 0; p < pieces.size(); ++p) {
    moveDown(pieces[p].firstNode + used[p]);
    gone += pieces[p].counts.nodes - used[p];
    from = pieces[p].firstNode + pieces[p].counts.nodes;
    gapEnd[p] = from;
    removed[p] = gone;
  }
  moveDown(wide.nodes.size());
  const size_t size = wide.nodes.size() - gone;
  wide.nodes.resize(size);
  wide.shapes.resize(size);
  wide.shapes.shrink_to_fit();
  if (gone == 0) return;
  releaseTail(wide.nodes);
  workers.forChunks(size, 4096, [&](size_t begin, size_t end) {
    for (size_t n = begin; n < end; ++n) {
      for (uint32_t& child : wide.nodes[n].child) {
        if (child == kWideEmpty || (child & kWideLeaf)) continue;
        const size_t k =
            size_t(std::upper_bound(gapEnd.begin(), gapEnd.end(), size_t(child)) - gapEnd.begin());
        if (k > 0) child -= uint32_t(removed[k - 1]);
      }
    }
  });
}

}  // namespace

WideBvh buildWideBvh(const Bvh& bvh, int threads) {
  PT_CHECK(!bvh.nodes.empty() && !bvh.triangles.empty());
  PT_BVH_PROFILE_BEGIN();
  const auto start = std::chrono::steady_clock::now();
  WideBvh wide;
  wide.rootMin = bvh.nodes[0].boundsMin;
  wide.rootMax = bvh.nodes[0].boundsMax;
  // The top levels' pieces, their sizes (counted in parallel), and from them the arrays'.
  std::vector<Collapse::Piece> pieces;
  size_t piece = 0;
  Collapse top(bvh, wide, 1, 0);
  top.fillTop(0, 0, 0, false, pieces, piece);
  // (One worker per hardware thread, fewer for small trees: the work is that of the nodes.)
  const size_t hardware = std::max(1u, std::thread::hardware_concurrency());
  Workers workers(int(
      std::min<size_t>(threads > 0 ? size_t(threads) : hardware, bvh.nodes.size() / 32768 + 1)));
  workers.forChunks(pieces.size(), 1,
                    [&](size_t p, size_t) { pieces[p].counts = boundBelow(bvh, pieces[p].index); });
  // The arrays' sizes from the pieces' (nodes: a bound); then the top again, writing.
  piece = 0;
  const Counts all = countTop(bvh, 0, 0, pieces, piece);
  PT_CHECK(all.packets < size_t(kWideLeaf) && all.nodes < size_t(kWideLeaf),
           "too many triangle packets or nodes");
  wide.nodes.reserve(1 + all.nodes);
  wide.packets.reserve(all.packets);
  adviseHugePages(wide.packets);
  adviseHugePages(wide.nodes);
  wide.nodes.resize(1 + all.nodes);  // (not initialised: see WideNode)
  wide.shapes.resize(1 + all.nodes);
  wide.packets.resize(all.packets);
  PT_BVH_PHASE("count and allocate");
  piece = 0;
  top.fillTop(0, 0, 0, true, pieces, piece);
  PT_BVH_PHASE("fill the top");
  std::vector<int> depths(pieces.size());
  std::vector<size_t> used(pieces.size());  // of each piece's slots
  workers.forChunks(pieces.size(), 1, [&](size_t p, size_t) {
    Collapse collapse(bvh, wide, pieces[p].firstNode, pieces[p].firstPacket);
    collapse.fill(pieces[p].at, pieces[p].index, pieces[p].depth);
    used[p] = collapse.nodesAllocated() - pieces[p].firstNode;
    PT_CHECK(used[p] <= pieces[p].counts.nodes &&
             collapse.packetsAllocated() == pieces[p].firstPacket + pieces[p].counts.packets);
    depths[p] = collapse.maxDepth();
  });
  PT_BVH_PHASE("fill the pieces");
  PT_CHECK(top.nodesAllocated() == wide.nodes.size() &&
           top.packetsAllocated() == wide.packets.size());
  closeGaps(wide, pieces, used, workers);
  PT_BVH_PHASE("close the gaps");
  wide.maxDepth = top.maxDepth();
  for (int depth : depths) wide.maxDepth = std::max(wide.maxDepth, depth);
  wide.buildSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  PT_BVH_PROFILE_END("buildWideBvh");
#ifdef PT_BVH_PROFILE
  if (std::getenv("PT_BVH_HASH")) {
    uint64_t hash = 1469598103934665603ull;
    auto add = [&hash](const void* data, size_t size) {
      const unsigned char* p = static_cast<const unsigned char*>(data);
      for (size_t i = 0; i < size; ++i) hash = (hash ^ p[i]) * 1099511628211ull;
    };
    add(wide.nodes.data(), wide.nodes.size() * sizeof(WideNode));
    add(wide.packets.data(), wide.packets.size() * sizeof(TrianglePacket));
    std::fprintf(stderr, "wide hash %016llx nodes %zu packets %zu depth %d\n",
                 static_cast<unsigned long long>(hash), wide.nodes.size(), wide.packets.size(),
                 wide.maxDepth);
  }
#endif
  return wide;
}

}  // namespace pt
