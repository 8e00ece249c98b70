// Small Vulkan helpers shared by the render and the ray-query pipelines: buffers with their
// memory, the storage-buffer size check, a memory barrier.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "vulkan/context.h"

namespace pt {

struct Buffer {
  vk::raii::Buffer buffer{nullptr};
  vk::raii::DeviceMemory memory{nullptr};
  vk::DeviceSize size = 0;
  void* mapped = nullptr;  // host-visible buffers only
  // The buffer as 16-byte texels (R32G32B32A32_UINT), for a uniform texel buffer binding;
  // only where makeTexelView made one (the buffer needs eUniformTexelBuffer usage).
  vk::raii::BufferView texels{nullptr};
};

// A buffer in device-local memory, or host-visible coherent memory mapped for its lifetime.
Buffer makeBuffer(const VulkanContext& ctx, vk::DeviceSize size, vk::BufferUsageFlags usage,
                  bool hostVisible);

// Makes b.texels, the whole buffer (a whole number of texels) as 16-byte texels.
void makeTexelView(const VulkanContext& ctx, Buffer& b);

// A texel buffer of more 16-byte texels than the device allows is refused with the numbers
// (InputError), like checkRange.
void checkTexelRange(const VulkanContext& ctx, const char* what, vk::DeviceSize size);

// Storage buffers larger than the device allows would be silently cut short (lavapipe's
// maxStorageBufferRange is 128 MiB): refuse them with the numbers instead (InputError).
void checkRange(const VulkanContext& ctx, const char* what, vk::DeviceSize size);

// One array for a device-local buffer, copied there through a staging buffer.
struct Upload {
  const char* what;  // for the size checks' messages: "triangle" (buffer)
  const void* data;
  vk::DeviceSize size;
  bool texels;  // read as texels (a uniform texel buffer, makeTexelView), else a storage buffer
};

// Checks every upload against the device's limits (checkRange, and checkTexelRange for texels)
// before anything is allocated.
void checkUploads(const VulkanContext& ctx, std::span<const Upload> uploads);

// A device-local buffer for each upload (with its texel view where asked), and the copies into
// them recorded into `cmd` from `staging`, filled here and to be kept alive by the caller until
// the commands have run.
std::vector<Buffer> recordUploads(const VulkanContext& ctx, const vk::raii::CommandBuffer& cmd,
                                  std::span<const Upload> uploads, Buffer& staging);

// The device time between two points of a command buffer, from timestamp queries: start and
// stop record them (start resets the pool first), seconds reads them once the commands have
// run.
class DeviceTimer {
 public:
  explicit DeviceTimer(const VulkanContext& ctx);
  void start(const vk::raii::CommandBuffer& cmd) const;
  void stop(const vk::raii::CommandBuffer& cmd) const;
  double seconds() const;

 private:
  vk::raii::QueryPool queries_;
  double tickSeconds_;
};

// Makes writes of one stage visible to the reads/writes of the next.
void barrier(const vk::raii::CommandBuffer& cmd, vk::PipelineStageFlags src,
             vk::AccessFlags srcAccess, vk::PipelineStageFlags dst, vk::AccessFlags dstAccess);

// One binding of set 0: a buffer read as a storage buffer, or through its texel view as a
// uniform texel buffer.
struct Binding {
  const Buffer* buffer;
  bool texels = false;
};

// A compute pipeline whose set 0 binds `bindings` as bindings 0, 1, ..., with a push
// constant block of pushConstantSize bytes. Members in creation order: C++ destroys them in
// reverse, the set before its pool, the pipeline before its layouts.
struct ComputeProgram {
  vk::raii::DescriptorSetLayout setLayout{nullptr};
  vk::raii::PipelineLayout layout{nullptr};
  vk::raii::ShaderModule module{nullptr};
  vk::raii::Pipeline pipeline{nullptr};
  vk::raii::DescriptorPool pool{nullptr};
  vk::raii::DescriptorSet set{nullptr};

  void bind(const vk::raii::CommandBuffer& cmd) const;
};

ComputeProgram makeComputeProgram(const VulkanContext& ctx, std::span<const uint32_t> spirv,
                                  const std::vector<Binding>& bindings, uint32_t pushConstantSize,
                                  const vk::SpecializationInfo* specialization = nullptr);

// One command buffer, recorded and submitted synchronously, again and again.
struct Commands {
  explicit Commands(const VulkanContext& ctx);
  void begin() const;
  void submitAndWait(const VulkanContext& ctx) const;

  vk::raii::CommandPool pool;
  vk::raii::CommandBuffer cmd{nullptr};
  vk::raii::Fence fence;
};

}  // namespace pt
