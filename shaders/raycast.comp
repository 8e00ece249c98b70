// Ray queries on the GPU: one invocation traces one ray through the BVH with the same
// traversal as the path tracer (bvh.glsl), so the traversal can be tested on its own
// against the CPU's (watertightness, brute force).
#version 460
#extension GL_GOOGLE_include_directive : require

#include "sampling.h"
#include "shared_types.h"

layout(local_size_x = kRaycastWorkgroupSize) in;

layout(set = 0, binding = PT_RAYCAST_BINDING_NODES) uniform usamplerBuffer nodeTexels;
layout(set = 0, binding = PT_RAYCAST_BINDING_TRIANGLES) uniform usamplerBuffer triangleTexels;
layout(std430, set = 0, binding = PT_RAYCAST_BINDING_QUERIES) readonly buffer QueryBuffer {
  RayQuery queries[];
};
layout(std430, set = 0, binding = PT_RAYCAST_BINDING_RESULTS) writeonly buffer ResultBuffer {
  RayResult results[];
};

layout(push_constant) uniform Count {
  uint queryCount;
};

#define PT_WATERTIGHT true
bool gTruncated = false;
uint gLoopIterations = 0u;

#include "bvh.glsl"

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= queryCount) return;
  RayQuery q = queries[i];
  HitData hit;
  bool found = traceRay(q.origin, q.direction, q.tMax, q.anyHit != 0u, hit);
  results[i] =
      RayResult(found ? hit.t : q.tMax, hit.triangle, found ? 1u : 0u, gTruncated ? 1u : 0u);
}
