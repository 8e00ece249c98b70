// GLSL ray queries on the flat BVH: watertight ray/triangle intersection (Woop, Benthin and
// Wald 2013), the slab test with Ize's (2013) widened far distance, and iterative traversal
// with a fixed stack, near child first, closest-hit and any-hit. The same algorithms as
// host/bvh/traverse.cpp, written for the GPU; the constants kMinDirection and kFarScale come
// from sampling.h, shared with it. Expects sampling.h, the buffers `nodes` and `triangles`,
// the globals `gLoopIterations` and `gTruncated`, and PT_WATERTIGHT (a boolean expression) to
// be declared by the including shader.

struct RayData {
  vec3 origin;
  vec3 direction;
  vec3 invDirection;
  int kx, ky, kz;    // kz: axis of the largest |direction|; (kx, ky) keep the winding
  float sx, sy, sz;  // shear constants
};

struct HitData {
  float t;
  vec3 barycentrics;  // weights of v0, v1, v2
  uint triangle;      // index into `triangles`
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
// would evaluate a shared edge differently for its two triangles and open cracks.
bool intersectTriangle(RayData r, Triangle tri, float tMax, out HitData hit) {
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
  // An edge function of exactly zero may be rounding: recompute in double, as the paper does.
  if (u == 0.0 || v == 0.0 || w == 0.0) {
    u = float(double(cx) * double(by) - double(cy) * double(bx));
    v = float(double(ax) * double(cy) - double(ay) * double(cx));
    w = float(double(bx) * double(ay) - double(by) * double(ax));
  }
  if ((u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0)) return false;
  precise float det = u + v + w;
  if (det == 0.0) return false;
  precise float az = r.sz * a[r.kz];
  precise float bz = r.sz * b[r.kz];
  precise float cz = r.sz * c[r.kz];
  precise float t = u * az + v * bz + w * cz;
  if (det > 0.0 ? (t <= 0.0 || t >= tMax * det) : (t >= 0.0 || t <= tMax * det)) return false;
  float invDet = 1.0 / det;
  hit.t = t * invDet;
  hit.barycentrics = vec3(u, v, w) * invDet;
  return true;
}

// Moller and Trumbore (1997): fewer operations, not watertight. Only for measuring what
// watertightness costs (--intersection fast).
bool intersectTriangleFast(RayData r, Triangle tri, float tMax, out HitData hit) {
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
  vec3 tMinV = min(t0, t1);
  vec3 tMaxV = max(t0, t1);
  float enter = max(max(tMinV.x, tMinV.y), max(tMinV.z, 0.0));
  float exit = min(min(tMaxV.x, tMaxV.y), min(tMaxV.z, tMax)) * kFarScale;
  tNear = enter;
  return enter <= exit;
}

// Closest hit (anyHit = false) or any hit (true) in 0 < t < tMax. Every loop records how it
// ended: one that ends other than by its own break or return was cut short by lavapipe's
// silent loop-iteration cap, and sets gTruncated.
bool traceRay(vec3 origin, vec3 direction, float tMax, bool anyHit, out HitData best) {
  RayData r = prepareRay(origin, direction);
  best.t = tMax;
  best.barycentrics = vec3(0.0);
  best.triangle = 0u;
  float tNear;
  if (!intersectBox(r, nodes[0].boundsMin, nodes[0].boundsMax, tMax, tNear)) return false;
  uint stack[kBvhStackSize];
  uint stackSize = 0u;
  uint nodeIndex = 0u;
  bool found = false;
  bool complete = false;
  for (;;) {
    gLoopIterations++;
    BvhNode node = nodes[nodeIndex];
    if (node.count > 0u) {
      // Leaf: test its triangles, shrinking the search range as hits are found.
      uint i = node.offset;
      uint end = node.offset + node.count;
      for (; i < end; ++i) {
        gLoopIterations++;
        HitData hit;
        bool hitTriangle = PT_WATERTIGHT ? intersectTriangle(r, triangles[i], best.t, hit)
                                         : intersectTriangleFast(r, triangles[i], best.t, hit);
        if (hitTriangle) {
          hit.triangle = i;
          best = hit;
          found = true;
          if (anyHit) return true;
        }
      }
      if (i < end) gTruncated = true;
    } else {
      // Interior: visit the nearer child that the ray enters, push the other.
      uint left = nodeIndex + 1u;
      uint right = node.offset;
      float tLeft, tRight;
      bool hitLeft = intersectBox(r, nodes[left].boundsMin, nodes[left].boundsMax, best.t, tLeft);
      bool hitRight =
          intersectBox(r, nodes[right].boundsMin, nodes[right].boundsMax, best.t, tRight);
      if (hitLeft && hitRight) {
        bool leftFirst = tLeft <= tRight;
        stack[stackSize++] = leftFirst ? right : left;
        nodeIndex = leftFirst ? left : right;
        continue;
      }
      if (hitLeft || hitRight) {
        nodeIndex = hitLeft ? left : right;
        continue;
      }
    }
    if (stackSize == 0u) {
      complete = true;
      break;
    }
    nodeIndex = stack[--stackSize];
  }
  if (!complete) gTruncated = true;
  return found;
}
