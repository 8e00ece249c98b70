// Vulkan instance, device choice and queue, through Vulkan-Hpp's RAII handles and its dynamic
// dispatcher (no link-time libvulkan). Only host/vulkan includes it; the rest of the program
// sees vulkan/device_info.h.
#pragma once

#define VULKAN_HPP_NO_SPACESHIP_OPERATOR
#include <vulkan/vulkan_raii.hpp>

#include <atomic>
#include <memory>

#include "vulkan/device_info.h"

namespace pt {

class VulkanContext {
 public:
  explicit VulkanContext(const ContextOptions& options);

  const DeviceInfo& info() const { return info_; }
  uint32_t validationErrors() const { return validationErrors_->load(); }

  // Members in creation order; C++ destroys them in reverse, device before instance.
  vk::raii::Context context;
  vk::raii::Instance instance{nullptr};
  vk::raii::DebugUtilsMessengerEXT messenger{nullptr};
  vk::raii::PhysicalDevice physicalDevice{nullptr};
  vk::raii::Device device{nullptr};
  vk::raii::Queue queue{nullptr};
  uint32_t queueFamily = 0;
  vk::PhysicalDeviceLimits limits;

 private:
  DeviceInfo info_;
  // Heap-allocated so the messenger callback's pointer stays valid if the context moves.
  std::unique_ptr<std::atomic<uint32_t>> validationErrors_ =
      std::make_unique<std::atomic<uint32_t>>(0);
};

}  // namespace pt
