// GLSL ray queries on the BVH: watertight ray/triangle intersection (Woop, Benthin and
// Wald 2013), the slab test with Ize's (2013) widened far distance, and iterative traversal
// with a fixed stack, near child first, closest-hit and any-hit. The same algorithms as
// host/bvh/traverse.cpp, written for the GPU on the GPU's layout of the same tree
// (GpuBvhNode, host/vulkan/gpu_bvh.h); the constants kMinDirection and kFarScale come from
// sampling.h, shared with it. Expects sampling.h, the texel buffers `nodeTexels` (the nodes,
// then the triangles: gpuTraversalTexels) and `triangleTexels`, the globals
// `gLoopIterations` and `gTruncated`, and PT_WATERTIGHT (a boolean expression) to be
// declared by the including shader.
//
// Written for lavapipe as much as for GPUs: lavapipe runs eight invocations in the lanes of
// one vector and runs every statement of a loop body on every iteration, both sides of each
// branch with the lanes that did not take it masked off, so what a loop iteration costs is
// all the code in its body, whatever each lane needs; what a fetch costs is how lavapipe
// gathers it (see PT_BINDING_NODES in shared_types.h).

// Rows of four stack entries that traverse keeps (1 to 16): enough for the tree's depth, set
// by the host from it (host/vulkan/gpu_bvh.h, gpuStackRows).
layout(constant_id = PT_SPEC_STACK_ROWS) const uint kStackRows = 16u;

// The structs from their 16-byte rows, fetched as texels (see PT_BINDING_NODES): row k
// holds the struct's members 2k and 2k + 1, a vec3 and a 4-byte scalar, as
// host/common/shared.h checks on the C++ side; the constructors take the members in
// declaration order.
GpuBvhNode loadNode(uint i) {
  int at = int(4u * i);
  uvec4 a = texelFetch(nodeTexels, at);
  uvec4 b = texelFetch(nodeTexels, at + 1);
  uvec4 c = texelFetch(nodeTexels, at + 2);
  uvec4 d = texelFetch(nodeTexels, at + 3);
  return GpuBvhNode(uintBitsToFloat(a.xyz), a.w, uintBitsToFloat(b.xyz), b.w,
                    uintBitsToFloat(c.xyz), c.w, uintBitsToFloat(d.xyz), d.w);
}

Triangle loadTriangle(uint i) {
  int at = int(3u * i);
  uvec4 a = texelFetch(triangleTexels, at);
  uvec4 b = texelFetch(triangleTexels, at + 1);
  uvec4 c = texelFetch(triangleTexels, at + 2);
  return Triangle(uintBitsToFloat(a.xyz), a.w, uintBitsToFloat(b.xyz), b.w, uintBitsToFloat(c.xyz),
                  c.w);
}

struct RayData {
  vec3 origin;
  vec3 direction;
  vec3 invDirection;
  int kx, ky, kz;    // kz: axis of the largest |direction|; (kx, ky) keep the winding
  float sx, sy, sz;  // shear constants
};

// What a triangle test reports.
struct TriangleHit {
  float t;
  vec3 barycentrics;  // weights of v0, v1, v2
};

// What a traversal reports: the hit's distance and triangle. The barycentric weights are
// computed again from these once the traversal is done (hitBarycentrics): carried through
// the loop, they were three more values in its state, which lavapipe spills.
struct HitData {
  float t;
  uint triangle;  // index into the triangle buffer (leaf order)
};

float safeInverse(float d) {
  return 1.0 / (abs(d) < kMinDirection ? (d < 0.0 ? -kMinDirection : kMinDirection) : d);
}

RayData prepareRay(vec3 origin, vec3 direction) {
  RayData r;
  r.origin = origin;
  r.direction = direction;
  r.invDirection =
      vec3(safeInverse(direction.x), safeInverse(direction.y), safeInverse(direction.z));
  vec3 a = abs(direction);
  r.kz = a.x > a.y ? (a.x > a.z ? 0 : 2) : (a.y > a.z ? 1 : 2);
  r.kx = (r.kz + 1) % 3;
  r.ky = (r.kx + 1) % 3;
  if (direction[r.kz] < 0.0) {
    int k = r.kx;
    r.kx = r.ky;
    r.ky = k;
  }
  r.sx = direction[r.kx] / direction[r.kz];
  r.sy = direction[r.ky] / direction[r.kz];
  r.sz = 1.0 / direction[r.kz];
  return r;
}

// Watertight test, both faces, 0 < t < tMax. `precise` forbids fused multiply-adds, which
// would evaluate a shared edge differently for its two triangles and open cracks. The
// rejections are combined into the returned condition rather than taken as early returns
// (each a masked branch on lavapipe), so `hit` means something only when it returns true;
// the values computed, and so the answer, are those of host/bvh/traverse.cpp, operation for
// operation. An edge function of exactly zero may be rounding, and the paper recomputes the
// three in double then. With `exact` this does so (a branch, which GPUs skip); without it,
// it sets `inexact` instead, and the ray is traversed again with `exact` (traceRay here,
// the path tracer's Retrace), so that the answer is the same either way. Lavapipe runs a
// branch's body whether a lane takes it or not: the double arithmetic would cost it on every
// test, and costs it once per ray this way.
bool intersectTriangle(RayData r, Triangle tri, float tMax, bool exact, out TriangleHit hit,
                       out bool inexact) {
  precise vec3 a = tri.v0 - r.origin;
  precise vec3 b = tri.v1 - r.origin;
  precise vec3 c = tri.v2 - r.origin;
  precise float ax = a[r.kx] - r.sx * a[r.kz];
  precise float ay = a[r.ky] - r.sy * a[r.kz];
  precise float bx = b[r.kx] - r.sx * b[r.kz];
  precise float by = b[r.ky] - r.sy * b[r.kz];
  precise float cx = c[r.kx] - r.sx * c[r.kz];
  precise float cy = c[r.ky] - r.sy * c[r.kz];
  precise float u = cx * by - cy * bx;
  precise float v = ax * cy - ay * cx;
  precise float w = bx * ay - by * ax;
  bool zero = u == 0.0 || v == 0.0 || w == 0.0;
  if (exact && zero) {
    u = float(double(cx) * double(by) - double(cy) * double(bx));
    v = float(double(ax) * double(cy) - double(ay) * double(cx));
    w = float(double(bx) * double(ay) - double(by) * double(ax));
  }
  bool mixed = (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0);
  inexact = !exact && zero;
  precise float det = u + v + w;
  precise float az = r.sz * a[r.kz];
  precise float bz = r.sz * b[r.kz];
  precise float cz = r.sz * c[r.kz];
  precise float t = u * az + v * bz + w * cz;
  bool outside = det > 0.0 ? (t <= 0.0 || t >= tMax * det) : (t >= 0.0 || t <= tMax * det);
  float invDet = 1.0 / det;
  hit.t = t * invDet;
  hit.barycentrics = vec3(u, v, w) * invDet;
  return !mixed && det != 0.0 && !outside;
}

// Moller and Trumbore (1997): fewer operations, not watertight. Only for measuring what
// watertightness costs (--intersection fast).
bool intersectTriangleFast(RayData r, Triangle tri, float tMax, out TriangleHit hit) {
  vec3 e1 = tri.v1 - tri.v0;
  vec3 e2 = tri.v2 - tri.v0;
  vec3 p = cross(r.direction, e2);
  float det = dot(e1, p);
  if (det == 0.0) return false;
  float invDet = 1.0 / det;
  vec3 s = r.origin - tri.v0;
  float u = dot(s, p) * invDet;
  if (u < 0.0 || u > 1.0) return false;
  vec3 q = cross(s, e1);
  float v = dot(r.direction, q) * invDet;
  if (v < 0.0 || u + v > 1.0) return false;
  float t = dot(e2, q) * invDet;
  if (t <= 0.0 || t >= tMax) return false;
  hit.t = t;
  hit.barycentrics = vec3(1.0 - u - v, u, v);
  return true;
}

bool intersectBox(RayData r, vec3 lo, vec3 hi, float tMax, out float tNear) {
  vec3 t0 = (lo - r.origin) * r.invDirection;
  vec3 t1 = (hi - r.origin) * r.invDirection;
  // min(t0, t1) and max(t0, t1), chosen by the direction's sign: rounding keeps the order of
  // lo - o <= hi - o, so t0 <= t1 exactly when 1/d > 0 (never 0: safeInverse).
  // A select is one instruction on lavapipe, where min and max take three (NaN handling).
  bvec3 negative = lessThan(r.invDirection, vec3(0.0));
  vec3 tMinV = mix(t0, t1, negative);
  vec3 tMaxV = mix(t1, t0, negative);
  float enter = max(max(tMinV.x, tMinV.y), max(tMinV.z, 0.0));
  float exit = min(min(tMaxV.x, tMaxV.y), min(tMaxV.z, tMax)) * kFarScale;
  tNear = enter;
  return enter <= exit;
}

// Closest hit (anyHit = false) or any hit (true) in 0 < t < tMax. The closest hit is the one
// isCloserHit (sampling.h) prefers, which does not depend on the order the triangles are
// tested in, so the answer is that of every CPU traversal, on any tree: the same distance
// and, where two hits tie, the same triangle. Boxes and triangles are tested against
// searchRange of the closest hit so far. The leaves are visited as host/bvh/traverse.cpp
// visits them (near child first, the left one on a tie; a child pushed is visited without
// testing its box again). A node visit (one fetch serves both children's
// boxes) chooses what comes next: the leaves it meets are tested at once, the near one, then
// the far one when that is the next to visit, and when nothing is left here the next thing
// to visit comes off the stack. One loop iteration takes one step of that: it visits a node
// or tests one triangle, both read by the same four texel fetches from the traversal's
// buffer (a node's four, or a triangle's three and one more; see gpuTraversalTexels), so a
// lavapipe vector's lanes share the fetches and the two steps' arithmetic whichever step each
// takes. Every loop records how it ended: one that ends other than by its own break was cut
// short by lavapipe's silent loop-iteration cap, and sets gTruncated. Without `exact` it
// gives up (returns with `inexact` set) at the first triangle whose test would need the
// recomputation in double (intersectTriangle), and the caller traverses again with it.
// `rootRef` is the root's reference and `triangleTexels` where the triangles start, from
// node 0; the ray enters the root's box.
bool traverse(RayData r, uint rootRef, int triangleTexels, float tMax, bool anyHit, bool exact,
              out HitData best, out bool inexact) {
  inexact = false;
  best.t = tMax;
  best.triangle = 0u;
  // The stack of what to visit later, in variables rather than an array: stack0.x is the top,
  // then stack0.y, ..., stack1.x, ...; a push shifts every entry down one place, a pop up.
  // Lavapipe reads and writes a local array lane by lane, with a branch on each lane's mask,
  // but moves variables for all its lanes at once. The tree's depth bounds the entries (one
  // per interior node above the one visited), and kStackRows rows of four hold them; the
  // rows beyond are compiled out.
  uvec4 stack0 = uvec4(0u), stack1 = uvec4(0u), stack2 = uvec4(0u), stack3 = uvec4(0u);
  uvec4 stack4 = uvec4(0u), stack5 = uvec4(0u), stack6 = uvec4(0u), stack7 = uvec4(0u);
  uvec4 stack8 = uvec4(0u), stack9 = uvec4(0u), stack10 = uvec4(0u), stack11 = uvec4(0u);
  uvec4 stack12 = uvec4(0u), stack13 = uvec4(0u), stack14 = uvec4(0u), stack15 = uvec4(0u);
  uint stackSize = 0u;
  uint ref = rootRef;  // the interior node to visit once no triangle is left, or 0
  // The triangles to test first: [first, end), then [first2, end2) (a leaf, then its sibling).
  uint first = 0u, end = 0u, first2 = 0u, end2 = 0u;
  if ((ref & kGpuBvhLeaf) != 0u) {
    first = (ref & ~kGpuBvhLeaf) >> kGpuBvhCountBits;
    end = first + (ref & kGpuBvhMaxLeafCount);
    ref = 0u;
  }
  uint bestPrimitive = kNoPrimitive;  // kNoPrimitive until a hit is found
  // The traversal loop is inside a second loop only with PT_HIT_FILTER, and is indented as the
  // one loop it is without; the formatter cannot read the two at once.
  // clang-format off
#ifdef PT_HIT_FILTER
  // A closer hit that the includer's filter judges (PT_HIT_FILTERED: an alpha cut-out) is
  // judged outside the traversal loop: lavapipe runs both sides of a branch, so a filter in the
  // loop would cost every step of every ray its texture lookups. The loop stops after the step
  // that meets such a hit, without taking it; the filter judges it below, and the loop goes on
  // from where it stopped. (The step's remainder, the next leaf or a pop, reads nothing of the
  // best hit: taking the hit after it is taking it in the step.)
  bool pending = false;
  Triangle pendingTri;
  TriangleHit pendingHit;
  uint pendingIndex = 0u;
  for (;;) {
    gLoopIterations++;
#endif
  for (;;) {
    gLoopIterations++;
    // searchRange of the closest hit so far (recomputed rather than kept: lavapipe keeps fewer
    // values across iterations in registers)
    float range = bestPrimitive == kNoPrimitive ? tMax : searchRange(best.t, tMax);
    bool testing = first < end;
    int at = testing ? triangleTexels + 3 * int(first) : 4 * int(ref);
    uvec4 a = texelFetch(nodeTexels, at);
    uvec4 b = texelFetch(nodeTexels, at + 1);
    uvec4 c = texelFetch(nodeTexels, at + 2);
    uvec4 d = texelFetch(nodeTexels, at + 3);
    if (testing) {
      // Test the next triangle; a hit that isCloserHit prefers shrinks the search range.
      Triangle tri = Triangle(uintBitsToFloat(a.xyz), a.w, uintBitsToFloat(b.xyz), b.w,
                              uintBitsToFloat(c.xyz), c.w);
      TriangleHit hit;
      bool zeroEdge = false;
      bool hitTriangle = PT_WATERTIGHT ? intersectTriangle(r, tri, range, exact, hit, zeroEdge)
                                       : intersectTriangleFast(r, tri, range, hit);
      inexact = zeroEdge;
      if (inexact) break;
      bool closer = hitTriangle && isCloserHit(hit.t, tri.primitive, best.t, bestPrimitive);
#ifdef PT_HIT_FILTER
      if (closer && PT_HIT_FILTERED(tri)) {
        pending = true;
        pendingTri = tri;
        pendingHit = hit;
        pendingIndex = first;
        closer = false;
      }
#endif
      best.t = closer ? hit.t : best.t;
      best.triangle = closer ? first : best.triangle;
      bestPrimitive = closer ? tri.primitive : bestPrimitive;
      if (anyHit && closer) break;
      first++;
      if (first == end) {  // the sibling leaf next, if any
        first = first2;
        end = end2;
        first2 = 0u;
        end2 = 0u;
      }
    } else {
      // Visit an interior node: the children that the ray enters, nearer first.
      GpuBvhNode node = GpuBvhNode(uintBitsToFloat(a.xyz), a.w, uintBitsToFloat(b.xyz), b.w,
                                   uintBitsToFloat(c.xyz), c.w, uintBitsToFloat(d.xyz), d.w);
      float tLeft, tRight;
      bool hitLeft = intersectBox(r, node.leftMin, node.leftMax, range, tLeft);
      bool hitRight = intersectBox(r, node.rightMin, node.rightMax, range, tRight);
      bool leftFirst = hitLeft && (!hitRight || tLeft <= tRight);
      uint near = hitLeft || hitRight ? (leftFirst ? node.left : node.right) : 0u;
      uint far = hitLeft && hitRight ? (leftFirst ? node.right : node.left) : 0u;
      // A near leaf is tested next, and so is the far child when it is a leaf too, as it is
      // the next thing the binary traversal visits; an interior far child of a leaf is
      // visited after them, without a push.
      if ((near & kGpuBvhLeaf) != 0u) {
        first = (near & ~kGpuBvhLeaf) >> kGpuBvhCountBits;
        end = first + (near & kGpuBvhMaxLeafCount);
        if ((far & kGpuBvhLeaf) != 0u) {
          first2 = (far & ~kGpuBvhLeaf) >> kGpuBvhCountBits;
          end2 = first2 + (far & kGpuBvhMaxLeafCount);
          far = 0u;
        }
        near = far;
        far = 0u;
      }
      if (far != 0u) {
        // Push. (The host sizes the stack from the tree; a push that would drop the bottom
        // entry all the same is reported as a traversal cut short.)
        if (stackSize == 4u * kStackRows) gTruncated = true;
        if (kStackRows > 15u) stack15 = uvec4(stack14.w, stack15.xyz);
        if (kStackRows > 14u) stack14 = uvec4(stack13.w, stack14.xyz);
        if (kStackRows > 13u) stack13 = uvec4(stack12.w, stack13.xyz);
        if (kStackRows > 12u) stack12 = uvec4(stack11.w, stack12.xyz);
        if (kStackRows > 11u) stack11 = uvec4(stack10.w, stack11.xyz);
        if (kStackRows > 10u) stack10 = uvec4(stack9.w, stack10.xyz);
        if (kStackRows > 9u) stack9 = uvec4(stack8.w, stack9.xyz);
        if (kStackRows > 8u) stack8 = uvec4(stack7.w, stack8.xyz);
        if (kStackRows > 7u) stack7 = uvec4(stack6.w, stack7.xyz);
        if (kStackRows > 6u) stack6 = uvec4(stack5.w, stack6.xyz);
        if (kStackRows > 5u) stack5 = uvec4(stack4.w, stack5.xyz);
        if (kStackRows > 4u) stack4 = uvec4(stack3.w, stack4.xyz);
        if (kStackRows > 3u) stack3 = uvec4(stack2.w, stack3.xyz);
        if (kStackRows > 2u) stack2 = uvec4(stack1.w, stack2.xyz);
        if (kStackRows > 1u) stack1 = uvec4(stack0.w, stack1.xyz);
        stack0 = uvec4(far, stack0.xyz);
        stackSize++;
      }
      ref = near;
    }
    if (first == end && ref == 0u) {
      // Nothing left here: the next thing to visit comes off the stack; a leaf is tested next.
      if (stackSize == 0u) break;
      // Pop.
      ref = stack0.x;
      stack0 = uvec4(stack0.yzw, stack1.x);
      if (kStackRows > 1u) stack1 = uvec4(stack1.yzw, stack2.x);
      if (kStackRows > 2u) stack2 = uvec4(stack2.yzw, stack3.x);
      if (kStackRows > 3u) stack3 = uvec4(stack3.yzw, stack4.x);
      if (kStackRows > 4u) stack4 = uvec4(stack4.yzw, stack5.x);
      if (kStackRows > 5u) stack5 = uvec4(stack5.yzw, stack6.x);
      if (kStackRows > 6u) stack6 = uvec4(stack6.yzw, stack7.x);
      if (kStackRows > 7u) stack7 = uvec4(stack7.yzw, stack8.x);
      if (kStackRows > 8u) stack8 = uvec4(stack8.yzw, stack9.x);
      if (kStackRows > 9u) stack9 = uvec4(stack9.yzw, stack10.x);
      if (kStackRows > 10u) stack10 = uvec4(stack10.yzw, stack11.x);
      if (kStackRows > 11u) stack11 = uvec4(stack11.yzw, stack12.x);
      if (kStackRows > 12u) stack12 = uvec4(stack12.yzw, stack13.x);
      if (kStackRows > 13u) stack13 = uvec4(stack13.yzw, stack14.x);
      if (kStackRows > 14u) stack14 = uvec4(stack14.yzw, stack15.x);
      if (kStackRows > 15u) stack15 = uvec4(stack15.yzw, 0u);
      stackSize--;
      if ((ref & kGpuBvhLeaf) != 0u) {
        first = (ref & ~kGpuBvhLeaf) >> kGpuBvhCountBits;
        end = first + (ref & kGpuBvhMaxLeafCount);
        ref = 0u;
      }
    }
#ifdef PT_HIT_FILTER
    if (pending) break;
#endif
  }
#ifdef PT_HIT_FILTER
    if (!pending) break;
    pending = false;
    // A hit the filter drops (an alpha cut-out) is passed by, as if missed.
    if (PT_HIT_FILTER(pendingTri, pendingHit, r)) {
      best.t = pendingHit.t;
      best.triangle = pendingIndex;
      bestPrimitive = pendingTri.primitive;
      if (anyHit) break;
    }
    if (first == end && ref == 0u && stackSize == 0u) break;
  }
#endif
  // clang-format on
  bool found = bestPrimitive != kNoPrimitive;
  // Ended by a break: a hit found for any-hit, a test to redo exactly, or nothing left. (A
  // flag set at each break would not do: the compiler folds it to true, having seen no other
  // way out.)
  if (!(anyHit && found) && !inexact && !(first == end && ref == 0u && stackSize == 0u)) {
    gTruncated = true;
  }
  return found;
}

// The ray prepared, with what traverse needs from node 0 (the root's reference and where the
// triangles start); false, with `best` holding no hit, when the ray misses the root's box.
bool enterRoot(vec3 origin, vec3 direction, float tMax, out RayData r, out uint rootRef,
               out int triangleTexels, out HitData best) {
  r = prepareRay(origin, direction);
  GpuBvhNode root = loadNode(0u);
  rootRef = root.left;
  triangleTexels = int(root.reserved0);
  best = HitData(tMax, 0u);
  float tNear;
  return intersectBox(r, root.leftMin, root.leftMax, tMax, tNear);
}

// Closest hit (anyHit = false) or any hit (true) in 0 < t < tMax by traverse, with the exact
// triangle test or (exact = false) with the one that gives up on an edge function of exactly
// zero: then `inexact` is set and the answer means nothing.
bool traceRayWith(bool exact, vec3 origin, vec3 direction, float tMax, bool anyHit,
                  out HitData best, out bool inexact) {
  RayData r;
  uint rootRef;
  int triangleTexels;
  inexact = false;
  if (!enterRoot(origin, direction, tMax, r, rootRef, triangleTexels, best)) return false;
  return traverse(r, rootRef, triangleTexels, tMax, anyHit, exact, best, inexact);
}

// Closest hit (anyHit = false) or any hit (true) in 0 < t < tMax, as traverse finds it with
// the exact triangle test. A ray meets an edge function of exactly zero rarely, so it is
// traversed with the test that skips the recomputation in double first (see
// intersectTriangle), and again with it when that gave up.
bool traceRay(vec3 origin, vec3 direction, float tMax, bool anyHit, out HitData best) {
  RayData r;
  uint rootRef;
  int triangleTexels;
  if (!enterRoot(origin, direction, tMax, r, rootRef, triangleTexels, best)) return false;
  bool inexact;
  bool found = traverse(r, rootRef, triangleTexels, tMax, anyHit, /*exact=*/false, best, inexact);
  if (inexact) {
    found = traverse(r, rootRef, triangleTexels, tMax, anyHit, /*exact=*/true, best, inexact);
  }
  return found;
}

// The barycentric weights of the hit of the ray from `origin` along `direction` on `tri`, as
// the traversal's triangle test computed them: the same operations on the same values. The
// exact test gives them either way: its recomputation in double changes something only where
// an edge function is exactly zero, and a traversal that met one was redone exactly.
vec3 hitBarycentrics(vec3 origin, vec3 direction, Triangle tri) {
  RayData r = prepareRay(origin, direction);
  TriangleHit hit;
  bool inexact;
  if (PT_WATERTIGHT) {
    intersectTriangle(r, tri, 1.0 / 0.0, /*exact=*/true, hit, inexact);
  } else {
    intersectTriangleFast(r, tri, 1.0 / 0.0, hit);
  }
  return hit.barycentrics;
}
