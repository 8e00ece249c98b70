// Collapse of the binary BVH into the wide one; see wide_bvh.h. (The traversal is in
// wide_traverse.cpp, compiled once per instruction set.)
#include "bvh/wide_bvh.h"

#include <algorithm>
#include <chrono>
#include <cstdint>

#ifdef __linux__
#include <sys/mman.h>
#endif

#include "common/check.h"

namespace pt {
namespace {

// The binary nodes in the lanes of the wide node of binary node `index` (wide_bvh.h): lane i
// holds the descendant reached by the steps i >> 2 & 1, i >> 1 & 1, i & 1 (0 left, 1 right),
// or, where a leaf comes first, that leaf, in the first lane under it. (The root of a tree
// that is one leaf is so its own node's only lane.)
void laneNodes(const Bvh& bvh, uint32_t index, uint32_t (&lanes)[kWideLanes]) {
  std::fill(lanes, lanes + kWideLanes, kWideEmpty);
  // Node n at `level` below `index` covers the `kWideLanes >> level` lanes from `first`.
  auto place = [&](auto& self, uint32_t n, int level, int first) -> void {
    const BvhNode& node = bvh.nodes[n];
    if (node.count > 0 || level == 3) {
      lanes[first] = n;
      return;
    }
    self(self, n + 1, level + 1, first);
    self(self, node.offset, level + 1, first + (kWideLanes >> (level + 1)));
  };
  place(place, index, 0, 0);
}

// The number of wide nodes that Collapse::fill makes of binary node `index` and below: its
// own, and those of its lanes that are interior nodes.
size_t wideNodeCount(const Bvh& bvh, uint32_t index) {
  uint32_t lanes[kWideLanes];
  laneNodes(bvh, index, lanes);
  size_t count = 1;
  for (uint32_t n : lanes) {
    if (n != kWideEmpty && bvh.nodes[n].count == 0) count += wideNodeCount(bvh, n);
  }
  return count;
}

class Collapse {
 public:
  Collapse(const Bvh& bvh, WideBvh& wide) : bvh_(bvh), wide_(wide) {}

  // Fills wide node `at` (already allocated) from binary node `index` (interior, or the
  // root when the whole tree is one leaf), then everything below it. A node's interior
  // children take consecutive slots, and its leaf children's packets are consecutive, so
  // that the children a ray visits after one another tend to share pages and cache lines.
  void fill(uint32_t at, uint32_t index, int depth) {
    wide_.maxDepth = std::max(wide_.maxDepth, depth);
    uint32_t lanes[kWideLanes];
    laneNodes(bvh_, index, lanes);
    WideNode wide;
    for (int i = 0; i < kWideLanes; ++i) {
      wide.child[i] = kWideEmpty;
      wide.packetCount[i] = 0;
      // An unused lane's box is inverted, lo = +inf and hi = -inf: no ray enters it, and its
      // slab entry distances, +inf, leave the minima over its group to the others.
      vec3 lo(INFINITY), hi(-INFINITY);
      if (lanes[i] != kWideEmpty) {
        const BvhNode& b = bvh_.nodes[lanes[i]];
        lo = b.boundsMin;
        hi = b.boundsMax;
        if (b.count > 0) {
          wide.child[i] = kWideLeaf | uint32_t(wide_.packets.size());
          wide.packetCount[i] = emitPackets(b.offset, b.count);
        } else {
          wide.child[i] = uint32_t(wide_.nodes.size());
          wide_.nodes.emplace_back();
        }
      }
      for (int axis = 0; axis < 3; ++axis) {
        wide.bounds[axis][i] = lo[axis];
        wide.bounds[axis + 3][i] = hi[axis];
      }
    }
    wide_.nodes[at] = wide;
    for (int i = 0; i < kWideLanes; ++i) {
      if (wide.child[i] != kWideEmpty && !(wide.child[i] & kWideLeaf)) {
        fill(wide.child[i], lanes[i], depth + 1);
      }
    }
  }

 private:
  // Packs triangles [first, first + count) four at a time; returns the number of packets.
  uint32_t emitPackets(uint32_t first, uint32_t count) {
    uint32_t packets = 0;
    for (uint32_t begin = first; begin < first + count; begin += kPacketLanes, ++packets) {
      TrianglePacket& p = wide_.packets.emplace_back();
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
    PT_CHECK(wide_.packets.size() < size_t(kWideLeaf), "too many triangle packets");
    return packets;
  }

  const Bvh& bvh_;
  WideBvh& wide_;
};

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

}  // namespace

WideBvh buildWideBvh(const Bvh& bvh) {
  PT_CHECK(!bvh.nodes.empty() && !bvh.triangles.empty());
  const auto start = std::chrono::steady_clock::now();
  WideBvh wide;
  // Exact sizes, so that the arrays are allocated once, untouched, and can be advised.
  size_t packets = 0;
  for (const BvhNode& node : bvh.nodes) packets += (node.count + kPacketLanes - 1) / kPacketLanes;
  wide.packets.reserve(packets);
  wide.nodes.reserve(wideNodeCount(bvh, 0));
  adviseHugePages(wide.packets);
  adviseHugePages(wide.nodes);
  wide.rootMin = bvh.nodes[0].boundsMin;
  wide.rootMax = bvh.nodes[0].boundsMax;
  wide.nodes.emplace_back();
  Collapse(bvh, wide).fill(0, 0, 0);
  PT_CHECK(wide.packets.size() == packets && wide.nodes.size() == wide.nodes.capacity());
  wide.buildSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return wide;
}

}  // namespace pt
