// The GPU-visible structs for C++, with compile-time proof that their layout is the std430
// layout GLSL sees (sizes and offsets), so one declaration serves both languages.
#pragma once

#include <cstddef>

#include "sampling.h"
#include "shared_types.h"

namespace pt {

static_assert(sizeof(vec3) == 12 && alignof(vec3) == 4, "GLM must not pad vec3");

static_assert(sizeof(BvhNode) == 32);
static_assert(offsetof(BvhNode, boundsMin) == 0 && offsetof(BvhNode, offset) == 12);
static_assert(offsetof(BvhNode, boundsMax) == 16 && offsetof(BvhNode, count) == 28);

static_assert(sizeof(GpuBvhNode) == 64);
static_assert(offsetof(GpuBvhNode, leftMin) == 0 && offsetof(GpuBvhNode, left) == 12);
static_assert(offsetof(GpuBvhNode, leftMax) == 16 && offsetof(GpuBvhNode, right) == 28);
static_assert(offsetof(GpuBvhNode, rightMin) == 32 && offsetof(GpuBvhNode, reserved0) == 44);
static_assert(offsetof(GpuBvhNode, rightMax) == 48 && offsetof(GpuBvhNode, reserved1) == 60);

static_assert(sizeof(Triangle) == 48);
static_assert(offsetof(Triangle, v0) == 0 && offsetof(Triangle, material) == 12);
static_assert(offsetof(Triangle, v1) == 16 && offsetof(Triangle, emitter) == 28);
static_assert(offsetof(Triangle, v2) == 32 && offsetof(Triangle, primitive) == 44);

static_assert(sizeof(Material) == 96 && sizeof(Material) == 16 * kMaterialTexels);
static_assert(offsetof(Material, reflectance) == 0 && offsetof(Material, type) == 12);
static_assert(offsetof(Material, emission) == 16 && offsetof(Material, twoSided) == 28);
static_assert(offsetof(Material, eta) == 32 && offsetof(Material, alphaX) == 44);
static_assert(offsetof(Material, k) == 48 && offsetof(Material, alphaY) == 60);
static_assert(offsetof(Material, transmittance) == 64 && offsetof(Material, thickness) == 76);
static_assert(offsetof(Material, g) == 80 && offsetof(Material, maxDepth) == 84);
static_assert(offsetof(Material, nSamples) == 88 && offsetof(Material, reserved1) == 92);

static_assert(sizeof(LightBvhNode) == 16 * kLightBvhTexels);
static_assert(offsetof(LightBvhNode, phi) == 12 && offsetof(LightBvhNode, w) == 16);
static_assert(offsetof(LightBvhNode, radius) == 32 && offsetof(LightBvhNode, flags) == 44);
static_assert(offsetof(LightBvhNode, child) == 48 && offsetof(LightBvhNode, reserved1) == 60);

static_assert(sizeof(TriangleNormals) == 48);
static_assert(offsetof(TriangleNormals, n1) == 16 && offsetof(TriangleNormals, n2) == 32);

static_assert(sizeof(Medium) == 144 && sizeof(Medium) == 16 * kMediumTexels);
static_assert(offsetof(Medium, type) == 12 && offsetof(Medium, g) == 28);
static_assert(offsetof(Medium, emissive) == 44 && offsetof(Medium, density) == 60);
static_assert(offsetof(Medium, majorants) == 76 && offsetof(Medium, emission) == 92);
static_assert(offsetof(Medium, toMedium0) == 96 && offsetof(Medium, toMedium2) == 128);
static_assert(sizeof(MediumInterface) == 8);

static_assert(sizeof(Emitter) == 16);
static_assert(offsetof(Emitter, pmf) == 4 && offsetof(Emitter, aliasThreshold) == 8);
static_assert(offsetof(Emitter, alias) == 12);

static_assert(sizeof(Camera) == 160);
static_assert(offsetof(Camera, forward) == 16 && offsetof(Camera, right) == 32);
static_assert(offsetof(Camera, up) == 48 && offsetof(Camera, height) == 60);
static_assert(offsetof(Camera, windowCenter) == 64 && offsetof(Camera, lensRadius) == 76);
static_assert(offsetof(Camera, cropX) == 80 && offsetof(Camera, filmHeight) == 92);
static_assert(offsetof(Camera, filterType) == 96 && offsetof(Camera, focalDistance) == 108);
static_assert(offsetof(Camera, filterWeight) == 112 && offsetof(Camera, filterC) == 124);
static_assert(offsetof(Camera, filterRootsNear) == 128 && offsetof(Camera, filterExpX) == 140);
static_assert(offsetof(Camera, filterRootsFar) == 144 && offsetof(Camera, filterExpY) == 156);

// RenderParams after its Camera, whatever the Camera's size (a multiple of 16 bytes).
inline constexpr std::size_t kParamsBase = sizeof(Camera);
static_assert(kParamsBase % 16 == 0);
static_assert(sizeof(RenderParams) == kParamsBase + 208);
static_assert(offsetof(RenderParams, minPosDifferentialX) == kParamsBase + 144);
static_assert(offsetof(RenderParams, footprints) == kParamsBase + 172);
static_assert(offsetof(RenderParams, minDirDifferentialY) == kParamsBase + 192);
static_assert(offsetof(RenderParams, cameraMedium) == kParamsBase + 128);
static_assert(offsetof(RenderParams, maxDepth) == kParamsBase);
static_assert(offsetof(RenderParams, seed) == kParamsBase + 12);
static_assert(offsetof(RenderParams, russianRoulette) == kParamsBase + 20);
static_assert(offsetof(RenderParams, normalsPresent) == kParamsBase + 32);
static_assert(offsetof(RenderParams, sceneRadius) == kParamsBase + 44);
static_assert(offsetof(RenderParams, environment) == kParamsBase + 48);
static_assert(offsetof(RenderParams, environmentPdf) == kParamsBase + 60);
static_assert(offsetof(RenderParams, sceneCenter) == kParamsBase + 64);
static_assert(offsetof(RenderParams, environmentX) == kParamsBase + 80);
static_assert(offsetof(RenderParams, environmentWidth) == kParamsBase + 92);
static_assert(offsetof(RenderParams, environmentHeight) == kParamsBase + 108);
static_assert(offsetof(RenderParams, environmentMapping) == kParamsBase + 124);

static_assert(sizeof(TextureNode) == 16 * kTextureNodeTexels);
static_assert(offsetof(TextureNode, type) == 12 && offsetof(TextureNode, mapping) == 16);
static_assert(offsetof(TextureNode, texels) == 32 && offsetof(TextureNode, count) == 52);
static_assert(offsetof(TextureNode, levels) == 56 && offsetof(TextureNode, maxAnisotropy) == 60);
static_assert(offsetof(TextureNode, skew) == 64);
static_assert(sizeof(TriangleUVs) == 32 && offsetof(TriangleUVs, uv2) == 16);
static_assert(sizeof(MaterialTextures) == 16 * kMaterialTextureTexels);
static_assert(offsetof(MaterialTextures, displacement) == 24 &&
              offsetof(MaterialTextures, scale) == 36 && offsetof(MaterialTextures, alpha) == 28 &&
              offsetof(MaterialTextures, emission) == 48 &&
              offsetof(MaterialTextures, alphaCutoff) == 60);
static_assert(sizeof(Light) == 64 && sizeof(Light) == 16 * kLightTexels);
static_assert(offsetof(Light, radius) == 48 && offsetof(Light, material) == 52);
static_assert(offsetof(Light, type) == 12 && offsetof(Light, radiance) == 16);
static_assert(offsetof(Light, cosFalloffStart) == 28 && offsetof(Light, direction) == 32);
static_assert(offsetof(Light, cosFalloffEnd) == 44);

static_assert(sizeof(PassConstants) == 16 && offsetof(PassConstants, sampleCount) == 4 &&
              offsetof(PassConstants, debugPixel) == 8);
static_assert(sizeof(AccumPixel) == 16 && offsetof(AccumPixel, invalid) == 12);
static_assert(sizeof(DeviceCounters) == 16 && offsetof(DeviceCounters, truncated) == 8);

static_assert(sizeof(RayQuery) == 32 && offsetof(RayQuery, direction) == 16);
static_assert(offsetof(RayQuery, anyHit) == 28);
static_assert(sizeof(RayResult) == 16 && offsetof(RayResult, truncated) == 12);

}  // namespace pt
