// Participating media, written once for the CPU reference and the shader (C++ through GLM,
// GLSL through #include): pbrt-v4's homogeneous, uniform-grid and RGB-grid media (its
// HomogeneousMedium, GridMedium and RGBGridMedium: the coefficients at a point, and the
// majorants over a ray's segments that delta and ratio tracking sample against), in RGB where
// pbrt-v4 is spectral. Their Henyey-Greenstein phase function is bsdf.h's (the coated
// material's medium uses it too). What a path does in a medium is volume_vertex.h's.
//
// What the functions read: in C++ the PathScene's media and grid floats (path_vertex.h); in
// GLSL the includer defines loadMedium(i), mediumGridFloat(i) and mediumGridWord(i) (the same
// float's bits) before including this.
// PT_MEDIUM_LOOP_TICK() is called once per step of the grid's majorant walk (the shader counts
// its loops for lavapipe's cap).
#ifndef PT_MEDIUM_H
#define PT_MEDIUM_H

#include "path_vertex.h"

#ifndef PT_MEDIUM_LOOP_TICK
#define PT_MEDIUM_LOOP_TICK()
#endif
// The types of media the scene has (bit 1 << kMedium* each): the shader's specialization
// constant, so that the code of the others is compiled out; every type on the CPU.
#ifndef PT_MEDIUM_KINDS
#define PT_MEDIUM_KINDS 0xFFFFFFFFu
#endif
#define PT_HAS_MEDIUM(medium, t) ((medium).type == (t) && (PT_MEDIUM_KINDS & (1u << (t))) != 0u)

#ifdef __cplusplus
namespace pt {
inline const Medium& loadMedium(const PathScene& scene, uint i) {
  return scene.media[i];
}
inline float mediumGridFloat(const PathScene& scene, uint i) {
  return scene.mediumGrids[i];
}
inline uint mediumGridWord(const PathScene& scene, uint i) {
  return floatBitsToUint(scene.mediumGrids[i]);
}
}  // namespace pt
#endif

#include "noise.h"

#ifdef __cplusplus
namespace pt {
#endif

// A medium's coefficients at a point (pbrt-v4's MediumProperties; the phase function is
// Henyey-Greenstein of the medium's g).
struct MediumProperties {
  vec3 sigmaA;  // absorption
  vec3 sigmaS;  // scattering
  vec3 Le;      // emitted radiance
};

// A point of world space in the medium's space (grids only).
PT_INLINE vec3 toMediumSpace(PT_IN(Medium) m, vec3 p) {
  return vec3(dot(vec3(m.toMedium0), p) + m.toMedium0.w, dot(vec3(m.toMedium1), p) + m.toMedium1.w,
              dot(vec3(m.toMedium2), p) + m.toMedium2.w);
}
PT_INLINE vec3 toMediumDirection(PT_IN(Medium) m, vec3 d) {
  return vec3(dot(vec3(m.toMedium0), d), dot(vec3(m.toMedium1), d), dot(vec3(m.toMedium2), d));
}

// ---- Grids --------------------------------------------------------------------------------
// pbrt-v4's SampledGrid: values at the centres of size.x * size.y * size.z voxels over the
// bounds, x fastest, interpolated trilinearly; zero beyond the outermost centres' neighbours.

// Component `c` (of `components` per voxel) of voxel v of the grid that starts at float
// `first`, or 0 outside the grid.
PT_INLINE float gridVoxel(PT_SCENE_PARAM uint first, uvec3 size, uint components, uint c, ivec3 v) {
  if (any(lessThan(v, ivec3(0))) || any(greaterThanEqual(v, ivec3(size)))) return 0.0f;
  uint index = (uint(v.z) * size.y + uint(v.y)) * size.x + uint(v.x);
  return mediumGridFloat(PT_SCENE_ARG first + index * components + c);
}

// a + t (b - a), written out: GLM's mix and the shader compiler's round differently.
PT_INLINE float lerpValue(float t, float a, float b) {
  return a + t * (b - a);
}

// The grid's value at point u of the unit cube (the bounds' offset coordinates), trilinearly.
PT_INLINE float gridLookup(PT_SCENE_PARAM uint first, uvec3 size, uint components, uint c, vec3 u) {
  vec3 s = u * vec3(size) - 0.5f;
  vec3 f = floor(s);
  ivec3 i = ivec3(f);
  vec3 d = s - f;
  float c00 = lerpValue(d.x, gridVoxel(PT_SCENE_ARG first, size, components, c, i),
                        gridVoxel(PT_SCENE_ARG first, size, components, c, i + ivec3(1, 0, 0)));
  float c10 = lerpValue(d.x, gridVoxel(PT_SCENE_ARG first, size, components, c, i + ivec3(0, 1, 0)),
                        gridVoxel(PT_SCENE_ARG first, size, components, c, i + ivec3(1, 1, 0)));
  float c01 = lerpValue(d.x, gridVoxel(PT_SCENE_ARG first, size, components, c, i + ivec3(0, 0, 1)),
                        gridVoxel(PT_SCENE_ARG first, size, components, c, i + ivec3(1, 0, 1)));
  float c11 = lerpValue(d.x, gridVoxel(PT_SCENE_ARG first, size, components, c, i + ivec3(0, 1, 1)),
                        gridVoxel(PT_SCENE_ARG first, size, components, c, i + ivec3(1, 1, 1)));
  return lerpValue(d.z, lerpValue(d.y, c00, c10), lerpValue(d.y, c01, c11));
}
PT_INLINE vec3 gridLookupRgb(PT_SCENE_PARAM uint first, uvec3 size, vec3 u) {
  return vec3(gridLookup(PT_SCENE_ARG first, size, 3u, 0u, u),
              gridLookup(PT_SCENE_ARG first, size, 3u, 1u, u),
              gridLookup(PT_SCENE_ARG first, size, 3u, 2u, u));
}

// ---- Sparse voxel grids (shared_types.h's layout) ---------------------------------------------

// A sparse grid's header, read once per lookup (its eight corners share it).
struct VoxelGrid {
  uint first;     // the grid's first float
  vec4 toIndex0;  // index-from-medium rows
  vec4 toIndex1;
  vec4 toIndex2;
  ivec3 origin;      // the first voxel of brick (0, 0, 0)
  uvec3 bricks;      // along x, y, z
  float background;  // beyond the bricks
  uint constants;    // where the constants start, from `first`
  uint values;       // where the bricks' values start, likewise
};

PT_INLINE vec4 gridVec4(PT_SCENE_PARAM uint i) {
  return vec4(mediumGridFloat(PT_SCENE_ARG i), mediumGridFloat(PT_SCENE_ARG i + 1u),
              mediumGridFloat(PT_SCENE_ARG i + 2u), mediumGridFloat(PT_SCENE_ARG i + 3u));
}

PT_INLINE VoxelGrid loadVoxelGrid(PT_SCENE_PARAM uint g) {
  return VoxelGrid(
      g, gridVec4(PT_SCENE_ARG g), gridVec4(PT_SCENE_ARG g + 4u), gridVec4(PT_SCENE_ARG g + 8u),
      ivec3(int(mediumGridWord(PT_SCENE_ARG g + 12u)), int(mediumGridWord(PT_SCENE_ARG g + 13u)),
            int(mediumGridWord(PT_SCENE_ARG g + 14u))),
      uvec3(mediumGridWord(PT_SCENE_ARG g + 15u), mediumGridWord(PT_SCENE_ARG g + 16u),
            mediumGridWord(PT_SCENE_ARG g + 17u)),
      mediumGridFloat(PT_SCENE_ARG g + 18u), mediumGridWord(PT_SCENE_ARG g + 19u),
      mediumGridWord(PT_SCENE_ARG g + 20u));
}

// The value of voxel v (index coordinates) of sparse grid `vg`.
PT_INLINE float voxelGridValue(PT_SCENE_PARAM PT_IN(VoxelGrid) vg, ivec3 v) {
  ivec3 local = v - vg.origin;
  ivec3 b = local >> 3;  // rounds down: negative coordinates fall outside
  if (any(lessThan(local, ivec3(0))) || any(greaterThanEqual(b, ivec3(vg.bricks)))) {
    return vg.background;
  }
  uint entry = mediumGridWord(PT_SCENE_ARG vg.first + kVoxelGridHeader +
                              (uint(b.z) * vg.bricks.y + uint(b.y)) * vg.bricks.x + uint(b.x));
  if ((entry & kConstantBrick) != 0u) {
    return mediumGridFloat(PT_SCENE_ARG vg.first + vg.constants + (entry & ~kConstantBrick));
  }
  ivec3 in8 = local & 7;
  return mediumGridFloat(PT_SCENE_ARG vg.first + vg.values + entry * kBrickVoxels +
                         uint((in8.z * 8 + in8.y) * 8 + in8.x));
}

// The value at point p of the medium's space of the sparse grid that starts at float g:
// trilinear between the voxels around its index coordinates (NanoVDB's SampleFromVoxels of
// order 1, as pbrt-v4 samples it).
PT_INLINE float voxelGridLookup(PT_SCENE_PARAM uint g, vec3 p) {
  VoxelGrid vg = loadVoxelGrid(PT_SCENE_ARG g);
  vec3 s =
      vec3(dot(vec3(vg.toIndex0), p) + vg.toIndex0.w, dot(vec3(vg.toIndex1), p) + vg.toIndex1.w,
           dot(vec3(vg.toIndex2), p) + vg.toIndex2.w);
  vec3 f = floor(s);
  ivec3 i = ivec3(f);
  vec3 d = s - f;
  float c00 = lerpValue(d.x, voxelGridValue(PT_SCENE_ARG vg, i),
                        voxelGridValue(PT_SCENE_ARG vg, i + ivec3(1, 0, 0)));
  float c10 = lerpValue(d.x, voxelGridValue(PT_SCENE_ARG vg, i + ivec3(0, 1, 0)),
                        voxelGridValue(PT_SCENE_ARG vg, i + ivec3(1, 1, 0)));
  float c01 = lerpValue(d.x, voxelGridValue(PT_SCENE_ARG vg, i + ivec3(0, 0, 1)),
                        voxelGridValue(PT_SCENE_ARG vg, i + ivec3(1, 0, 1)));
  float c11 = lerpValue(d.x, voxelGridValue(PT_SCENE_ARG vg, i + ivec3(0, 1, 1)),
                        voxelGridValue(PT_SCENE_ARG vg, i + ivec3(1, 1, 1)));
  return lerpValue(d.z, lerpValue(d.y, c00, c10), lerpValue(d.y, c01, c11));
}

// pbrt-v4's normalized blackbody spectrum at `kelvin` as RGB, from the table at float `table`
// (shared_types.h): zero at 100 K and below, as pbrt-v4 emits nothing there.
PT_INLINE vec3 blackbodyLookup(PT_SCENE_PARAM uint table, float kelvin) {
  float top = mediumGridFloat(PT_SCENE_ARG table);
  if (!(kelvin > 100.0f)) return vec3(0.0f);
  float x = min((kelvin - 100.0f) / (top - 100.0f), 1.0f) * float(kBlackbodyEntries - 1u);
  uint i = min(uint(x), kBlackbodyEntries - 2u);
  float t = x - float(i);
  uint at = table + 1u + 3u * i;
  vec3 a = vec3(mediumGridFloat(PT_SCENE_ARG at), mediumGridFloat(PT_SCENE_ARG at + 1u),
                mediumGridFloat(PT_SCENE_ARG at + 2u));
  vec3 b = vec3(mediumGridFloat(PT_SCENE_ARG at + 3u), mediumGridFloat(PT_SCENE_ARG at + 4u),
                mediumGridFloat(PT_SCENE_ARG at + 5u));
  return a + t * (b - a);
}

// ---- The coefficients at a point ------------------------------------------------------------

// Medium m's coefficients at world point p. A grid is zero outside its bounds. uniformgrid:
// sigma_a and sigma_s times the density, Le times its grid (or the blackbody at its
// temperature grid's value times its Lescale grid); rgbgrid: the RGB grids times
// sigma_a and sigma_s, its Le grid times Le (the readers fold the scales into its grids).
PT_INLINE MediumProperties mediumPropertiesAt(PT_SCENE_PARAM PT_IN(Medium) m, vec3 p) {
  if (PT_HAS_MEDIUM(m, kMediumHomogeneous)) return MediumProperties(m.sigmaA, m.sigmaS, m.Le);
  vec3 pm = toMediumSpace(m, p);
  vec3 u = (pm - m.boundsMin) / (m.boundsMax - m.boundsMin);
  MediumProperties mp = MediumProperties(vec3(0.0f), vec3(0.0f), vec3(0.0f));
  if (PT_HAS_MEDIUM(m, kMediumNanoVdb)) {
    // pbrt-v4's NanoVDBMedium: the density grid scales sigma_a and sigma_s; where it has a
    // temperature grid, Lescale times the blackbody at (T - temperatureoffset) *
    // temperaturescale.
    float d = voxelGridLookup(PT_SCENE_ARG m.density, pm);
    mp.sigmaA = m.sigmaA * d;
    mp.sigmaS = m.sigmaS * d;
    if (m.emissive != 0u) {
      float t = voxelGridLookup(PT_SCENE_ARG m.emission + kBlackbodyTableFloats, pm);
      mp.Le = m.Le.x * blackbodyLookup(PT_SCENE_ARG m.emission, (t - m.Le.y) * m.Le.z);
    }
  } else if (PT_HAS_MEDIUM(m, kMediumCloud)) {
    // pbrt-v4's CloudMedium; Le holds its density, wispiness and frequency, `density` where
    // its noise's permutation is.
    float d = cloudDensity(PT_SCENE_ARG m.density, pm, m.Le.x, m.Le.y, m.Le.z);
    mp.sigmaA = m.sigmaA * d;
    mp.sigmaS = m.sigmaS * d;
  } else if (PT_HAS_MEDIUM(m, kMediumUniformGrid)) {
    float d = gridLookup(PT_SCENE_ARG m.density, m.size, 1u, 0u, u);
    mp.sigmaA = m.sigmaA * d;
    mp.sigmaS = m.sigmaS * d;
    if (m.emissive != kEmitsNothing) {
      // Without a grid of its own, Le's scale is pbrt-v4's grid of one voxel of 1: the
      // interpolation falls to a half at the faces.
      vec3 f = vec3(1.0f) - abs(u - 0.5f);
      float tent = f.x * f.y * f.z;
      if (m.emissive == kEmitsBlackbody) {
        // pbrt-v4's GridMedium with a temperature grid: the scale times the blackbody at
        // (T - temperatureoffset) * temperaturescale.
        uint temperatures = m.emission + kBlackbodyTableFloats;
        float scale = m.Le.x == 0.0f
                          ? tent
                          : gridLookup(PT_SCENE_ARG temperatures + m.size.x * m.size.y * m.size.z,
                                       m.size, 1u, 0u, u);
        float t = gridLookup(PT_SCENE_ARG temperatures, m.size, 1u, 0u, u);
        mp.Le = scale * blackbodyLookup(PT_SCENE_ARG m.emission, (t - m.Le.y) * m.Le.z);
      } else {
        mp.Le = m.emission == kNoGrid
                    ? m.Le * tent
                    : m.Le * gridLookup(PT_SCENE_ARG m.emission, m.size, 1u, 0u, u);
      }
    }
  } else if (PT_HAS_MEDIUM(m, kMediumRgbGrid)) {
    uint voxels = m.size.x * m.size.y * m.size.z;
    mp.sigmaA = m.sigmaA * gridLookupRgb(PT_SCENE_ARG m.density, m.size, u);
    mp.sigmaS = m.sigmaS * gridLookupRgb(PT_SCENE_ARG m.density + 3u * voxels, m.size, u);
    if (m.emissive != 0u && m.emission != kNoGrid) {
      mp.Le = m.Le * gridLookupRgb(PT_SCENE_ARG m.emission, m.size, u);
    }
  }
  return mp;
}

// ---- Majorants along a ray ----------------------------------------------------------------
// A ray's parameter range in one medium, cut into segments of constant majorant sigma_maj >=
// sigma_a + sigma_s in every channel: one segment for a homogeneous medium (sigma_maj =
// sigma_t, no null collisions); for a grid, the cells of its majorant grid the ray crosses
// (a 3D DDA, pbrt-v4's DDAMajorantIterator), each the largest coefficient its voxels reach, so
// that thin regions are crossed in long steps. t is the ray's own parameter (o + t d, d of any
// length).

struct MajorantSegment {
  float tMin;
  float tMax;
  vec3 sigmaMaj;
};

struct MajorantWalk {
  uint type;  // the medium's kMedium*
  bool done;
  float tMin;      // where the next segment starts
  float tMax;      // where the walk ends
  vec3 sigmaMaj;   // homogeneous: sigma_t; grid: what a cell's majorant grid value multiplies
  ivec3 cell;      // grid: the current cell of the majorant grid
  vec3 nextT;      // grid: t where the ray crosses into the next cell along each axis
  vec3 deltaT;     // grid: t from one crossing to the next along each axis
  ivec3 step;      // grid: +1 or -1 per axis
  uint majorants;  // grid: the first float of its majorant grid
  ivec3 res;       // grid: its cells along x, y, z
};

// The walk of ray (o, d) over t in [0, tMax) through medium m.
PT_INLINE MajorantWalk startMajorantWalk(PT_IN(Medium) m, vec3 o, vec3 d, float tMax) {
  MajorantWalk w = MajorantWalk(m.type, false, 0.0f, tMax, m.sigmaA + m.sigmaS, ivec3(0),
                                vec3(0.0f), vec3(0.0f), ivec3(0), m.majorants, ivec3(0));
  if (m.type == kMediumHomogeneous) return w;
  if (m.type == kMediumRgbGrid) w.sigmaMaj = vec3(1.0f);
  w.res = m.type == kMediumUniformGrid || m.type == kMediumRgbGrid ? ivec3(int(kMajorantGridRes))
                                                                   : ivec3(m.size);
  // The ray in the grid's unit cube.
  vec3 extent = m.boundsMax - m.boundsMin;
  vec3 o01 = (toMediumSpace(m, o) - m.boundsMin) / extent;
  vec3 d01 = toMediumDirection(m, d) / extent;
  // Its overlap with the cube (the slabs' test; an axis the ray runs along is inside or not).
  float t0 = 0.0f;
  float t1 = tMax;
  for (int a = 0; a < 3; ++a) {
    if (d01[a] == 0.0f) {
      if (o01[a] < 0.0f || o01[a] > 1.0f) t1 = -1.0f;
      continue;
    }
    float tNear = (0.0f - o01[a]) / d01[a];
    float tFar = (1.0f - o01[a]) / d01[a];
    if (tNear > tFar) {
      float swap = tNear;
      tNear = tFar;
      tFar = swap;
    }
    t0 = max(t0, tNear);
    t1 = min(t1, tFar);
  }
  if (!(t0 < t1)) {
    w.done = true;
    return w;
  }
  w.tMin = t0;
  w.tMax = t1;
  // The cell it enters and where it leaves that cell along each axis.
  for (int a = 0; a < 3; ++a) {
    float res = float(w.res[a]);
    w.cell[a] = clamp(int(floor((o01[a] + t0 * d01[a]) * res)), 0, w.res[a] - 1);
    if (d01[a] == 0.0f) {
      w.nextT[a] = 1e30f;
      w.deltaT[a] = 1e30f;
      w.step[a] = 0;
    } else if (d01[a] > 0.0f) {
      w.nextT[a] = t0 + (float(w.cell[a] + 1) / res - (o01[a] + t0 * d01[a])) / d01[a];
      w.deltaT[a] = 1.0f / (res * d01[a]);
      w.step[a] = 1;
    } else {
      w.nextT[a] = t0 + (float(w.cell[a]) / res - (o01[a] + t0 * d01[a])) / d01[a];
      w.deltaT[a] = -1.0f / (res * d01[a]);
      w.step[a] = -1;
    }
  }
  return w;
}

// The walk's next segment; false when it has none left.
PT_INLINE bool nextMajorantSegment(PT_SCENE_PARAM PT_INOUT(MajorantWalk) w,
                                   PT_OUT(MajorantSegment) seg) {
  if (w.done) return false;
  PT_MEDIUM_LOOP_TICK();
  if (w.type == kMediumHomogeneous) {
    // The whole range.
    seg = MajorantSegment(w.tMin, w.tMax, w.sigmaMaj);
    w.done = true;
    return true;
  }
  // The axis whose crossing comes first leaves the cell.
  int a = w.nextT.x < w.nextT.y ? (w.nextT.x < w.nextT.z ? 0 : 2) : (w.nextT.y < w.nextT.z ? 1 : 2);
  float tExit = min(w.nextT[a], w.tMax);
  uvec3 r = uvec3(w.res);
  float cellMajorant = mediumGridFloat(
      PT_SCENE_ARG w.majorants + (uint(w.cell.z) * r.y + uint(w.cell.y)) * r.x + uint(w.cell.x));
  seg = MajorantSegment(w.tMin, tExit, w.sigmaMaj * cellMajorant);
  w.tMin = tExit;
  w.cell[a] += w.step[a];
  w.nextT[a] += w.deltaT[a];
  if (tExit >= w.tMax || w.cell[a] < 0 || w.cell[a] >= w.res[a]) w.done = true;
  return true;
}

#ifdef __cplusplus
}  // namespace pt
#endif

#endif  // PT_MEDIUM_H
