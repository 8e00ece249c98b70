// Bidirectional path tracing on the Vulkan backend (docs/bdpt.md): pathtrace.comp's PT_BDPT
// variant (shaders/bdpt.glsl) traces one pixel sample per invocation, every strategy of the CPU
// reference's (cpu/bdpt.h) from the same headers, and adds its own sample and its light-tracing
// splats into a film of exact sums on the device, which the host folds into its film. Light
// header: no Vulkan-Hpp.
#pragma once

#include "image/image.h"
#include "render/prepare.h"
#include "vulkan/backend.h"

namespace pt {

// Renders options.spp passes of one sample index each (options.bdptStrategy: one strategy
// alone, or all of them weighed), as renderBdpt (cpu/bdpt.h) does: the film's sums are exact,
// so the image does not depend on the order the device adds in, and equals the CPU reference's
// up to the floats each computes. The film holds whole passes after every fold (about one a
// second, and at the end), when options.checkpoint is called: no batch is ever left open.
// Throws InputError where the device lacks 64-bit buffer atomics, the film exceeds its
// storage-buffer limit, or a sample ran into lavapipe's loop-iteration cap.
VulkanRenderStats renderBdptVulkan(const SceneData& scene, const VulkanRenderOptions& options,
                                   Film& film);

}  // namespace pt
