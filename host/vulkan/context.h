// Vulkan instance, device choice and queue, through Vulkan-Hpp's RAII handles and its dynamic
// dispatcher (no link-time libvulkan). The only place besides backend.cpp that knows Vulkan.
#pragma once

#define VULKAN_HPP_NO_SPACESHIP_OPERATOR
#include <vulkan/vulkan_raii.hpp>

#include <atomic>
#include <stdexcept>
#include <string>
#include <vector>

namespace pt {

// No Vulkan loader, no driver, or no device fit for the renderer: the command line maps this
// to its own exit status (kExitNoDevice).
class NoDeviceError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct DeviceInfo {
  uint32_t index = 0;
  std::string name;
  std::string type;    // "discrete", "integrated", "virtual", "cpu", "other"
  std::string driver;  // driver name and version
  bool suitable = false;
  std::string whyNot;  // when not suitable
};

struct ContextOptions {
  std::string device;        // name substring or index; empty: discrete GPU, else the best
  bool validation = false;   // enable VK_LAYER_KHRONOS_validation, count its errors
  bool debugPrintf = false;  // route debugPrintfEXT through the validation layer to stderr
};

class VulkanContext {
 public:
  explicit VulkanContext(const ContextOptions& options);

  // Every physical device with whether the renderer can use it.
  static std::vector<DeviceInfo> listDevices();

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
