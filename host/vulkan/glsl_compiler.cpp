// glslang (front end and SPIR-V generator) and SPIRV-Tools' optimizer, run in process on the
// shaders embedded at build time (cmake/embed_sources.cmake).
#include "vulkan/glsl_compiler.h"

#include <glslang/Public/ResourceLimits.h>
#include <glslang/Public/ShaderLang.h>
#include <glslang/SPIRV/GlslangToSpv.h>

#include <map>
#include <memory>
#include <mutex>
#include <spirv-tools/optimizer.hpp>
#include <utility>

#include "common/check.h"
#include "image/film_state.h"
#include "shader_sources.h"  // kShaderSources, generated from shaders/

namespace pt {
namespace {

std::string_view embeddedSource(std::string_view name) {
  for (const ShaderSource& s : kShaderSources) {
    if (s.name == name) return s.text;
  }
  return {};
}

// #include "x.h" resolved among the embedded files (shaders/ has no subfolders).
class EmbeddedIncluder : public glslang::TShader::Includer {
 public:
  IncludeResult* includeLocal(const char* headerName, const char*, size_t) override {
    const std::string_view text = embeddedSource(headerName);
    if (text.data() == nullptr) return nullptr;
    return new IncludeResult(headerName, text.data(), text.size(), nullptr);
  }
  IncludeResult* includeSystem(const char* headerName, const char* includer,
                               size_t depth) override {
    return includeLocal(headerName, includer, depth);
  }
  void releaseInclude(IncludeResult* result) override { delete result; }
};

// GLSL to SPIR-V as `glslangValidator -V --target-env vulkan1.1` compiles it (the build runs
// that on the same sources, with spirv-val, so that a shader error fails the build).
std::vector<uint32_t> glslToSpirv(std::string_view entry, const std::string& definitions) {
  const std::string_view text = embeddedSource(entry);
  PT_CHECK(text.data() != nullptr, "no embedded shader " + std::string(entry));
  glslang::TShader shader(EShLangCompute);
  const char* strings[] = {text.data()};
  const int lengths[] = {int(text.size())};
  const std::string name(entry);
  const char* names[] = {name.c_str()};
  shader.setStringsWithLengthsAndNames(strings, lengths, names, 1);
  shader.setPreamble(definitions.c_str());
  shader.setEnvInput(glslang::EShSourceGlsl, EShLangCompute, glslang::EShClientVulkan, 100);
  shader.setEnvClient(glslang::EShClientVulkan, glslang::EShTargetVulkan_1_1);
  shader.setEnvTarget(glslang::EShTargetSpv, glslang::EShTargetSpv_1_3);
  const auto messages = EShMessages(EShMsgSpvRules | EShMsgVulkanRules);
  EmbeddedIncluder includer;
  PT_CHECK(shader.parse(GetDefaultResources(), 100, false, messages, includer),
           name + ": " + shader.getInfoLog() + "\n(definitions:\n" + definitions + ")");
  glslang::TProgram program;
  program.addShader(&shader);
  PT_CHECK(program.link(messages), name + ": " + program.getInfoLog());
  std::vector<uint32_t> spirv;
  glslang::SpvOptions options;
  options.disableOptimizer = true;
  glslang::GlslangToSpv(*program.getIntermediate(EShLangCompute), spirv, &options);
  return spirv;
}

// The code behind branches on constants that are false goes, and the functions only it
// called: dead branches first (their conditions are constants of the definitions), then the
// instructions and functions nothing uses any more, twice, since removing code makes more
// branches' conditions constant. Nothing else: no pass here changes an arithmetic operation.
std::vector<uint32_t> removeDeadCode(const std::vector<uint32_t>& spirv, const std::string& name) {
  spvtools::Optimizer optimizer(SPV_ENV_VULKAN_1_1);
  std::string log;
  optimizer.SetMessageConsumer(
      [&log](spv_message_level_t, const char*, const spv_position_t&, const char* message) {
        log += message;
        log += '\n';
      });
  for (int round = 0; round < 2; ++round) {
    optimizer.RegisterPass(spvtools::CreateDeadBranchElimPass());
    optimizer.RegisterPass(spvtools::CreateAggressiveDCEPass());
    optimizer.RegisterPass(spvtools::CreateEliminateDeadFunctionsPass());
  }
  std::vector<uint32_t> out;
  PT_CHECK(optimizer.Run(spirv.data(), spirv.size(), &out), name + ": " + log);
  return out;
}

}  // namespace

const std::vector<uint32_t>& compileShader(std::string_view entry, const std::string& definitions) {
  static std::mutex mutex;
  static std::map<std::pair<std::string, std::string>, std::unique_ptr<std::vector<uint32_t>>>
      compiled;
  const std::lock_guard<std::mutex> lock(mutex);
  std::unique_ptr<std::vector<uint32_t>>& spirv = compiled[{std::string(entry), definitions}];
  if (!spirv) {
    static const bool initialized = glslang::InitializeProcess();
    PT_CHECK(initialized, "glslang failed to initialize");
    const std::string name(entry);
    spirv = std::make_unique<std::vector<uint32_t>>(
        removeDeadCode(glslToSpirv(entry, definitions), name));
  }
  return *spirv;
}

uint64_t shaderSourcesHash() {
  uint64_t hash = 0;
  for (const ShaderSource& s : kShaderSources) {
    hash = hashBytes(s.name.data(), s.name.size(), hash);
    hash = hashBytes(s.text.data(), s.text.size(), hash);
  }
  return hash;
}

}  // namespace pt
