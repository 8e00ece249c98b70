// Scene -> the flat arrays both backends read: the BVH (nodes, triangles in leaf order),
// materials, the emitter alias table and the per-render parameters, plus the set of
// effects the scene calls for. The Vulkan backend uploads exactly these arrays; the CPU
// reference reads them in place, but for the BVH, which it traverses in an eight-wide copy,
// and the triangles' normals, areas and offset scales, which it computes once (CpuSceneCopies).
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "bvh/bvh.h"
#include "bvh/wide_bvh.h"
#include "path_vertex.h"
#include "scene/scene.h"
#include "texture.h"

namespace pt {

// The renderer's BVH builder: PLOC on the Morton order. On the seed's scene (bunny and
// dragon, 0.94M triangles, 256x256, 16 spp on 2 CPU threads) it gave the shortest time to an
// image, build included: 1.29 s against 1.43 s for the plain LBVH and 1.55 s for binned SAH
// (tools/bvh-bench.sh), and the images are the same with every builder.
inline constexpr BvhBuilder kDefaultBuilder = BvhBuilder::kPloc;

// The BVH's leaf size when none is given, per backend (the images do not depend on it; the
// speed does). Lavapipe traced 3 triangles per leaf 5 to 23 % faster than 4 (Cornell box and
// its mirror variant +23 %, the seed's scene +5 %, the bunny box the same; 2 was slower on the
// meshes). The CPU tests a leaf four triangles at a time (wide_bvh.h), and 8 per leaf, two
// such tests, was the fastest there: against 4, the bunny box +10 %, the Cornell boxes
// +0.3 to +4 %, the seed's scene the same within the noise; 16 was no faster than 8.
inline constexpr int kDefaultLeafSizeCpu = 8;
inline constexpr int kDefaultLeafSizeVulkan = 3;

// Overrides of the scene's camera and integrator settings (unset: the scene's), and the
// settings the scene file does not hold.
struct RenderSettings {
  std::optional<int> width, height;
  std::optional<int> spp;
  std::optional<uint32_t> seed;
  std::optional<int> maxDepth;
  std::optional<uint> integrator;  // kIntegrator*
  std::optional<uint> strategy;    // kStrategy*
  std::optional<bool> russianRoulette;
  std::optional<uint> sampler;       // kSampler*
  std::optional<uint> lightSampler;  // kLightSampler*
  int maxLeafSize = kDefaultLeafSizeCpu;
  BvhBuilder builder = kDefaultBuilder;
  bool fastIntersection = false;  // Moller-Trumbore instead of the watertight test
  // MIS renders of an environment image: light sampling from pbrt-v4's compensated
  // distribution (render/environment_map.h); unset: kEnvironmentCompensationDefault.
  std::optional<bool> environmentCompensation;
};

// Which effects the scene calls for; the rest are compiled or switched out.
struct EffectSet {
  bool diffuse = false;  // some surface is Lambertian with non-zero reflectance
  bool mirror = false;   // some surface is an ideal mirror
  // The material types of shaders/bsdf.h that some surface has.
  bool conductor = false;
  bool dielectric = false;
  bool thinDielectric = false;
  bool diffuseTransmission = false;
  bool coatedDiffuse = false;
  bool gltf = false;
  bool gltfLayers = false;      // some gltf material uses an extension (transmission, clearcoat...)
  bool gltfSheen = false;       // some gltf material has KHR_materials_sheen
  bool shadingNormals = false;  // some mesh has vertex normals: shading normals interpolated
  bool deltaLights = false;     // point, spot or distant lights (sampled, never hit)
  bool environment = false;     // an infinite light: rays that leave the scene see it
  bool environmentImage = false;  // that light is an image (shaders/environment.h)
  bool twoSidedEmitters = false;  // some emissive triangle emits on both sides
  bool sphereLights = false;      // sphere area lights, sampled by the cone they subtend
  bool lightBvh = false;          // emitters are chosen by the light BVH
  bool textures = false;          // some material has a parameter given by a texture
  bool alphaCutouts = false;      // some material has an alpha texture (any-hit tests)
  bool bumpMaps = false;          // some material has a displacement texture
  bool media = false;             // participating media: the volume integrator (volpath)
  bool interfaces = false;        // some triangle only bounds media (`interface` material)
  uint mediumKinds = 0;           // bit 1 << kMedium* for each type of medium present
  uint textureFeatures = 0;       // kTextureUses*: what the used materials' textures need
  bool lightSampling = false;     // next-event estimation (needs emitters, a diffuse surface)
  bool bsdfEmission = false;      // emission found by BSDF-sampled rays is counted (MIS/BSDF)
  bool mis = false;               // both of the above, weighed by the power heuristic
  bool russianRoulette = false;
  bool watertight = true;  // false: the faster, leaky Moller-Trumbore test
  bool sobol = false;      // Owen-scrambled Sobol numbers instead of independent ones
  bool hasBsdfMaterials() const {
    return conductor || dielectric || thinDielectric || diffuseTransmission || coatedDiffuse ||
           gltf;
  }
  std::string toString() const;  // e.g. "diffuse+mirror+nee+mis+rr" (+"fast-isect", "sobol")
};

// One TriangleShading (path_vertex.h) per triangle, in the order of `triangles`
// (Bvh::triangles): what the CPU reads at every hit and light sample, computed once.
std::vector<TriangleShading> computeTriangleShading(const std::vector<Triangle>& triangles);

// What only the CPU reference reads: the wide copy of the BVH (wide_bvh.h), the
// triangles' shading constants, and which triangles alpha tests may cut away.
struct CpuSceneCopies {
  WideBvh wide;
  std::vector<TriangleShading> shading;  // in Bvh::triangles order
  // Bit t (word t / 64, bit t % 64): Bvh::triangles[t]'s material has an alpha texture. The
  // traversal's candidate hits read it instead of the triangle (a cache miss at every
  // candidate); empty where no material has one.
  std::vector<uint64_t> cutouts;
};

// CpuSceneCopies, built on first use, once, by whichever thread asks first: the Vulkan
// backend never asks, and does not pay for them. A copy of the holder starts empty and builds
// its own, so it never describes another BVH than its owner's.
class LazyCpuSceneCopies {
 public:
  LazyCpuSceneCopies() : state_(std::make_unique<State>()) {}
  LazyCpuSceneCopies(const LazyCpuSceneCopies&) : LazyCpuSceneCopies() {}
  LazyCpuSceneCopies(LazyCpuSceneCopies&&) noexcept = default;
  LazyCpuSceneCopies& operator=(const LazyCpuSceneCopies&) {
    state_ = std::make_unique<State>();
    return *this;
  }
  LazyCpuSceneCopies& operator=(LazyCpuSceneCopies&&) noexcept = default;

  // Once per ray in the CPU reference: inline, one load and a branch once it is built.
  const CpuSceneCopies& get(const Bvh& bvh,
                            const std::vector<MaterialTextures>& materialTextures) const {
    if (!state_->built.load(std::memory_order_acquire)) build(bvh, materialTextures);
    return state_->copies;
  }

 private:
  struct State {
    std::once_flag once;
    std::atomic<bool> built{false};
    CpuSceneCopies copies;
  };
  void build(const Bvh& bvh, const std::vector<MaterialTextures>& materialTextures) const;
  std::unique_ptr<State> state_;
};

struct SceneData {
  Bvh bvh;
  std::vector<Material> materials;
  std::vector<Emitter> emitters;  // alias table; empty when nothing emits
  std::vector<Light> lights;      // the analytic lights the emitters beyond the triangles name
  // Vertex normals by Triangle::primitive (load order), or empty when no mesh has any.
  std::vector<TriangleNormals> normals;
  // Textures (shaders/texture.h), all empty where no material has one: texture coordinates by
  // Triangle::primitive (every triangle's, pbrt-v4's defaults where its mesh has none), the
  // textures' programs, the image buffer, and per material the textures of its parameters.
  std::vector<TriangleUVs> uvs;
  std::vector<TextureNode> textureNodes;
  std::vector<uint32_t> imageWords;
  std::vector<MaterialTextures> materialTextures;
  // The environment image's texels and sampling distribution (shaders/environment.h), empty
  // without one, and its file (for messages).
  std::vector<vec4> environmentTexels;
  std::string environmentFile;
  // Participating media (shaders/medium.h), all empty in a scene without any: the media, the
  // floats of their grids followed by their majorant grids, and the media on the two sides of
  // each triangle by Triangle::primitive.
  std::vector<Medium> media;
  std::vector<float> mediumGrids;
  std::vector<MediumInterface> mediumInterfaces;
  // The light BVH (render/light_bvh.h), empty unless the light sampler is the BVH and some
  // emitter has a position: its nodes, and each emitter's leaf followed by the unbounded
  // emitters.
  std::vector<LightBvhNode> lightBvh;
  std::vector<uint32_t> lightBvhWords;
  RenderParams params{};
  int spp = 0;
  uint integrator = kIntegratorPath;  // kIntegrator* (common/named_values.h)
  SppmSettings sppm;                  // kIntegratorSppm's parameters
  EffectSet effects;
  vec3 shift{0.0f};        // subtracted from every coordinate of a scene far from the origin
  LazyCpuSceneCopies cpu;  // of bvh; through cpuCopies() and wideBvh()

  // What only the CPU reference reads, built from bvh on the first call.
  const CpuSceneCopies& cpuCopies() const { return cpu.get(bvh, materialTextures); }
  // The BVH the CPU reference traverses: bvh collapsed to eight-wide nodes, with the same
  // answers to every query (wide_bvh.h).
  const WideBvh& wideBvh() const { return cpuCopies().wide; }
  // What shaders/texture.h reads on the CPU.
  TextureTables textureTables() const {
    return TextureTables{textureNodes.data(), imageWords.data(), materialTextures.data(),
                         uvs.data()};
  }
  // What shaders/path_vertex.h reads on the CPU (builds cpuCopies on a first call).
  PathScene pathScene() const {
    return PathScene{&params,
                     bvh.triangles.data(),
                     cpuCopies().shading.data(),
                     materials.data(),
                     emitters.data(),
                     lights.data(),
                     normals.empty() ? nullptr : normals.data(),
                     textureTables(),
                     environmentTexels.data(),
                     media.empty() ? nullptr : media.data(),
                     mediumGrids.empty() ? nullptr : mediumGrids.data(),
                     mediumInterfaces.empty() ? nullptr : mediumInterfaces.data(),
                     lightBvh.empty() ? nullptr : lightBvh.data(),
                     lightBvhWords.empty() ? nullptr : lightBvhWords.data()};
  }
};

// Takes the scene by value: pass it with std::move when it is not needed afterwards, so that
// its triangles move into the BVH builder instead of being copied (one copy fewer at peak).
SceneData prepareScene(Scene scene, const RenderSettings& settings);

// Builds the alias table over the emissive triangles (in the given order), with pmf
// proportional to emitted power (area x luminance of the emission), and stores each
// triangle's emitter index in Triangle::emitter. Exposed for tests.
std::vector<Emitter> buildEmitters(std::vector<Triangle>& triangles,
                                   const std::vector<Material>& materials);

// The same with analytic lights (struct Light) after the triangles. Distant and infinite lights
// take 1 / (U + 1) each (U of them; 1 / U when nothing else emits), as pbrt-v4's default
// light sampler gives them; point and spot lights join the triangles, which share the rest
// by power, a light's as pbrt-v4's Light::Phi gives it (divided by pi, as the triangles'
// area x luminance is). `uniform`: every emitter alike instead (pbrt-v4's "uniform").
std::vector<Emitter> buildEmitters(std::vector<Triangle>& triangles,
                                   const std::vector<Material>& materials,
                                   const std::vector<Light>& lights, float sceneRadius,
                                   bool uniform = false);

}  // namespace pt
