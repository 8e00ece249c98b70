// The shaders compiled at run time, for the scene at hand: glslang turns shaders/ (embedded in
// the binary at build time) into SPIR-V with the scene's effect set as preprocessor
// definitions, and SPIRV-Tools removes the code those definitions switch off. Lavapipe inlines
// every function before it removes dead code, so a shader carrying the code of effects the
// scene does not use costs it seconds per pipeline even where specialization constants switch
// that code off; removed here, it never reaches the driver (docs/performance.md).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace pt {

// SPIR-V (Vulkan 1.1) of shaders/`entry` with `definitions` ("#define NAME VALUE" lines; none
// for raycast.comp) in front of its text. Compiled once per process for each distinct pair, then
// reused; kept between processes in the disk cache of vulkan/spirv_cache.h, keyed by the pair,
// the embedded sources and the compilers' versions. An error in the embedded shaders is a bug
// of this build: PT_CHECK with glslang's log.
const std::vector<uint32_t>& compileShader(std::string_view entry, const std::string& definitions);

// A hash of every embedded shader source: film states record it, so that a render is only
// resumed or merged with samples from the same shaders.
uint64_t shaderSourcesHash();

}  // namespace pt
