// glslang (front end and SPIR-V generator) and SPIRV-Tools' optimizer, run in process on the
// shaders embedded at build time (cmake/embed_sources.cmake).
#include "vulkan/glsl_compiler.h"

#include <glslang/Public/ResourceLimits.h>
#include <glslang/Public/ShaderLang.h>
#include <glslang/SPIRV/GlslangToSpv.h>
#include <glslang/build_info.h>

#include <spirv-tools/libspirv.h>
#include <map>
#include <memory>
#include <mutex>
#include <spirv-tools/optimizer.hpp>
#include <utility>

#include "common/check.h"
#include "image/film_state.h"
#include "shader_sources.h"  // kShaderSources, generated from shaders/
#include "vulkan/spirv_cache.h"

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

// Everything a compiled variant depends on besides its entry and definitions, for the disk
// cache's key: the compilers' versions, the embedded sources and the options above (change
// kCompileOptions with them).
const std::string& compilerIdentity() {
  constexpr const char* kCompileOptions =
      "vulkan1.1 spirv1.3 glsl100 spv-rules vulkan-rules no-spv-opt; "
      "2x(dead-branch-elim aggressive-dce eliminate-dead-functions)";
  static const std::string identity =
      "glslang " + std::to_string(GLSLANG_VERSION_MAJOR) + "." +
      std::to_string(GLSLANG_VERSION_MINOR) + "." + std::to_string(GLSLANG_VERSION_PATCH) +
      GLSLANG_VERSION_FLAVOR + " generator " + std::to_string(glslang::GetSpirvGeneratorVersion()) +
      "; " + spvSoftwareVersionDetailsString() + "; sources " + hexHash(shaderSourcesHash()) +
      "; " + kCompileOptions;
  return identity;
}

// The most variants the disk cache keeps (a few hundred KiB each).
constexpr size_t kMaxCachedVariants = 256;

}  // namespace

const std::vector<uint32_t>& compileShader(std::string_view entry, const std::string& definitions) {
  static std::mutex mutex;
  static std::map<std::pair<std::string, std::string>, std::unique_ptr<std::vector<uint32_t>>>
      compiled;
  const std::lock_guard<std::mutex> lock(mutex);
  std::unique_ptr<std::vector<uint32_t>>& spirv = compiled[{std::string(entry), definitions}];
  if (spirv) return *spirv;
  const std::string name(entry);
  const std::optional<std::filesystem::path> cacheDir = spirvCacheDirectory();
  const std::string key = compilerIdentity() + "\n" + name + "\n" + definitions;
  if (cacheDir) {
    if (std::optional<std::vector<uint32_t>> cached = readCachedSpirv(*cacheDir, key)) {
      spirv = std::make_unique<std::vector<uint32_t>>(std::move(*cached));
      return *spirv;
    }
  }
  static const bool initialized = glslang::InitializeProcess();
  PT_CHECK(initialized, "glslang failed to initialize");
  spirv = std::make_unique<std::vector<uint32_t>>(
      removeDeadCode(glslToSpirv(entry, definitions), name));
  if (cacheDir) {
    writeCachedSpirv(*cacheDir, key, *spirv);
    cleanUpSpirvCache(*cacheDir, kMaxCachedVariants);
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
