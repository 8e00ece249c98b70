// Every struct and constant that crosses between the host and the GPU, declared once.
// Read by C++ (through GLM, which spells vectors as GLSL does) and by GLSL (#include).
// Structs are built from 16-byte rows (a vec3 followed by a 4-byte scalar), so the std430
// layout equals the C++ layout with no padding members; host/common/shared.h checks that
// with static_asserts on every size and offset.
#ifndef PT_SHARED_TYPES_H
#define PT_SHARED_TYPES_H

#ifdef __cplusplus
#include <cstdint>
#include <glm/glm.hpp>
namespace pt {
using uint = std::uint32_t;
using namespace glm;  // so that shared code reads as GLSL: dot, cross, floatBitsToInt...
#define PT_CONST inline constexpr
#define PT_INLINE inline
// Parameters a shared function writes: references in C++, inout/out in GLSL.
#define PT_INOUT(T) T&
#define PT_OUT(T) T&
// Large structs a shared function only reads: const references in C++ (GLSL passes by value).
#define PT_IN(T) const T&
// For the few small functions called several times per path vertex (the random numbers):
// inlined whatever the compiler's heuristics say, so that independent calls overlap and
// unused results are dropped.
#define PT_HOT_INLINE [[gnu::always_inline]] inline
// GLSL's bitfieldReverse for a 32-bit word, the same bits as GLM's (five mask-and-shift
// steps) with the last two done by one byte swap: the samplers reverse several words per
// random number.
inline uint bitfieldReverse(uint x) {
  x = __builtin_bswap32(x);
  x = ((x & 0x0F0F0F0Fu) << 4u) | ((x >> 4u) & 0x0F0F0F0Fu);
  x = ((x & 0x33333333u) << 2u) | ((x >> 2u) & 0x33333333u);
  return ((x & 0x55555555u) << 1u) | ((x >> 1u) & 0x55555555u);
}
#else
#define PT_CONST const
#define PT_INLINE
#define PT_INOUT(T) inout T
#define PT_OUT(T) out T
#define PT_IN(T) T
#define PT_HOT_INLINE
// normalize as GLM computes it on the CPU: v times 1 / sqrt(dot(v, v)), sqrt and the division
// rounded as IEEE rounds them. Lavapipe's own normalize differs in the last bit, and a last bit
// in a triangle's normal or a sampled direction grows over a few bounces into another path: at
// 16 spp the backends differed beyond 1e-3 on 3.1 % of classroom's pixels and 2.0 % of
// bathroom's with it, on 0.014 % and 0.007 % with this.
#define normalize(v) ((v) * (1.0f / sqrt(dot((v), (v)))))
#endif

// ---- BVH -------------------------------------------------------------------------------

// One node of the depth-first linearized BVH. The left child of an interior node is the
// node that follows it in the array; only the right child's index is stored.
struct BvhNode {
  vec3 boundsMin;  // 12 bytes: lower corner of the box
  uint offset;     //  4 bytes: interior: index of the right child; leaf: first triangle
  vec3 boundsMax;  // 12 bytes: upper corner of the box
  uint count;      //  4 bytes: number of triangles in a leaf, 0 for an interior node
};                 // 32 bytes

// One interior node of the GPU's copy of the BVH (host/vulkan/gpu_bvh.h): the boxes of both
// children of a binary node, so that one fetch of 64 bytes serves its two box tests, and the
// references of both. A reference is an interior child's GpuBvhNode index, or for a leaf
// kGpuBvhLeaf | first triangle << kGpuBvhCountBits | triangle count (a larger leaf is split,
// see gpu_bvh.h). The binary tree's shape, boxes and triangle order are kept: traversal
// visits the leaves in the same order. Node 0 holds the root's box and reference as its left
// child; its right half is unused (nothing refers to node 0, so a reference of 0 means none).
struct GpuBvhNode {
  vec3 leftMin;    // 12 bytes: the left child's box, lower corner
  uint left;       //  4 bytes: reference to the left child
  vec3 leftMax;    // 12 bytes: upper corner
  uint right;      //  4 bytes: reference to the right child
  vec3 rightMin;   // 12 bytes: the right child's box, lower corner
  uint reserved0;  //  4 bytes: zero; node 0: the traversal texel where the triangles start
  vec3 rightMax;   // 12 bytes: upper corner
  uint reserved1;  //  4 bytes: zero
};                 // 64 bytes
PT_CONST uint kGpuBvhLeaf = 0x80000000u;
PT_CONST uint kGpuBvhCountBits = 4u;  // a leaf reference holds up to 15 triangles
PT_CONST uint kGpuBvhMaxLeafCount = (1u << kGpuBvhCountBits) - 1u;

// Traversal stack entries per ray. Both builders keep every tree within this depth: where a
// split would go deeper, they split the range in balanced halves instead.
PT_CONST uint kBvhStackSize = 64u;

// ---- Geometry and materials ------------------------------------------------------------

PT_CONST uint kNoEmitter = 0xFFFFFFFFu;

// One triangle, stored in BVH leaf order. Vertices are kept (not edges) because the
// watertight intersection test (Woop et al. 2013) works on vertices relative to the ray.
struct Triangle {
  vec3 v0;         // 12 bytes
  uint material;   //  4 bytes: index into the material buffer
  vec3 v1;         // 12 bytes
  uint emitter;    //  4 bytes: index into the emitter buffer, or kNoEmitter
  vec3 v2;         // 12 bytes
  uint primitive;  //  4 bytes: index of the triangle in scene (load) order
};                 // 48 bytes

// Material types. Diffuse and mirror are the seed's; the rest follow pbrt-v4's materials of
// the same names (its parameters, its definitions: shaders/bsdf.h).
PT_CONST uint kMaterialDiffuse = 0u;         // ideal Lambertian, BRDF = reflectance / pi, two-sided
PT_CONST uint kMaterialMirror = 1u;          // ideal specular reflection, no Fresnel, two-sided
PT_CONST uint kMaterialConductor = 2u;       // metal: complex Fresnel, smooth or Trowbridge-Reitz
PT_CONST uint kMaterialDielectric = 3u;      // glass: reflection and refraction, smooth or rough
PT_CONST uint kMaterialThinDielectric = 4u;  // a pane: reflection, straight transmission
PT_CONST uint kMaterialDiffuseTransmission = 5u;  // Lambertian reflection and transmission
PT_CONST uint kMaterialCoatedDiffuse = 6u;  // dielectric coat over a Lambertian base (layered)
// No surface: pbrt-v4's "interface" material. Its triangles only bound media (a ray passes
// through, into the medium on the side it goes to); scenes without media have none.
PT_CONST uint kMaterialInterface = 7u;
// glTF 2.0's metallic-roughness material (its appendix B; shaders/bsdf.h says how it is read).
PT_CONST uint kMaterialGltf = 8u;
// Which of glTF's material extensions a kMaterialGltf material uses, in its nSamples (0: none,
// the metallic-roughness material alone; shaders/bsdf.h's gltfLayered* otherwise).
PT_CONST uint kGltfTransmission = 1u;  // KHR_materials_transmission
PT_CONST uint kGltfVolume = 2u;        // KHR_materials_volume: the transmission refracts
PT_CONST uint kGltfClearcoat = 4u;     // KHR_materials_clearcoat
PT_CONST uint kGltfSpecular = 8u;      // KHR_materials_specular
PT_CONST uint kGltfSheen = 16u;        // KHR_materials_sheen (gltf_material_fields.h)
PT_CONST uint kGltfCoatNormal = 32u;   // the clear coat has its own shading normal (a hit's)
PT_CONST uint kMaterialTypeCount = 9u;

// One material. The first two rows are all that diffuse and mirror surfaces read; the others
// hold the parameters of the other types (zero where a type has no use for them). Roughness is
// stored as the Trowbridge-Reitz alpha, pbrt-v4's remapping already applied by the host.
struct Material {
  vec3 reflectance;    // 12 bytes: diffuse albedo, mirror reflectance, diffusetransmission's
                       //           reflectance, coateddiffuse's base albedo, gltf's base
                       //           colour; linear RGB
  uint type;           //  4 bytes: kMaterial*
  vec3 emission;       // 12 bytes: radiance emitted on the front side (geometric normal side)
  uint twoSided;       //  4 bytes: 1: emission leaves both sides (pbrt-v4's "twosided")
  vec3 eta;            // 12 bytes: conductor: real part of the index of refraction per channel;
                       //           dielectric, thindielectric, coateddiffuse, gltf: the index
                       //           in .x; gltf: the specular factor in .y
  float alphaX;        //  4 bytes: Trowbridge-Reitz alpha along the tangent (conductor,
                       //           dielectric, coateddiffuse's coat)
  vec3 k;              // 12 bytes: conductor: imaginary part of the index (absorption); gltf:
                       //           the specular colour factor
  float alphaY;        //  4 bytes: alpha along the bitangent
  vec3 transmittance;  // 12 bytes: diffusetransmission: transmittance; coateddiffuse: the
                       //           albedo of the medium between coat and base; gltf: the
                       //           transmission and clearcoat factors, the clearcoat's alpha
  float thickness;     //  4 bytes: coateddiffuse: the medium's optical thickness; gltf: the
                       //           metallic factor
  float g;             //  4 bytes: coateddiffuse: Henyey-Greenstein asymmetry of the medium
  uint maxDepth;       //  4 bytes: coateddiffuse: random-walk length
  uint nSamples;       //  4 bytes: coateddiffuse: random walks per evaluation; gltf: kGltf*
                       //           (and gltf_material_fields.h's sheen roughness)
  uint reserved1;      //  4 bytes: zero; gltf: the coat's normal (gltf_material_fields.h)
};                     // 96 bytes
PT_CONST uint kMaterialTexels = 6u;  // 16-byte texels per Material (the GPU reads them so)

// The vertex normals of one triangle, for shading normals, in the scene's load order (indexed by
// Triangle::primitive). Unit length, in world space. Uploaded only where some mesh has normals.
// With them, the vertices' tangents where the mesh gives them (glTF's TANGENT, for normal
// maps), each packed in a word (texture.h's packTangent; zero: none).
struct TriangleNormals {
  vec3 n0;        // 12 bytes: at v0
  uint tangent0;  //  4 bytes: at v0, packed
  vec3 n1;        // 12 bytes: at v1
  uint tangent1;  //  4 bytes
  vec3 n2;        // 12 bytes: at v2
  uint tangent2;  //  4 bytes
};                // 48 bytes

// One entry of the emitter alias table (Walker 1977, Vose 1991): emitter i is picked with
// probability pmf; sampling draws a slot uniformly and keeps it with probability
// aliasThreshold, else takes slot alias.
struct Emitter {
  uint triangle;         // 4 bytes: index into the triangle buffer (leaf order)
  float pmf;             // 4 bytes: probability of choosing this emitter
  float aliasThreshold;  // 4 bytes
  uint alias;            // 4 bytes
};                       // 16 bytes

// A node of the light BVH (pbrt-v4's LightBVHNode; shaders/light_bvh.h): the bounds of the
// lights below it, their total power, and the cone of their emission (pbrt-v4's LightBounds).
// Interior nodes have their first child next in the array and the second at `child`; a leaf
// holds one Emitter. Built depth first from the root at 0.
struct LightBvhNode {
  vec3 centre;      // 12 bytes: the centre of the lights' box (a point light's: its position)
  float phi;        //  4 bytes: their power (pbrt-v4's LightBounds::phi)
  vec3 w;           // 12 bytes: unit axis of their normals' cone
  float cosThetaO;  //  4 bytes: cosine of the spread of their normals about w
  float radius;     //  4 bytes: half the box's diagonal (importance sees the box as its sphere)
  float sinThetaO;  //  4 bytes: sine of the normals' spread
  float cosThetaE;  //  4 bytes: cosine of the angle beyond the normals they emit to
  uint flags;       //  4 bytes: kLightBvhLeaf, kLightBvhTwoSided, kLightBvhSameBounds
  uint child;       //  4 bytes: interior: the second child's node; leaf: its Emitter
  uint parent;      //  4 bytes: the node above (the root: itself)
  uint reserved0;   //  4 bytes: zero
  uint reserved1;   //  4 bytes: zero
};                  // 64 bytes
PT_CONST uint kLightBvhTexels = 4u;
PT_CONST uint kLightBvhLeaf = 1u;      // a leaf: `child` is an Emitter
PT_CONST uint kLightBvhTwoSided = 2u;  // some light below emits on both sides of its normal
// The two children's bounds differ in power alone (the two triangles of an axis-aligned quad:
// one box): their importance is in the ratio of their power wherever it is not zero for both.
PT_CONST uint kLightBvhSameBounds = 4u;

// Lights that are not triangles: pbrt-v4's point, spot, distant and (constant) infinite lights.
// They join the emissive triangles in the alias table: an Emitter whose `triangle` has
// kEmitterLight set names Light number (triangle & ~kEmitterLight) instead.
PT_CONST uint kLightPoint = 0u;     // isotropic point: intensity I at position
PT_CONST uint kLightSpot = 1u;      // point with pbrt-v4's smoothstep falloff about an axis
PT_CONST uint kLightDistant = 2u;   // parallel light from one direction (radiance L, a delta)
PT_CONST uint kLightInfinite = 3u;  // constant radiance from every direction (an environment)
// A sphere area light: its surface is triangles of material `material` (emissive, one-sided,
// outward), which BSDF-sampled rays hit; light sampling takes the cone the exact sphere
// subtends (pbrt-v4's Sphere::Sample), and those triangles' Emitter is this light's.
PT_CONST uint kLightSphere = 4u;
PT_CONST uint kLightTypeCount = 5u;
PT_CONST uint kEmitterLight = 0x80000000u;

struct Light {
  vec3 position;          // 12 bytes: point, spot: where it is
  uint type;              //  4 bytes: kLight*
  vec3 radiance;          // 12 bytes: point, spot: intensity (W/sr); distant, infinite:
                          //           radiance; linear RGB, pbrt-v4's scale already applied
  float cosFalloffStart;  //  4 bytes: spot: full intensity inside this cosine
  vec3 direction;         // 12 bytes: spot: unit axis it shines along; distant: unit
                          //           direction towards the light
  float cosFalloffEnd;    //  4 bytes: spot: dark outside this cosine
  float radius;           //  4 bytes: sphere: its radius (position: its centre)
  uint material;          //  4 bytes: sphere: the material of its triangles
  uint reserved0;         //  4 bytes: zero
  uint reserved1;         //  4 bytes: zero
};                        // 64 bytes
PT_CONST uint kLightTexels = 4u;

// ---- Participating media ----------------------------------------------------------------

// pbrt-v4's media (its MakeNamedMedium classes, their parameters and definitions;
// shaders/medium.h evaluates them). Coefficients are per unit of world distance, linear RGB
// (pbrt-v4 is spectral: its RGB values become spectra, ours stay RGB), scales applied.
PT_CONST uint kNoMedium = 0xFFFFFFFFu;  // vacuum
PT_CONST uint kMediumHomogeneous = 0u;  // constant sigma_a, sigma_s, Le
PT_CONST uint kMediumUniformGrid = 1u;  // sigma_a, sigma_s times a density grid; Le times a grid
PT_CONST uint kMediumRgbGrid = 2u;      // RGB grids of sigma_a, sigma_s and Le
PT_CONST uint kMediumNanoVdb = 3u;  // sigma_a, sigma_s times a sparse density grid; blackbody Le
PT_CONST uint kMediumCloud = 4u;    // sigma_a, sigma_s times pbrt-v4's procedural cloud density
PT_CONST uint kMediumTypeCount = 5u;
// What a medium emits (Medium::emissive): nothing; Le (times a grid where it has one); or
// pbrt-v4's blackbody at the temperature its grid gives.
PT_CONST uint kEmitsNothing = 0u;
PT_CONST uint kEmitsLe = 1u;
PT_CONST uint kEmitsBlackbody = 2u;
PT_CONST uint kNoGrid = 0xFFFFFFFFu;  // a grid medium's missing grid (no Le grid)
// The majorant grid of a grid medium: this many cells on each axis over its bounds (pbrt-v4's
// 16^3), each the largest density of the voxels it overlaps.
PT_CONST uint kMajorantGridRes = 16u;
// A nanovdb medium's majorant grid: this many cells on each axis over its bounds (pbrt-v4's).
PT_CONST uint kNanoVdbMajorantRes = 64u;

// Grids hold a value per voxel (RGB: three) in pbrt-v4's SampledGrid order, x fastest: voxel
// (x, y, z) is number (z * size.y + y) * size.x + x. An rgbgrid's scales are folded into its
// grids by the readers (its sigmaA, sigmaS and Le are then ones). A nanovdb medium's grids are
// sparse voxel grids (below), its emission a blackbody table followed by its temperature grid.
// A uniformgrid that emits by temperature (emissive kEmitsBlackbody) has the same: a blackbody
// table, then its temperature grid, then its Lescale grid where it has one (Le.x 1; 0 without:
// pbrt-v4's grid of one voxel of 1), and (Le.y, Le.z) its (temperatureoffset, temperaturescale).
// A cloud's density is a function of the point (shaders/noise.h), its "density grid" the
// permutation its noise reads. "Grids" below means every medium but the homogeneous one.
struct Medium {
  vec3 sigmaA;     // 12 bytes: absorption (homogeneous), or what the density multiplies
  uint type;       //  4 bytes: kMedium*
  vec3 sigmaS;     // 12 bytes: scattering, likewise
  float g;         //  4 bytes: Henyey-Greenstein asymmetry, in [-1, 1]
  vec3 Le;         // 12 bytes: emitted radiance (homogeneous, uniformgrid: times its grid);
                   //           nanovdb: (Lescale, temperatureoffset, temperaturescale);
                   //           cloud: (density, wispiness, frequency)
  uint emissive;   //  4 bytes: kEmitsNothing, kEmitsLe or kEmitsBlackbody
  vec3 boundsMin;  // 12 bytes: grids: p0, in the medium's space (nanovdb: its grids' bounds)
  uint density;    //  4 bytes: grids: the first float of its density grid (uniformgrid: one
                   //           float per voxel; rgbgrid: sigma_a's RGB then sigma_s's RGB;
                   //           nanovdb: a sparse voxel grid; cloud: its noise's permutation)
  vec3 boundsMax;  // 12 bytes: grids: p1
  uint majorants;  //  4 bytes: grids: the first float of its majorant grid (size below)
  uvec3 size;      // 12 bytes: uniformgrid, rgbgrid: voxels along x, y, z (their majorant grid
                   //           is kMajorantGridRes^3); nanovdb, cloud: the majorant grid's cells
  uint emission;   //  4 bytes: grids: the first float of its Le grid (uniformgrid: a scale per
                   //           voxel; rgbgrid: RGB per voxel; nanovdb: its blackbody table), or
                   //           kNoGrid
  vec4 toMedium0;  // 16 bytes: the world-to-medium transform's rows (affine: p' = M p + t,
  vec4 toMedium1;  // 16 bytes: row i is (M[i][0], M[i][1], M[i][2], t[i])); grids only
  vec4 toMedium2;  // 16 bytes
};                 // 144 bytes
PT_CONST uint kMediumTexels = 9u;

// A sparse voxel grid (a nanovdb medium's density or temperature: NanoVDB's float tree, its
// leaves kept as they are and its tiles as constants), floats in the media's grid buffer from
// its first: kVoxelGridHeader floats of header, then a brick map, its constants and its bricks.
// Values sit at integer index coordinates; a point of the medium's space maps to index space by
// the grid's own affine transform. The index space is cut into bricks of 8^3 voxels (NanoVDB's
// leaves, aligned at multiples of 8); the brick map has an entry per brick over the grid's
// bounding box, x fastest: a brick number (its 512 values, x fastest, at bricks + 512 number),
// or kConstantBrick plus the number of the constant every voxel of that brick has. Integers are
// stored as their bits. Header, by float:
//   0-11  index-from-medium rows (as Medium::toMedium0-2)
//   12-14 the index of the first voxel of brick (0, 0, 0) (int, multiples of 8)
//   15-17 bricks along x, y, z (uint)
//   18    the value beyond the bounding box (NanoVDB's background)
//   19    where the constants start, from the grid's first float (uint)
//   20    where the bricks start, likewise (uint)
//   21    the floats of the whole grid (uint)
PT_CONST uint kVoxelGridHeader = 24u;
PT_CONST uint kBrickVoxels = 512u;
PT_CONST uint kConstantBrick = 0x80000000u;
// A blackbody table (the emission of a nanovdb medium, or of a uniformgrid with
// temperatures): float 0 the highest temperature T1 it
// covers, then kBlackbodyEntries RGB triples of pbrt-v4's normalized blackbody spectrum at
// temperatures evenly spaced from 100 K to T1, interpolated linearly; the medium's
// temperature grid follows the table.
PT_CONST uint kBlackbodyEntries = 2048u;
PT_CONST uint kBlackbodyTableFloats = 1u + 3u * kBlackbodyEntries;

// The media on the two sides of a triangle, by Triangle::primitive: `inside` on the side
// opposite its normal, `outside` on the normal's side (pbrt-v4's MediumInterface). The normal
// is the geometric one, turned to the side of the vertex normals where the triangle has them
// (as pbrt-v4 turns it; the readers give the geometric normal's sides, prepareScene turns
// them). A triangle whose two are equal marks no change: a ray keeps the medium it was in.
struct MediumInterface {
  uint inside;   // 4 bytes: a Medium index, or kNoMedium
  uint outside;  // 4 bytes
};               // 8 bytes

// ---- Textures ----------------------------------------------------------------------------

// pbrt-v4's textures (its Texture directive's classes, their parameters and definitions;
// shaders/texture.h evaluates them). A texture is a short program in postfix order: leaves
// (constant, image) push a value, the others pop their operands and push their result, so that
// nesting needs no recursion. A texture is named by the index of its first node, whose `count`
// is the program's length; values are RGB (a float texture's value is in all three channels).
PT_CONST uint kNoTexture = 0xFFFFFFFFu;
PT_CONST uint kTextureConstant = 0u;      // pushes value
PT_CONST uint kTextureImage = 1u;         // pushes the image's filtered value (imagemap)
PT_CONST uint kTextureCheckerboard = 2u;  // pops tex2, tex1: tex1 on even squares, else tex2
PT_CONST uint kTextureScale = 3u;         // pops scale, tex: tex * scale.x (0 where scale is 0)
PT_CONST uint kTextureMix = 4u;           // pops amount, tex2, tex1: (1 - a) tex1 + a tex2
PT_CONST uint kTextureStackSize = 4u;     // the deepest a program's stack may grow

// An image node's flags: its texel format in bits 0-3, wrap mode in 4-7, filter in 8-11, what
// a float texture reads in 12-15, bit 16 for pbrt-v4's "invert", and in bits 24-28 the number
// of levels of its MIP map.
PT_CONST uint kTexel8 = 0u;       // one word per texel, RGBA bytes decoded by the image's table
PT_CONST uint kTexelFloat1 = 1u;  // one float per texel (grey)
PT_CONST uint kTexelFloat3 = 2u;  // three floats (RGB)
PT_CONST uint kTexelFloat4 = 3u;  // four floats (RGBA)
PT_CONST uint kWrapRepeat = 0u;
PT_CONST uint kWrapClamp = 1u;
PT_CONST uint kWrapBlack = 2u;  // zero outside the image
// pbrt-v4's image filters: every one reads the MIP map level the ray's footprint on the
// texture calls for (texture.h); at a footprint of zero, level 0.
PT_CONST uint kTextureBilinear = 0u;   // bilinear in the level below the footprint's width
PT_CONST uint kTexturePoint = 1u;      // the nearest texel of that level
PT_CONST uint kTextureTrilinear = 2u;  // bilinear in the two levels about it, interpolated
PT_CONST uint kTextureEwa = 3u;  // an elliptical gaussian over the footprint (pbrt-v4's default)
PT_CONST uint kTextureLevelsShift = 24u;
// What a float texture reads of an image (pbrt-v4's MIPMap::Bilerp<Float>): the one channel
// of a grey image, the average of R, G and B, or the alpha of an image that has one that is
// not all ones; a point lookup reads the first channel whatever the image (MIPMap::Texel).
PT_CONST uint kFloatChannelFirst = 0u;
PT_CONST uint kFloatChannelAverage = 1u;
PT_CONST uint kFloatChannelAlpha = 2u;
PT_CONST uint kTextureInvert = 0x10000u;
PT_CONST uint kTextureFloat = 0x20000u;   // the texture is a float texture (image lookups)
PT_CONST uint kTextureSkewed = 0x40000u;  // the mapping has cross terms (TextureNode::skew)

struct TextureNode {
  vec3 value;           // 12 bytes: constant: its value; image: pbrt-v4's "scale" (all three)
  uint type;            //  4 bytes: kTexture*
  vec4 mapping;         // 16 bytes: image, checkerboard: (uscale, vscale, udelta, vdelta), so that
                        //           (s, t) = (uscale u + udelta, vscale v + vdelta)
  uint texels;          //  4 bytes: image: its first word in the image buffer
  uint width;           //  4 bytes: image: texels per row
  uint height;          //  4 bytes: image: rows (row 0 at the top, where t = 1)
  uint flags;           //  4 bytes: image: format, wrap, filter, float channel, invert (above)
  uint decode;          //  4 bytes: image, kTexel8: the first word of its 256 decoded byte values
  uint count;           //  4 bytes: a texture's first node: the nodes of its program
  uint levels;          //  4 bytes: image: the first word of its MIP map's table, whose word k is
                        //           the first word of level k's texels (level 0 is width x height,
                        //           powers of two; level k halves them, down to 1)
  float maxAnisotropy;  // 4 bytes: image, kTextureEwa: pbrt-v4's "maxanisotropy"
  vec2 skew;            // 8 bytes: with kTextureSkewed, the mapping's cross terms: s gains
                        //          skew.x v and t gains skew.y u (a rotated mapping, glTF's
                        //          KHR_texture_transform)
  uint reserved0;       // 4 bytes: zero
  uint reserved1;       // 4 bytes: zero
};                      // 80 bytes
PT_CONST uint kTextureNodeTexels = 5u;

// The texture coordinates of one triangle's vertices, in the scene's load order (indexed by
// Triangle::primitive); pbrt-v4's (0, 0), (1, 0), (1, 1) where a mesh has none. Uploaded only
// where some material has a texture.
struct TriangleUVs {
  vec2 uv0;       // 8 bytes
  vec2 uv1;       // 8 bytes
  vec2 uv2;       // 8 bytes
  vec2 reserved;  // 8 bytes: zero
};                // 32 bytes

// The textures of one material's parameters (kNoTexture: the Material's own value), parallel
// to the materials; uploaded only where some material has one. A texture's value replaces the
// parameter at each hit before the BSDF sees it (shaders/texture.h, resolveMaterial).
struct MaterialTextures {
  uint reflectance;    // reflectance (all types that have one; a conductor's by its k)
  uint transmittance;  // diffusetransmission: transmittance; coateddiffuse: albedo
  uint uRoughness;     // roughness along u (float)
  uint vRoughness;     // along v (float)
  uint eta;            // conductor: eta (spectrum)
  uint k;              // conductor: k (spectrum)
  uint displacement;   // bump map (float)
  uint alpha;          // cut-out (float): the surface is missing where it is 0
  uint flags;          // kRemapRoughness
  float scale;         // diffusetransmission: pbrt-v4's "scale" of both colours
  uint thickness;      // coateddiffuse: the medium's thickness (float); gltf: metallic
  uint g;              // coateddiffuse: the medium's asymmetry (float)
  uint emission;       // emitted radiance (RGB, not clamped): gltf's emissiveTexture
  uint normalMap;      // tangent-space normal map (RGB, linear): gltf's normalTexture
  float normalScale;   // normalMap: the scale of its x and y (gltf's normalTexture.scale)
  float alphaCutoff;   // kAlphaCutoff: alpha below it is 0, at or above it 1 (gltf's MASK)
  // gltf's material extensions (shaders/bsdf.h, gltfLayersOf), each a float texture but the
  // last: KHR_materials_transmission's transmission (transmittance.x), KHR_materials_clearcoat's
  // clear coat (transmittance.y) and its roughness (squared to transmittance.z),
  // KHR_materials_specular's specular (eta.y) and its colour (k, RGB).
  uint transmission;
  uint clearcoat;
  uint clearcoatRoughness;
  uint specular;
  uint specularColour;
  // KHR_materials_sheen's colour (RGB) and roughness (float), KHR_materials_clearcoat's normal
  // map (RGB, linear; its scale in `scale`, which only diffusetransmission uses otherwise).
  uint sheenColour;
  uint sheenRoughness;
  uint clearcoatNormal;
};  // 96 bytes
PT_CONST uint kMaterialTextureTexels = 6u;
PT_CONST uint kRemapRoughness = 1u;   // roughness textures give pbrt-v4's roughness, not alpha
PT_CONST uint kSquareRoughness = 2u;  // roughness textures give gltf's roughness: alpha = r^2
PT_CONST uint kAlphaCutoff = 4u;      // the alpha texture is cut at alphaCutoff (gltf's MASK)

// What a scene's textures need (PT_FX_TEXTURE_FEATURES): the material parameters some used
// material takes from a texture, and whether any texture is a program of several nodes or reads
// an image. texture.h evaluates only these, so that a scene's shader holds no code for the rest
// (lavapipe runs both sides of a branch that its lanes take differently).
PT_CONST uint kTextureUsesReflectance = 1u << 0u;
PT_CONST uint kTextureUsesTransmittance = 1u << 1u;
PT_CONST uint kTextureUsesRoughness = 1u << 2u;    // uRoughness or vRoughness
PT_CONST uint kTextureUsesEtaK = 1u << 3u;         // a conductor's eta or k
PT_CONST uint kTextureUsesMedium = 1u << 4u;       // coateddiffuse's thickness or g, gltf's
                                                   // metallic
PT_CONST uint kTextureUsesEmission = 1u << 5u;     // emission (gltf's emissiveTexture)
PT_CONST uint kTextureUsesNormalMap = 1u << 6u;    // a normal map (gltf's normalTexture)
PT_CONST uint kTextureUsesGltfLayers = 1u << 7u;   // gltf's extension textures (transmission,
                                                   // clear coat, specular)
PT_CONST uint kTextureUsesPrograms = 1u << 8u;     // a texture of more than one node
PT_CONST uint kTextureUsesImages = 1u << 9u;       // an image lookup
PT_CONST uint kTextureUsesEwa = 1u << 10u;         // an image filtered by kTextureEwa
PT_CONST uint kTextureUsesFootprints = 1u << 11u;  // filtering over the ray's footprint (paths
                                                   // carry differentials: differentials.h)
PT_CONST uint kTextureUsesGltfSheen = 1u << 12u;   // gltf's sheen textures (colour, roughness)
PT_CONST uint kTextureUsesCoatNormal = 1u << 13u;  // a gltf clear coat with a normal of its own
PT_CONST uint kTextureUsesAll = 0xFFFFFFFFu;

// ---- Camera and per-render parameters --------------------------------------------------

// Pixel filters (pbrt-v4's, its definitions and parameters; shaders/filter.h samples them).
// Every one is separable, f(x, y) = f1(x) f1(y), and zero beyond its radius on each axis.
PT_CONST uint kFilterBox = 0u;       // 1 on [-radius, radius]
PT_CONST uint kFilterTriangle = 1u;  // radius - |x|
PT_CONST uint kFilterGaussian = 2u;  // exp(-x^2 / (2 sigma^2)) minus its value at the radius
PT_CONST uint kFilterMitchell = 3u;  // Mitchell and Netravali's cubic of parameters B and C

// Perspective camera, a pinhole or a thin lens (pbrt-v4's PerspectiveCamera), with a pixel
// filter. The film is filmWidth x filmHeight pixels; the image rendered is the crop of
// width x height pixels from (cropX, cropY) (the whole film without a crop window). Film point
// (x, y) in [0, filmWidth) x [0, filmHeight), row 0 at the top, maps to the direction
// normalize(windowCenter + u * tanHalfFovY * aspect * right + v * tanHalfFovY * up) with
// u = 2x / filmWidth - 1, v = 1 - 2y / filmHeight: the film spans the screen window, a
// rectangle on the plane at unit distance along forward. With the default window (centred,
// tan(vfov / 2) high) windowCenter is forward and aspect filmWidth / filmHeight.
struct Camera {
  vec3 position;         // 12 bytes: the pinhole; the lens's centre
  float tanHalfFovY;     //  4 bytes: half the screen window's height (tan(vertical fov / 2))
  vec3 forward;          // 12 bytes: unit view direction, the lens's axis
  float aspect;          //  4 bytes: the screen window's width / height
  vec3 right;            // 12 bytes: unit, forward x up
  uint width;            //  4 bytes: the image's width (the crop's)
  vec3 up;               // 12 bytes: unit, right x forward
  uint height;           //  4 bytes: the image's height
  vec3 windowCenter;     // 12 bytes: the screen window's centre: forward + cx * right + cy * up
  float lensRadius;      //  4 bytes: 0: a pinhole
  uint cropX;            //  4 bytes: the film column of the image's column 0
  uint cropY;            //  4 bytes: the film row of the image's row 0
  uint filmWidth;        //  4 bytes: the whole film, which the screen window spans
  uint filmHeight;       //  4 bytes
  uint filterType;       //  4 bytes: kFilter*
  float filterRadiusX;   //  4 bytes: pbrt-v4's xradius, in pixels
  float filterRadiusY;   //  4 bytes: yradius
  float focalDistance;   //  4 bytes: thin lens: distance of the plane in focus along forward
  float filterWeight;    //  4 bytes: |weight| of every sample: 1, or mitchell's integral of
                         //           |f| over the integral of f (filter.h)
  float filterScale;     //  4 bytes: gaussian: 1 / (sigma sqrt 2); otherwise unused
  float filterB;         //  4 bytes: mitchell: B
  float filterC;         //  4 bytes: mitchell: C
  vec3 filterRootsNear;  // 12 bytes: mitchell: where its cubic on |t| < 1 changes sign, in
                         //           increasing order, padded with 1 (t = 2x / radius)
  float filterExpX;      //  4 bytes: gaussian: its value at the x radius times 2k / sqrt(pi)
  vec3 filterRootsFar;   // 12 bytes: mitchell: the sign changes on 1 < |t| < 2, padded with 2
  float filterExpY;      //  4 bytes: gaussian: the same at the y radius
};                       // 160 bytes

// Sampling strategies for direct light (the MIS knob).
PT_CONST uint kStrategyMis = 0u;   // light sampling + BSDF sampling, power heuristic
PT_CONST uint kStrategyNee = 1u;   // light sampling only (emission hit by BSDF rays ignored)
PT_CONST uint kStrategyBsdf = 2u;  // BSDF sampling only (no shadow rays)

// How light sampling chooses its emitter (the host builds the table or tree; path_vertex.h's
// chooseEmitter reads them): pbrt-v4's light samplers.
PT_CONST uint kLightSamplerBvh = 0u;      // the light BVH, by importance at the shading point
PT_CONST uint kLightSamplerPower = 1u;    // the alias table, by power
PT_CONST uint kLightSamplerUniform = 2u;  // the alias table, every emitter alike

// Where the integrators' random numbers come from (sampling.h).
PT_CONST uint kSamplerIndependent = 0u;  // a hash per (pixel, sample, dimension): independent
PT_CONST uint kSamplerSobol = 1u;        // Owen-scrambled Sobol points per dimension

struct RenderParams {
  Camera camera;            // 160 bytes
  uint maxDepth;            //  4 bytes: maximum number of scattering events on a path
  uint rrStartDepth;        //  4 bytes: Russian roulette from this many scattering events on
  uint emitterCount;        //  4 bytes
  uint seed;                //  4 bytes
  uint strategy;            //  4 bytes: kStrategyMis, kStrategyNee or kStrategyBsdf
  uint russianRoulette;     // 4 bytes: 0 or 1
  uint fastIntersection;    // 4 bytes: 1: Moller-Trumbore (not watertight), 0: watertight
  uint samplerType;         //  4 bytes: kSamplerIndependent or kSamplerSobol
  uint normalsPresent;      //  4 bytes: 1 when the vertex-normal buffer holds the scene's normals
  uint lightCount;          //  4 bytes: Light entries (analytic lights) in the light buffer
  uint environmentEmitter;  // 4 bytes: the Emitter of the infinite light, or kNoEmitter
  float sceneRadius;        //  4 bytes: radius of a sphere about sceneCenter holding the scene
  vec3 environment;         // 12 bytes: radiance of the infinite light (zero when none)
  float environmentPdf;     //  4 bytes: its light-sampling density, environmentLightPdf of
                            //           its Emitter's pmf (for MIS where rays leave the scene);
                            //           with an image: that pmf alone (environment.h gives the
                            //           density of each direction)
  vec3 sceneCenter;         // 12 bytes: centre of the scene's bounding box
  uint texturesPresent;     //  4 bytes: 1 when the texture buffers hold the scene's textures
  // The infinite light's image, when it has one (environment.h; its texels and sampling
  // distribution are PT_BINDING_ENVIRONMENT): the image's frame in world space, its size and
  // how its (u, v) square maps to directions. environmentWidth 0: no image (the constant
  // `environment` radiance, if any).
  vec3 environmentX;        // 12 bytes: the image frame's x axis in world space (unit)
  uint environmentWidth;    //  4 bytes: texels per row, 0 without an image
  vec3 environmentY;        // 12 bytes: its y axis
  uint environmentHeight;   //  4 bytes: rows
  vec3 environmentZ;        // 12 bytes: its z axis
  uint environmentMapping;  //  4 bytes: kEnvironmentOctahedral or kEnvironmentLatLong
  uint cameraMedium;        //  4 bytes: the medium the camera is in, or kNoMedium
  uint mediaPresent;        //  4 bytes: 1 when the scene has media (the volume integrator)
  uint lightBvhNodes;       //  4 bytes: nodes of the light BVH; 0: emitters are chosen from
                            //           the alias table
  uint unboundedEmitters;   //  4 bytes: with the light BVH: the emitters without a position
                            //           (distant, infinite lights), chosen uniformly
  // Ray differentials (differentials.h), where some texture reads the ray's footprint: the
  // camera's smallest differentials in camera space (right, up, forward), which stand in for
  // a ray's own after a bounce that is not specular (pbrt-v4's Approximate_dp_dxy), and the
  // scale both take for the samples per pixel.
  vec3 minPosDifferentialX;  // 12 bytes
  float differentialScale;   //  4 bytes: pbrt-v4's max(1/8, 1/sqrt(samples per pixel))
  vec3 minPosDifferentialY;  // 12 bytes
  uint footprints;           //  4 bytes: 1 when some texture reads the footprint (or bumps by it)
  vec3 minDirDifferentialX;  // 12 bytes
  uint reservedD0;           //  4 bytes: zero
  vec3 minDirDifferentialY;  // 12 bytes
  uint reservedD1;           //  4 bytes: zero
};                           // 368 bytes

// How an environment image's (u, v) square maps to directions in its frame (environment.h).
PT_CONST uint kEnvironmentOctahedral = 0u;  // pbrt-v4's equal-area octahedral square, +z up
PT_CONST uint kEnvironmentLatLong = 1u;  // equirectangular: u = phi / 2 pi, v = theta / pi, +y up

// ---- Compute pipeline interface (Vulkan backend) ----------------------------------------

// Descriptor bindings of set 0. The scene's arrays are uniform texel buffers, read as 16-byte
// texels (R32G32B32A32_UINT) a row of a struct at a time: lavapipe gathers a texel fetch for
// its eight lanes at once, where a storage-buffer load with a different index per lane
// takes a loop over the lanes with a branch per lane and component (as does any buffer load
// inside a loop or branch: see `params` in pathtrace.comp). The rest are storage buffers.
// (Mesa 22.3 fetches these texels in a function of its own, called four times per traversal
// step; as storage texel buffers read by imageLoad, which it inlines, they were no faster:
// Cornell box the same, bunny box 2-4 % slower.)
#define PT_BINDING_PARAMS 0     // RenderParams
#define PT_BINDING_NODES 1      // GpuBvhNode[], then Triangle[] (gpuTraversalTexels), texels
#define PT_BINDING_TRIANGLES 2  // Triangle[], texels
#define PT_BINDING_MATERIALS 3  // Material[], texels
#define PT_BINDING_EMITTERS 4   // Emitter[], texels (one dummy entry when the scene has none)
#define PT_BINDING_NORMALS 5    // TriangleNormals[], texels (one dummy entry when none)
#define PT_BINDING_LIGHTS 6     // Light[], texels (one dummy entry when the scene has none)
#define PT_BINDING_ACCUM 7      // AccumPixel[width * height]
#define PT_BINDING_COUNTERS 8   // DeviceCounters
// The environment image's texels and sampling distribution (environment.h), as float texels
// (one dummy texel when the scene has no image).
#define PT_BINDING_ENVIRONMENT 9
// Textures: one dummy entry each where no material has a texture.
#define PT_BINDING_UVS 10                // TriangleUVs[], texels
#define PT_BINDING_TEXTURES 11           // TextureNode[], texels
#define PT_BINDING_IMAGES 12             // the image buffer: uint words (R32_UINT texels)
#define PT_BINDING_MATERIAL_TEXTURES 13  // MaterialTextures[], texels
// Participating media (the volume variant reads them): one dummy entry each without media.
#define PT_BINDING_MEDIA 14              // Medium[], texels
#define PT_BINDING_MEDIUM_GRIDS 15       // the grids' floats, four to a texel
#define PT_BINDING_MEDIUM_INTERFACES 16  // MediumInterface[] by primitive, two to a texel
// LightBvhNode[], then (four to a texel) each Emitter's leaf and the unbounded Emitters' indices
#define PT_BINDING_LIGHT_BVH 17
#define PT_BINDING_COUNT 18
// Stochastic progressive photon mapping's passes (shaders/sppm.glsl) bind these besides.
#define PT_BINDING_SPPM_POINTS 18       // the visible points' records, in the shader's layout
#define PT_BINDING_SPPM_FOUND 19        // vec4 per pixel: its visible point, w 1 where there is one
#define PT_BINDING_SPPM_GRID 20         // SppmGridShape, the buckets' starts, the entries (uint)
#define PT_BINDING_SPPM_GRID_POINTS 21  // vec4 per pixel: the visible point, its search radius
#define PT_BINDING_SPPM_FLUX 22         // PT_SPPM_FLUX_WORDS uint64 per pixel
// A pixel's photons of one iteration on the device: the exact sums of their flux (red, green,
// blue: five limbs each, exact_sum_atomic.glsl), then their count plus 2^PT_SPPM_INVALID_SHIFT
// for each whose flux was NaN or infinite.
#define PT_SPPM_FLUX_WORDS 16u
#define PT_SPPM_COUNT_WORD 15u
#define PT_SPPM_INVALID_SHIFT 40u
// Bidirectional path tracing's pass (shaders/bdpt.glsl) binds its film besides: per pixel, the
// exact sums of what its samples and the splats that land on it add (red, green, blue: five
// limbs each, exact_sum_atomic.glsl), then its sample count plus 2^PT_BDPT_INVALID_SHIFT for
// each sample or splat that came out NaN or infinite.
#define PT_BINDING_BDPT_FILM 18
#define PT_BDPT_FILM_WORDS 16u
#define PT_BDPT_COUNT_WORD 15u
#define PT_BDPT_INVALID_SHIFT 40u

// The one specialization constant: the traversal stack's size, rows of four entries
// (bvh.glsl), from the tree. The effect set is not specialized but compiled in: the host
// compiles pathtrace.comp for each scene with its effects as PT_FX_* definitions.
#define PT_SPEC_STACK_ROWS 0  // uint: 1 to kBvhStackSize / 4
// The intersection test and the sampler as effects: the value of the parameter the scene
// chose, so that only that alternative is compiled, or kSpecAtRunTime to compile both and
// read RenderParams.
PT_CONST uint kSpecAtRunTime = 0xFFFFFFFFu;

// Workgroups of 8 x 8 pixels. Lavapipe runs eight invocations of a row as one vector whatever
// the shape (16 x 16, 32 x 2 and 64 x 1 measure the same there); on a GPU, 8 x 8 gives a warp
// of 32 a tile of 8 x 4 pixels, whose primary rays stay together.
PT_CONST uint kWorkgroupSize = 8u;

// Push constants of one dispatch (one pass): which sample index every pixel takes.
struct PassConstants {
  uint sampleIndex;  // 4 bytes: the first sample index of this dispatch
  uint sampleCount;  // 4 bytes: samples per pixel in this dispatch, indices sampleIndex + i
  uint debugPixel;   // 4 bytes: y * width + x of the pixel whose path is printed, or ~0u
  uint reserved;     // 4 bytes: SPPM's photons: the first; BDPT: the strategy (bdpt.glsl)
};                   // 16 bytes

// Per-pixel accumulation on the device, in float; the host folds it into its double
// precision film every few passes and clears it, so float sums never grow long.
struct AccumPixel {
  vec3 sum;      // 12 bytes: sum of valid samples' radiance
  uint invalid;  //  4 bytes: samples that came out NaN or Inf (not added to sum)
};               // 16 bytes

struct DeviceCounters {
  uint raysLow;            // 4 bytes: rays traced, low 32 bits
  uint raysHigh;           // 4 bytes: rays traced, high 32 bits (carried by the shader)
  uint truncated;          // 4 bytes: samples whose loops lavapipe's iteration cap cut short
  uint maxLoopIterations;  // 4 bytes: most loop iterations one invocation counted
};                         // 16 bytes

// ---- Ray queries (shaders/raycast.comp: traversal tested on its own) --------------------

#define PT_RAYCAST_BINDING_NODES 0      // GpuBvhNode[], texels
#define PT_RAYCAST_BINDING_TRIANGLES 1  // Triangle[], texels
#define PT_RAYCAST_BINDING_QUERIES 2    // RayQuery[]
#define PT_RAYCAST_BINDING_RESULTS 3    // RayResult[]
PT_CONST uint kRaycastWorkgroupSize = 64u;

struct RayQuery {
  vec3 origin;     // 12 bytes
  float tMax;      //  4 bytes: hits with 0 < t < tMax count
  vec3 direction;  // 12 bytes: need not be unit length
  uint anyHit;     //  4 bytes: 1: stop at the first hit found (shadow ray), 0: closest
};                 // 32 bytes

struct RayResult {
  float t;         // 4 bytes: distance of the hit, tMax when none
  uint triangle;   // 4 bytes: index into the triangle buffer (leaf order)
  uint found;      // 4 bytes: 1 when something was hit
  uint truncated;  // 4 bytes: 1 when lavapipe's loop cap cut the traversal short
};                 // 16 bytes

// ---- Random-number dimensions ----------------------------------------------------------
// Random numbers are a pure function of (pixel, sample index, dimension, seed); see
// sampling.h. One dimension yields up to two numbers. Each path uses dimension kDimPixel for
// the pixel filter's sample (and kDimLens for a thin lens), then kDimsPerBounce dimensions per
// scattering event, starting at kDimFirstBounce + kDimsPerBounce * bounce.
PT_CONST uint kDimPixel = 0u;
PT_CONST uint kDimFirstBounce = 1u;
PT_CONST uint kDimsPerBounce = 4u;
PT_CONST uint kDimLightChoose = 0u;  // +0: alias-table slot and coin
PT_CONST uint kDimLightPoint = 1u;   // +1: point on the emitter triangle
PT_CONST uint kDimBsdf = 2u;         // +2: BSDF direction
PT_CONST uint kDimRoulette = 3u;     // +3: Russian roulette
// The point on a thin lens (Camera::lensRadius > 0 only: a pinhole draws nothing from it). A
// dimension no path's scattering events reach: bounce dimensions grow by kDimsPerBounce per
// event from kDimFirstBounce and would come to it at event number 2^30 - 1.
PT_CONST uint kDimLens = 0xFFFFFFFFu;

#ifdef __cplusplus
}  // namespace pt
#endif

#endif  // PT_SHARED_TYPES_H
