// Scene preparation; see prepare.h.
#include "render/prepare.h"

#include <algorithm>
#include <cmath>

#include "bsdf.h"
#include "common/check.h"
#include "lights.h"
#include "render/camera.h"
#include "render/environment_map.h"
#include "render/light_bvh.h"
#include "render/prepare_media.h"
#include "texture.h"

namespace pt {

std::vector<TriangleShading> computeTriangleShading(const std::vector<Triangle>& triangles) {
  std::vector<TriangleShading> shading;
  shading.reserve(triangles.size());
  for (const Triangle& t : triangles) shading.push_back(triangleShadingOf(t));
  return shading;
}

void LazyCpuSceneCopies::build(const Bvh& bvh,
                               const std::vector<MaterialTextures>& materialTextures) const {
  std::call_once(state_->once, [&] {
    CpuSceneCopies& c = state_->copies;
    c.wide = buildWideBvh(bvh);
    c.shading = computeTriangleShading(bvh.triangles);
    const auto cutAway = [&](uint material) {
      return material < materialTextures.size() && materialTextures[material].alpha != kNoTexture;
    };
    if (std::any_of(bvh.triangles.begin(), bvh.triangles.end(),
                    [&](const Triangle& t) { return cutAway(t.material); })) {
      c.cutouts.assign((bvh.triangles.size() + 63) / 64, 0);
      for (size_t t = 0; t < bvh.triangles.size(); ++t) {
        if (cutAway(bvh.triangles[t].material)) c.cutouts[t / 64] |= uint64_t(1) << (t % 64);
      }
    }
    state_->built.store(true, std::memory_order_release);
  });
}

std::string EffectSet::toString() const {
  std::string s;
  auto add = [&s](bool on, std::string_view name) {
    if (!on) return;
    if (!s.empty()) s += '+';
    s += name;
  };
  add(diffuse, "diffuse");
  add(mirror, "mirror");
  add(conductor, "conductor");
  add(dielectric, "dielectric");
  add(thinDielectric, "thindielectric");
  add(diffuseTransmission, "diffusetransmission");
  add(coatedDiffuse, "coateddiffuse");
  add(gltf, "gltf");
  add(gltfLayers, "gltf-layers");
  add(gltfSheen, "gltf-sheen");
  add(shadingNormals, "shading-normals");
  add(deltaLights, "delta-lights");
  add(environment, "environment");
  add(environmentImage, "environment-image");
  add(twoSidedEmitters, "two-sided-emitters");
  add(sphereLights, "sphere-lights");
  add(lightBvh, "light-bvh");
  add(textures, "textures");
  add(alphaCutouts, "alpha");
  add(bumpMaps, "bump");
  add(media, "media");
  add(lightSampling, "nee");
  add(mis, "mis");
  add(russianRoulette, "rr");
  add(!watertight, "fast-isect");
  add(sobol, nameOf(kSamplerNames, kSamplerSobol));
  return s.empty() ? "none" : s;
}

namespace {

double luminance(vec3 c) {
  return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
}

// A light's power divided by pi (pbrt-v4's Light::Phi, from luminance): point 4 pi I, spot
// 2 pi I (1 - (cosStart + cosEnd) / 2), distant pi r^2 L, infinite 4 pi^2 r^2 L.
double lightPowerOverPi(const Light& light, double sceneRadius) {
  const double y = luminance(light.radiance);
  const double pi = 3.14159265358979323846;
  switch (light.type) {
    case kLightPoint:
      return 4.0 * y;
    case kLightSpot:
      return 2.0 * y * (1.0 - 0.5 * (double(light.cosFalloffStart) + double(light.cosFalloffEnd)));
    case kLightDistant:
      return y * sceneRadius * sceneRadius;
    case kLightSphere:
      return 4.0 * pi * double(light.radius) * double(light.radius) * y;
    default:
      return 4.0 * pi * y * sceneRadius * sceneRadius;
  }
}

}  // namespace

std::vector<Emitter> buildEmitters(std::vector<Triangle>& triangles,
                                   const std::vector<Material>& materials) {
  return buildEmitters(triangles, materials, {}, 0.0f);
}

std::vector<Emitter> buildEmitters(std::vector<Triangle>& triangles,
                                   const std::vector<Material>& materials,
                                   const std::vector<Light>& lights, float sceneRadius,
                                   bool uniform) {
  // Power of each emissive triangle: one-sided, so flux = pi * area * radiance; the pmf only
  // needs proportions, and luminance weights the channels.
  std::vector<Emitter> emitters;
  std::vector<double> power;
  // The triangles of a sphere light are not emitters of their own: its Emitter is theirs.
  std::vector<uint32_t> sphereOf(materials.size(), kNoEmitter);
  for (uint32_t i = 0; i < lights.size(); ++i) {
    if (lights[i].type == kLightSphere && lights[i].material < materials.size()) {
      sphereOf[lights[i].material] = i;
    }
  }
  for (uint32_t i = 0; i < triangles.size(); ++i) {
    Triangle& tri = triangles[i];
    tri.emitter = kNoEmitter;
    if (sphereOf[tri.material] != kNoEmitter) continue;
    const vec3 e = materials[tri.material].emission;
    const double luminance = 0.2126 * e.x + 0.7152 * e.y + 0.0722 * e.z;
    const double area = 0.5 * double(length(cross(tri.v1 - tri.v0, tri.v2 - tri.v0)));
    if (!(luminance > 0.0) || !(area > 0.0)) continue;
    tri.emitter = uint32_t(emitters.size());
    emitters.push_back(Emitter{i, 0.0f, 1.0f, uint32_t(emitters.size())});
    power.push_back(materials[tri.material].twoSided != 0u ? 2.0 * luminance * area
                                                           : luminance * area);
  }
  // Lights without a position (distant, infinite) are chosen as pbrt-v4's default light
  // sampler (its BVHLightSampler) chooses them: each with probability 1 / (U + 1), U their
  // number, and the lights with a position (triangles, point, spot) share the rest by power.
  // Weighed by power too, they would take nearly every sample (their power grows with the
  // scene's radius squared) and leave each local light rare samples of huge weight.
  std::vector<bool> unbounded(power.size(), false);
  for (uint32_t i = 0; i < lights.size(); ++i) {
    const double phi = lightPowerOverPi(lights[i], sceneRadius);
    if (!(phi > 0.0)) continue;  // a black light, or a distant one in an empty scene
    if (lights[i].type == kLightSphere) {
      for (Triangle& tri : triangles) {
        if (tri.material == lights[i].material) tri.emitter = uint32_t(emitters.size());
      }
    }
    emitters.push_back(Emitter{kEmitterLight | i, 0.0f, 1.0f, uint32_t(emitters.size())});
    power.push_back(phi);
    unbounded.push_back(lights[i].type == kLightDistant || lights[i].type == kLightInfinite);
  }
  if (emitters.empty()) return emitters;
  const size_t unboundedCount = size_t(std::count(unbounded.begin(), unbounded.end(), true));
  if (uniform) {
    std::fill(power.begin(), power.end(), 1.0);  // pbrt-v4's UniformLightSampler
  } else if (unboundedCount > 0) {
    double boundedPower = 0.0;
    for (size_t i = 0; i < power.size(); ++i) boundedPower += unbounded[i] ? 0.0 : power[i];
    const double share =
        boundedPower > 0.0 ? 1.0 / double(unboundedCount + 1) : 1.0 / double(unboundedCount);
    for (size_t i = 0; i < power.size(); ++i) {
      power[i] = unbounded[i] ? share : power[i] / boundedPower * share;
    }
  }

  // Vose's alias method: scale probabilities by n, then pair each under-full slot with an
  // over-full one that tops it up. Slots left at the end are full (threshold 1).
  const size_t n = emitters.size();
  double total = 0.0;
  for (double p : power) total += p;
  std::vector<double> scaled(n);
  std::vector<uint32_t> small, large;
  for (size_t i = 0; i < n; ++i) {
    emitters[i].pmf = float(power[i] / total);
    scaled[i] = power[i] / total * double(n);
    (scaled[i] < 1.0 ? small : large).push_back(uint32_t(i));
  }
  while (!small.empty() && !large.empty()) {
    const uint32_t s = small.back();
    small.pop_back();
    const uint32_t l = large.back();
    emitters[s].aliasThreshold = float(scaled[s]);
    emitters[s].alias = l;
    scaled[l] -= 1.0 - scaled[s];
    if (scaled[l] < 1.0) {
      large.pop_back();
      small.push_back(l);
    }
  }
  for (uint32_t i : small) emitters[i].aliasThreshold = 1.0f;  // rounding leftovers
  for (uint32_t i : large) emitters[i].aliasThreshold = 1.0f;
  return emitters;
}

namespace {

// pbrt-v4 sums the infinite lights' radiance where rays leave the scene; constant ones are one
// light of the summed radiance (the first keeps its place in the list).
std::vector<Light> mergeInfiniteLights(std::vector<Light> lights) {
  std::vector<Light> merged;
  int infinite = -1;
  for (const Light& light : lights) {
    if (light.type == kLightInfinite && infinite >= 0) {
      merged[size_t(infinite)].radiance += light.radiance;
      continue;
    }
    if (light.type == kLightInfinite) infinite = int(merged.size());
    merged.push_back(light);
  }
  return merged;
}

// A scene far from the origin (coordinates much larger than its extent) wastes float bits on
// the offset: at 1e5 the spacing of floats is 0.008, and ray offsets, which scale with the
// coordinates, grow with it. The image does not depend on where the scene is, so move it,
// with its camera, next to the origin. Per axis, only when the centre is farther out than
// the extent; then every coordinate is within a factor of two of the centre and the
// subtraction is exact (Sterbenz), so nothing is rounded. Returns the shift applied.
vec3 recentre(std::vector<Triangle>& triangles, CameraDesc& camera, std::vector<Light>& lights) {
  vec3 lo(INFINITY), hi(-INFINITY);
  for (const Triangle& t : triangles) {
    lo = min(lo, min(t.v0, min(t.v1, t.v2)));
    hi = max(hi, max(t.v0, max(t.v1, t.v2)));
  }
  vec3 shift(0.0f);
  for (int axis = 0; axis < 3; ++axis) {
    const float centre = 0.5f * lo[axis] + 0.5f * hi[axis];
    if (std::fabs(centre) > 2.0f * (hi[axis] - lo[axis])) shift[axis] = centre;
  }
  if (shift == vec3(0.0f)) return shift;
  for (Triangle& t : triangles) {
    t.v0 -= shift;
    t.v1 -= shift;
    t.v2 -= shift;
  }
  camera.position -= shift;
  camera.target -= shift;
  for (Light& light : lights) light.position -= shift;
  return shift;
}

}  // namespace

SceneData prepareScene(Scene scene, const RenderSettings& settings) {
  SceneData data;
  const int width = settings.width.value_or(scene.camera.width);
  const int height = settings.height.value_or(scene.camera.height);
  const IntegratorSettings& integ = scene.integrator;
  data.spp = settings.spp.value_or(integ.spp);
  data.integrator = settings.integrator.value_or(integ.integrator);
  data.sppm = integ.sppm;
  data.materials = scene.materials;
  data.normals = std::move(scene.normals);
  PT_CHECK(data.normals.empty() || data.normals.size() == scene.triangles.size());

  // Textures only where some material has one; then every triangle has coordinates.
  if (!scene.materialTextures.empty()) {
    PT_CHECK(scene.materialTextures.size() == scene.materials.size());
    PT_CHECK(scene.uvs.empty() || scene.uvs.size() == scene.triangles.size());
    if (scene.uvs.empty()) scene.uvs.assign(scene.triangles.size(), defaultTriangleUVs());
    data.uvs = std::move(scene.uvs);
    data.textureNodes = std::move(scene.textureNodes);
    data.imageWords = std::move(scene.imageWords);
    data.materialTextures = std::move(scene.materialTextures);
  }

  std::vector<Triangle> triangles = std::move(scene.triangles);
  CameraDesc camera = scene.camera;
  std::vector<Light> lights = std::move(scene.lights);
  if (scene.environment) {
    // The image is the infinite light; constant ones add their radiance to its texels (pbrt-v4
    // sums what the infinite lights emit).
    EnvironmentImage& env = *scene.environment;
    vec3 constant(0.0f);
    std::erase_if(lights, [&](const Light& light) {
      if (light.type != kLightInfinite) return false;
      constant += light.radiance;
      return true;
    });
    if (constant != vec3(0.0f)) {
      for (vec3& c : env.image.pixels) c += constant;
    }
    Light light{};
    light.type = kLightInfinite;
    light.radiance = environmentMeanRadiance(env.image, env.mapping);
    lights.push_back(light);
  }
  lights = mergeInfiniteLights(std::move(lights));
  data.shift = recentre(triangles, camera, lights);
  data.bvh =
      buildBvh(std::move(triangles), BvhBuildOptions{settings.maxLeafSize, settings.builder});
  // The sphere about the scene's box, for distant and infinite lights (pbrt-v4's
  // scene radius).
  vec3 centre(0.0f);
  float radius = 0.0f;
  if (!data.bvh.nodes.empty()) {
    const BvhNode& root = data.bvh.nodes[0];
    centre = 0.5f * (root.boundsMin + root.boundsMax);
    radius = 0.5f * length(root.boundsMax - root.boundsMin);
  }
  // Emitters index triangles in leaf order, so they are built after the reorder.
  const uint lightSampler = settings.lightSampler.value_or(integ.lightSampler);
  data.emitters = buildEmitters(data.bvh.triangles, data.materials, lights, radius,
                                lightSampler == kLightSamplerUniform);
  LightBvh tree;
  if (lightSampler == kLightSamplerBvh) {
    tree = buildLightBvh(data.emitters, data.bvh.triangles, data.materials, lights);
  }
  if (!choosesByPowerAlone(tree)) {
    data.lightBvh = std::move(tree.nodes);
    data.lightBvhWords = std::move(tree.words);
    data.params.lightBvhNodes = uint32_t(data.lightBvh.size());
    data.params.unboundedEmitters = tree.unbounded;
    data.effects.lightBvh = true;
  }
  data.lights = std::move(lights);

  RenderParams& p = data.params;
  p.camera = makeCamera(camera, width, height);
  p.maxDepth = uint32_t(settings.maxDepth.value_or(integ.maxDepth));
  p.rrStartDepth = uint32_t(integ.rrStartDepth);
  p.emitterCount = uint32_t(data.emitters.size());
  p.lightCount = uint32_t(data.lights.size());
  p.sceneCenter = centre;
  p.sceneRadius = radius;
  p.environmentEmitter = kNoEmitter;
  for (uint32_t i = 0; i < data.emitters.size(); ++i) {
    const uint32_t ref = data.emitters[i].triangle;
    if ((ref & kEmitterLight) == 0u) continue;
    const Light& light = data.lights[ref & ~kEmitterLight];
    if (light.type == kLightInfinite && scene.environment) {
      // The image: environment.h gives each direction's radiance and density.
      p.environmentEmitter = i;
      p.environmentPdf = data.emitters[i].pmf;
      const EnvironmentImage& env = *scene.environment;
      p.environmentX = env.toWorld[0];
      p.environmentY = env.toWorld[1];
      p.environmentZ = env.toWorld[2];
      p.environmentWidth = uint32_t(env.image.width);
      p.environmentHeight = uint32_t(env.image.height);
      p.environmentMapping = env.mapping;
      data.effects.environmentImage = true;
    } else if (light.type == kLightInfinite) {
      p.environmentEmitter = i;
      p.environment = light.radiance;
      p.environmentPdf = environmentLightPdf(data.emitters[i].pmf);
    } else if (light.type == kLightSphere) {
      data.effects.sphereLights = true;
    } else {
      data.effects.deltaLights = true;
    }
  }
  data.effects.environment = p.environmentEmitter != kNoEmitter;
  p.seed = settings.seed.value_or(integ.seed);
  p.strategy = settings.strategy.value_or(integ.strategy);
  p.fastIntersection = settings.fastIntersection ? 1u : 0u;
  p.samplerType = settings.sampler.value_or(integ.sampler);
  p.russianRoulette = settings.russianRoulette.value_or(integ.russianRoulette) ? 1u : 0u;
  if (data.effects.environmentImage) {
    // The compensated distribution only where BSDF sampling covers what it leaves out (the
    // path tracer's MIS; BDPT's light subpaths start from the light's whole distribution).
    const bool compensated =
        p.strategy == kStrategyMis && data.integrator == kIntegratorPath &&
        settings.environmentCompensation.value_or(kEnvironmentCompensationDefault);
    data.environmentTexels =
        buildEnvironmentTexels(scene.environment->image, scene.environment->mapping, compensated);
    data.environmentFile = scene.environment->file;
  }

  prepareMedia(scene, data.shift, data);

  // Effects: which material kinds occur on triangles, and whether light sampling can matter.
  EffectSet& fx = data.effects;
  // What evaluating a texture needs: several nodes, an image lookup, EWA filtering, the ray's
  // footprint (an image or a checkerboard filters over it).
  const auto programFeatures = [&](uint first) {
    const uint count = data.textureNodes[first].count;
    uint bits = count > 1 ? kTextureUsesPrograms : 0u;
    for (uint i = 0; i < count; ++i) {
      const TextureNode& node = data.textureNodes[first + i];
      if (node.type == kTextureImage) {
        bits |= kTextureUsesImages | kTextureUsesFootprints;
        if (((node.flags >> 8u) & 0xFu) == kTextureEwa) bits |= kTextureUsesEwa;
      }
      if (node.type == kTextureCheckerboard) bits |= kTextureUsesFootprints;
    }
    return bits;
  };
  std::vector<char> used(data.materials.size(), 0);
  for (const Triangle& tri : data.bvh.triangles) used[tri.material] = 1;
  bool lightSampled = false;  // some surface has a BSDF with a non-delta lobe
  for (size_t i = 0; i < used.size(); ++i) {
    if (!used[i]) continue;
    if (data.materials[i].type == kMaterialInterface) {
      fx.interfaces = true;
      continue;
    }
    const Material& m = data.materials[i];
    // A texture's value is known only at a hit: a parameter with one counts as non-zero.
    const MaterialTextures* t = data.materialTextures.empty() ? nullptr : &data.materialTextures[i];
    const bool reflects =
        m.reflectance != vec3(0.0f) || (t != nullptr && t->reflectance != kNoTexture);
    if (t != nullptr) {
      const bool any = t->reflectance != kNoTexture || t->transmittance != kNoTexture ||
                       t->uRoughness != kNoTexture || t->vRoughness != kNoTexture ||
                       t->eta != kNoTexture || t->k != kNoTexture || t->thickness != kNoTexture ||
                       t->g != kNoTexture || t->emission != kNoTexture ||
                       t->normalMap != kNoTexture || gltfLayerTextured(*t);
      fx.textures = fx.textures || any;
      fx.alphaCutouts = fx.alphaCutouts || t->alpha != kNoTexture;
      fx.bumpMaps = fx.bumpMaps || t->displacement != kNoTexture;
      const auto uses = [&](uint texture, uint bit) {
        if (texture != kNoTexture) fx.textureFeatures |= bit | programFeatures(texture);
      };
      uses(t->reflectance, kTextureUsesReflectance);
      uses(t->transmittance, kTextureUsesTransmittance);
      uses(t->uRoughness, kTextureUsesRoughness);
      uses(t->vRoughness, kTextureUsesRoughness);
      uses(t->eta, kTextureUsesEtaK);
      uses(t->k, kTextureUsesEtaK);
      uses(t->thickness, kTextureUsesMedium);
      uses(t->g, kTextureUsesMedium);
      uses(t->emission, kTextureUsesEmission);
      uses(t->normalMap, kTextureUsesNormalMap);
      uses(t->transmission, kTextureUsesGltfLayers);
      uses(t->clearcoat, kTextureUsesGltfLayers);
      uses(t->clearcoatRoughness, kTextureUsesGltfLayers);
      uses(t->specular, kTextureUsesGltfLayers);
      uses(t->specularColour, kTextureUsesGltfLayers);
      uses(t->sheenColour, kTextureUsesGltfSheen);
      uses(t->sheenRoughness, kTextureUsesGltfSheen);
      uses(t->clearcoatNormal, kTextureUsesCoatNormal);
      // A clear coat over a normal-mapped base has a normal of its own, the unmapped one.
      if (m.type == kMaterialGltf && (m.nSamples & kGltfClearcoat) != 0u &&
          t->normalMap != kNoTexture) {
        fx.textureFeatures |= kTextureUsesCoatNormal;
      }
      // A bump map steps by the footprint; alpha is tested in the traversal, at a point.
      uses(t->displacement, kTextureUsesFootprints);
      if (t->alpha != kNoTexture) {
        fx.textureFeatures |= programFeatures(t->alpha) & ~kTextureUsesFootprints;
      }
      // Roughness that a texture gives may be smooth somewhere and rough elsewhere.
      if (m.type > kMaterialMirror &&
          (t->uRoughness != kNoTexture || t->vRoughness != kNoTexture)) {
        lightSampled = true;
      }
      // So may gltf's extension textures (a coat's roughness, a transmission below 1).
      if (m.type == kMaterialGltf && gltfLayerTextured(*t)) lightSampled = true;
    }
    if (m.type == kMaterialMirror && reflects) fx.mirror = true;
    if (m.type == kMaterialDiffuse && reflects) fx.diffuse = true;
    if (m.type == kMaterialConductor) fx.conductor = true;
    if (m.type == kMaterialDielectric) fx.dielectric = true;
    if (m.type == kMaterialThinDielectric) fx.thinDielectric = true;
    if (m.type == kMaterialDiffuseTransmission) fx.diffuseTransmission = true;
    if (m.type == kMaterialCoatedDiffuse) fx.coatedDiffuse = true;
    if (m.type == kMaterialGltf) fx.gltf = true;
    if (m.type == kMaterialGltf && m.nSamples != 0u) fx.gltfLayers = true;
    if (m.type == kMaterialGltf && (m.nSamples & kGltfSheen) != 0u) fx.gltfSheen = true;
    if (m.type > kMaterialMirror && bsdfHasNonSpecular(m)) lightSampled = true;
  }
  // Light is sampled from the points where a medium scatters.
  for (const Medium& m : data.media) {
    if (m.sigmaS != vec3(0.0f)) lightSampled = true;
  }
  const bool scatters = p.maxDepth > 0;
  fx.lightSampling = (fx.diffuse || lightSampled) && scatters && !data.emitters.empty() &&
                     p.strategy != kStrategyBsdf;
  // Emission found by BSDF-sampled rays: some triangle or the environment emits.
  bool hittable = fx.environment || fx.sphereLights;
  for (const Emitter& e : data.emitters) {
    if ((e.triangle & kEmitterLight) != 0u) continue;
    hittable = true;
    if (data.materials[data.bvh.triangles[e.triangle].material].twoSided != 0u) {
      fx.twoSidedEmitters = true;
    }
  }
  fx.bsdfEmission = hittable && p.strategy != kStrategyNee;
  p.texturesPresent = (fx.textures || fx.alphaCutouts || fx.bumpMaps) ? 1u : 0u;
  // Ray differentials where some texture reads the footprint (differentials.h).
  if ((fx.textureFeatures & kTextureUsesFootprints) != 0u) {
    p.footprints = 1u;
    setCameraDifferentials(p, data.spp);
  }
  fx.shadingNormals = !data.normals.empty();
  p.normalsPresent = fx.shadingNormals ? 1u : 0u;
  fx.watertight = !settings.fastIntersection;
  fx.sobol = p.samplerType == kSamplerSobol;
  fx.mis = fx.lightSampling && fx.bsdfEmission && p.strategy == kStrategyMis;
  fx.russianRoulette = p.russianRoulette != 0 && scatters &&
                       (fx.diffuse || fx.mirror || fx.hasBsdfMaterials() || fx.media);
  return data;
}

}  // namespace pt
