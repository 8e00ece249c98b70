// Stochastic progressive photon mapping on the Vulkan backend (docs/sppm.md): the camera pass
// and the photon pass on the device, as variants of shaders/pathtrace.comp (shaders/sppm.glsl),
// the hash grid and the pixels' update on the host between them, with the CPU reference's own
// code (cpu/sppm_grid.h, sppm_vertex.h's sppmUpdatePixel). Light header: no Vulkan-Hpp.
#pragma once

#include "image/image.h"
#include "render/prepare.h"
#include "vulkan/backend.h"

namespace pt {

// Renders options.spp iterations as renderSppm (cpu/sppm.h) does, each pixel's estimate added
// to the film as its one sample. A photon's flux is summed on the device exactly (64-bit
// atomics on the film's fixed point), so the image does not depend on the order photons
// arrive in: the same bits on every run. Throws InputError where the device lacks 64-bit
// buffer atomics or the pixels' state exceeds its storage-buffer limit.
VulkanRenderStats renderSppmVulkan(const SceneData& scene, const VulkanRenderOptions& options,
                                   Film& film);

}  // namespace pt
