// Vulkan helpers; see resources.h.
#include "vulkan/resources.h"

#include <cstring>
#include <string>

#include "common/check.h"

namespace pt {
namespace {

uint32_t findMemoryType(const VulkanContext& ctx, uint32_t typeBits, vk::MemoryPropertyFlags want) {
  const auto props = ctx.physicalDevice.getMemoryProperties();
  for (uint32_t i = 0; i < props.memoryTypeCount; ++i) {
    if ((typeBits & (1u << i)) && (props.memoryTypes[i].propertyFlags & want) == want) return i;
  }
  throw vk::SystemError(vk::make_error_code(vk::Result::eErrorOutOfDeviceMemory),
                        "no memory type with the required properties");
}

}  // namespace

Buffer makeBuffer(const VulkanContext& ctx, vk::DeviceSize size, vk::BufferUsageFlags usage,
                  bool hostVisible) {
  Buffer b;
  b.size = size;
  b.buffer = vk::raii::Buffer(ctx.device, vk::BufferCreateInfo({}, size, usage));
  const vk::MemoryRequirements req = b.buffer.getMemoryRequirements();
  const auto props = hostVisible ? vk::MemoryPropertyFlagBits::eHostVisible |
                                       vk::MemoryPropertyFlagBits::eHostCoherent
                                 : vk::MemoryPropertyFlagBits::eDeviceLocal;
  b.memory = vk::raii::DeviceMemory(
      ctx.device, vk::MemoryAllocateInfo(req.size, findMemoryType(ctx, req.memoryTypeBits, props)));
  b.buffer.bindMemory(*b.memory, 0);
  if (hostVisible) b.mapped = b.memory.mapMemory(0, size);
  return b;
}

void makeTexelView(const VulkanContext& ctx, Buffer& b) {
  PT_CHECK(b.size % 16 == 0, "a texel view needs a whole number of 16-byte texels");
  b.texels = vk::raii::BufferView(
      ctx.device,
      vk::BufferViewCreateInfo({}, *b.buffer, vk::Format::eR32G32B32A32Uint, 0, VK_WHOLE_SIZE));
}

void checkTexelRange(const VulkanContext& ctx, const char* what, vk::DeviceSize size) {
  const vk::DeviceSize texels = size / 16;
  if (texels > ctx.limits.maxTexelBufferElements) {
    throw InputError("scene too large for " + ctx.info().name + ": the " + what + " buffer is " +
                     std::to_string(texels) + " texels, the device's maxTexelBufferElements is " +
                     std::to_string(ctx.limits.maxTexelBufferElements));
  }
}

void checkRange(const VulkanContext& ctx, const char* what, vk::DeviceSize size) {
  if (size > ctx.limits.maxStorageBufferRange) {
    throw InputError("scene too large for " + ctx.info().name + ": the " + what + " buffer is " +
                     std::to_string(size >> 20) + " MiB, the device's maxStorageBufferRange is " +
                     std::to_string(ctx.limits.maxStorageBufferRange >> 20) + " MiB");
  }
}

void checkUploads(const VulkanContext& ctx, std::span<const Upload> uploads) {
  for (const Upload& u : uploads) {
    checkRange(ctx, u.what, u.size);
    if (u.texels) checkTexelRange(ctx, u.what, u.size);
  }
}

std::vector<Buffer> recordUploads(const VulkanContext& ctx, const vk::raii::CommandBuffer& cmd,
                                  std::span<const Upload> uploads, Buffer& staging) {
  using U = vk::BufferUsageFlagBits;
  std::vector<Buffer> buffers;
  vk::DeviceSize stagingSize = 0;
  for (const Upload& u : uploads) {
    const vk::BufferUsageFlags usage = u.texels ? U::eUniformTexelBuffer : U::eStorageBuffer;
    buffers.push_back(makeBuffer(ctx, u.size, usage | U::eTransferDst, false));
    if (u.texels) makeTexelView(ctx, buffers.back());
    stagingSize += u.size;
  }
  staging = makeBuffer(ctx, stagingSize, U::eTransferSrc, true);
  vk::DeviceSize offset = 0;
  for (size_t i = 0; i < uploads.size(); ++i) {
    std::memcpy(static_cast<char*>(staging.mapped) + offset, uploads[i].data, uploads[i].size);
    cmd.copyBuffer(*staging.buffer, *buffers[i].buffer, vk::BufferCopy(offset, 0, uploads[i].size));
    offset += uploads[i].size;
  }
  return buffers;
}

DeviceTimer::DeviceTimer(const VulkanContext& ctx)
    : queries_(ctx.device, vk::QueryPoolCreateInfo({}, vk::QueryType::eTimestamp, 2)),
      tickSeconds_(double(ctx.limits.timestampPeriod) * 1e-9) {}

void DeviceTimer::start(const vk::raii::CommandBuffer& cmd) const {
  cmd.resetQueryPool(*queries_, 0, 2);
  cmd.writeTimestamp(vk::PipelineStageFlagBits::eTopOfPipe, *queries_, 0);
}

void DeviceTimer::stop(const vk::raii::CommandBuffer& cmd) const {
  cmd.writeTimestamp(vk::PipelineStageFlagBits::eBottomOfPipe, *queries_, 1);
}

double DeviceTimer::seconds() const {
  const auto [result, ticks] =
      queries_.getResults<uint64_t>(0, 2, 2 * sizeof(uint64_t), sizeof(uint64_t),
                                    vk::QueryResultFlagBits::e64 | vk::QueryResultFlagBits::eWait);
  PT_CHECK(result == vk::Result::eSuccess);
  return double(ticks[1] - ticks[0]) * tickSeconds_;
}

void barrier(const vk::raii::CommandBuffer& cmd, vk::PipelineStageFlags src,
             vk::AccessFlags srcAccess, vk::PipelineStageFlags dst, vk::AccessFlags dstAccess) {
  const vk::MemoryBarrier mb(srcAccess, dstAccess);
  cmd.pipelineBarrier(src, dst, {}, mb, {}, {});
}

ComputeProgram makeComputeProgram(const VulkanContext& ctx, std::span<const uint32_t> spirv,
                                  const std::vector<Binding>& bindings, uint32_t pushConstantSize,
                                  const vk::SpecializationInfo* specialization) {
  ComputeProgram p;
  const uint32_t n = uint32_t(bindings.size());
  auto type = [&](uint32_t b) {
    return bindings[b].texels ? vk::DescriptorType::eUniformTexelBuffer
                              : vk::DescriptorType::eStorageBuffer;
  };
  std::vector<vk::DescriptorSetLayoutBinding> layoutBindings;
  uint32_t texelCount = 0;
  for (uint32_t b = 0; b < n; ++b) {
    layoutBindings.emplace_back(b, type(b), 1, vk::ShaderStageFlagBits::eCompute);
    texelCount += bindings[b].texels ? 1 : 0;
  }
  p.setLayout = vk::raii::DescriptorSetLayout(
      ctx.device, vk::DescriptorSetLayoutCreateInfo({}, layoutBindings));
  const vk::PushConstantRange push(vk::ShaderStageFlagBits::eCompute, 0, pushConstantSize);
  p.layout =
      vk::raii::PipelineLayout(ctx.device, vk::PipelineLayoutCreateInfo({}, *p.setLayout, push));
  p.module = vk::raii::ShaderModule(
      ctx.device, vk::ShaderModuleCreateInfo({}, spirv.size_bytes(), spirv.data()));
  const vk::PipelineShaderStageCreateInfo stage({}, vk::ShaderStageFlagBits::eCompute, *p.module,
                                                "main", specialization);
  p.pipeline =
      vk::raii::Pipeline(ctx.device, nullptr, vk::ComputePipelineCreateInfo({}, stage, *p.layout));

  std::vector<vk::DescriptorPoolSize> poolSizes;
  if (n > texelCount) poolSizes.emplace_back(vk::DescriptorType::eStorageBuffer, n - texelCount);
  if (texelCount > 0) poolSizes.emplace_back(vk::DescriptorType::eUniformTexelBuffer, texelCount);
  p.pool = vk::raii::DescriptorPool(
      ctx.device, vk::DescriptorPoolCreateInfo(vk::DescriptorPoolCreateFlagBits::eFreeDescriptorSet,
                                               1, poolSizes));
  vk::raii::DescriptorSets sets(ctx.device, vk::DescriptorSetAllocateInfo(*p.pool, *p.setLayout));
  p.set = std::move(sets.front());
  std::vector<vk::DescriptorBufferInfo> infos;
  std::vector<vk::BufferView> views;
  infos.reserve(n);
  views.reserve(n);
  for (const Binding& b : bindings) {
    infos.emplace_back(*b.buffer->buffer, 0, b.buffer->size);
    views.push_back(b.texels ? *b.buffer->texels : vk::BufferView{});
  }
  std::vector<vk::WriteDescriptorSet> writes;
  for (uint32_t b = 0; b < n; ++b) {
    if (bindings[b].texels) {
      PT_CHECK(*bindings[b].buffer->texels, "a texel binding needs makeTexelView");
      writes.emplace_back(*p.set, b, 0, 1, type(b), nullptr, nullptr, &views[b]);
    } else {
      writes.emplace_back(*p.set, b, 0, 1, type(b), nullptr, &infos[b]);
    }
  }
  ctx.device.updateDescriptorSets(writes, {});
  return p;
}

void ComputeProgram::bind(const vk::raii::CommandBuffer& cmd) const {
  cmd.bindPipeline(vk::PipelineBindPoint::eCompute, *pipeline);
  cmd.bindDescriptorSets(vk::PipelineBindPoint::eCompute, *layout, 0, *set, {});
}

Commands::Commands(const VulkanContext& ctx)
    : pool(ctx.device, vk::CommandPoolCreateInfo(vk::CommandPoolCreateFlagBits::eResetCommandBuffer,
                                                 ctx.queueFamily)),
      fence(ctx.device, vk::FenceCreateInfo()) {
  vk::raii::CommandBuffers buffers(
      ctx.device, vk::CommandBufferAllocateInfo(*pool, vk::CommandBufferLevel::ePrimary, 1));
  cmd = std::move(buffers.front());
}

void Commands::begin() const {
  cmd.begin(vk::CommandBufferBeginInfo(vk::CommandBufferUsageFlagBits::eOneTimeSubmit));
}

void Commands::submitAndWait(const VulkanContext& ctx) const {
  cmd.end();
  ctx.queue.submit(vk::SubmitInfo({}, {}, *cmd), *fence);
  const vk::Result r = ctx.device.waitForFences(*fence, VK_TRUE, UINT64_MAX);
  PT_CHECK(r == vk::Result::eSuccess);
  ctx.device.resetFences(*fence);
}

}  // namespace pt
