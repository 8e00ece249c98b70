// Vulkan context: instance (optionally with validation), device choice, one compute queue.
#include "vulkan/context.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <cstring>

VULKAN_HPP_DEFAULT_DISPATCH_LOADER_DYNAMIC_STORAGE

namespace pt {
namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string typeName(vk::PhysicalDeviceType t) {
  switch (t) {
    case vk::PhysicalDeviceType::eDiscreteGpu:
      return "discrete";
    case vk::PhysicalDeviceType::eIntegratedGpu:
      return "integrated";
    case vk::PhysicalDeviceType::eVirtualGpu:
      return "virtual";
    case vk::PhysicalDeviceType::eCpu:
      return "cpu";
    default:
      return "other";
  }
}

// Preference when no device is named: discrete GPU, integrated, virtual, then CPU (lavapipe).
int typeRank(vk::PhysicalDeviceType t) {
  switch (t) {
    case vk::PhysicalDeviceType::eDiscreteGpu:
      return 4;
    case vk::PhysicalDeviceType::eIntegratedGpu:
      return 3;
    case vk::PhysicalDeviceType::eVirtualGpu:
      return 2;
    case vk::PhysicalDeviceType::eCpu:
      return 1;
    default:
      return 0;
  }
}

int computeQueueFamily(const vk::raii::PhysicalDevice& pd) {
  const auto families = pd.getQueueFamilyProperties();
  for (size_t i = 0; i < families.size(); ++i) {
    if (families[i].queueFlags & vk::QueueFlagBits::eCompute) return int(i);
  }
  return -1;
}

DeviceInfo describe(const vk::raii::PhysicalDevice& pd, uint32_t index) {
  DeviceInfo info;
  info.index = index;
  const auto props =
      pd.getProperties2<vk::PhysicalDeviceProperties2, vk::PhysicalDeviceDriverProperties>();
  const auto& p = props.get<vk::PhysicalDeviceProperties2>().properties;
  const auto& d = props.get<vk::PhysicalDeviceDriverProperties>();
  info.name = p.deviceName.data();
  info.type = typeName(p.deviceType);
  info.driver = std::string(d.driverName.data()) + " " + d.driverInfo.data();
  // What the shader needs: Vulkan 1.1 (SPIR-V 1.3), a compute queue, 64-bit floats (the
  // watertight test's exact fallback), timestamps on the compute queue.
  if (p.apiVersion < VK_API_VERSION_1_1) {
    info.whyNot = "Vulkan 1.1 required";
  } else if (computeQueueFamily(pd) < 0) {
    info.whyNot = "no compute queue";
  } else if (!pd.getFeatures().shaderFloat64) {
    info.whyNot = "no shaderFloat64";
  } else {
    info.suitable = true;
  }
  return info;
}

VKAPI_ATTR VkBool32 VKAPI_CALL onValidationMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                   VkDebugUtilsMessageTypeFlagsEXT,
                                                   const VkDebugUtilsMessengerCallbackDataEXT* data,
                                                   void* user) {
  const char* message = data->pMessage ? data->pMessage : "";
  // debugPrintfEXT output arrives as an info message; print it as is.
  if (data->pMessageIdName &&
      std::string(data->pMessageIdName).find("DEBUG-PRINTF") != std::string::npos) {
    const char* text = std::strrchr(message, '|');
    std::fprintf(stderr, "%s\n", text ? text + 2 : message);
    return VK_FALSE;
  }
  if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) {
    static_cast<std::atomic<uint32_t>*>(user)->fetch_add(1);
    std::fprintf(stderr, "vulkan validation error: %s\n", message);
  } else if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) {
    std::fprintf(stderr, "vulkan validation warning: %s\n", message);
  }
  return VK_FALSE;
}

vk::raii::Instance makeInstance(const vk::raii::Context& context, const ContextOptions& options) {
  const vk::ApplicationInfo app("pt", 1, "pt", 1, VK_API_VERSION_1_3);
  std::vector<const char*> layers, extensions;
  const bool debug = options.validation || options.debugPrintf;
  if (debug) {
    const auto available = context.enumerateInstanceLayerProperties();
    const bool found = std::any_of(available.begin(), available.end(), [](const auto& l) {
      return std::string(l.layerName.data()) == kValidationLayer;
    });
    if (!found) {
      throw NoDeviceError(std::string(kValidationLayer) +
                          " is not installed (Debian: vulkan-validationlayers)");
    }
    layers.push_back(kValidationLayer);
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  }
  vk::InstanceCreateInfo info({}, &app, layers, extensions);
  const vk::ValidationFeatureEnableEXT printf = vk::ValidationFeatureEnableEXT::eDebugPrintf;
  vk::ValidationFeaturesEXT features(printf, {});
  if (options.debugPrintf) {
    info.pNext = &features;
    // The layer's printf buffer (1 KiB by default) would drop most of a path's lines.
    setenv("VK_KHRONOS_VALIDATION_PRINTF_BUFFER_SIZE", "4194304", /*overwrite=*/0);
  }
  return vk::raii::Instance(context, info);
}

}  // namespace

VulkanContext::VulkanContext(const ContextOptions& options) try {
  instance = makeInstance(context, options);
  if (options.validation || options.debugPrintf) {
    using S = vk::DebugUtilsMessageSeverityFlagBitsEXT;
    using T = vk::DebugUtilsMessageTypeFlagBitsEXT;
    messenger = instance.createDebugUtilsMessengerEXT(vk::DebugUtilsMessengerCreateInfoEXT(
        {}, S::eError | S::eWarning | S::eInfo, T::eGeneral | T::eValidation | T::ePerformance,
        &onValidationMessage, validationErrors_.get()));
  }

  vk::raii::PhysicalDevices devices(instance);
  if (devices.empty()) throw NoDeviceError("no Vulkan device found");
  int chosen = -1;
  if (!options.device.empty()) {
    // By index, or by a case-insensitive part of the name.
    const bool isIndex = std::all_of(options.device.begin(), options.device.end(), [](char c) {
      return std::isdigit(static_cast<unsigned char>(c));
    });
    for (uint32_t i = 0; i < devices.size() && chosen < 0; ++i) {
      const std::string name = devices[i].getProperties().deviceName.data();
      if (isIndex ? std::stoul(options.device) == i
                  : lower(name).find(lower(options.device)) != std::string::npos) {
        chosen = int(i);
      }
    }
    if (chosen < 0) throw NoDeviceError("no Vulkan device matches --device " + options.device);
    const DeviceInfo info = describe(devices[size_t(chosen)], uint32_t(chosen));
    if (!info.suitable) throw NoDeviceError(info.name + " cannot run the renderer: " + info.whyNot);
  } else {
    int bestRank = -1;
    for (uint32_t i = 0; i < devices.size(); ++i) {
      if (!describe(devices[i], i).suitable) continue;
      const int rank = typeRank(devices[i].getProperties().deviceType);
      if (rank > bestRank) bestRank = rank, chosen = int(i);
    }
    if (chosen < 0) throw NoDeviceError("no Vulkan device can run the renderer (see `pt devices`)");
  }
  physicalDevice = std::move(devices[size_t(chosen)]);
  info_ = describe(physicalDevice, uint32_t(chosen));
  limits = physicalDevice.getProperties().limits;

  queueFamily = uint32_t(computeQueueFamily(physicalDevice));
  const float priority = 1.0f;
  const vk::DeviceQueueCreateInfo queueInfo({}, queueFamily, 1, &priority);
  vk::PhysicalDeviceFeatures features;
  features.shaderFloat64 = VK_TRUE;
  std::vector<const char*> extensions;
  const auto available = physicalDevice.enumerateDeviceExtensionProperties();
  const auto addIfAvailable = [&](const char* name) {
    for (const auto& e : available) {
      if (std::string(e.extensionName.data()) == name) extensions.push_back(name);
    }
  };
  // debugPrintfEXT needs non-semantic instructions: core in Vulkan 1.3, else an extension.
  if (options.debugPrintf) addIfAvailable(VK_KHR_SHADER_NON_SEMANTIC_INFO_EXTENSION_NAME);
  vk::DeviceCreateInfo createInfo({}, queueInfo, {}, {}, &features);
  vk::PhysicalDeviceShaderAtomicInt64Features atomics;
  if (options.int64Atomics) {
    // Core in Vulkan 1.2, else an extension; asked for only by the renders that use them.
    const auto supported =
        physicalDevice.getFeatures2<vk::PhysicalDeviceFeatures2,
                                    vk::PhysicalDeviceShaderAtomicInt64Features>();
    if (!supported.get<vk::PhysicalDeviceFeatures2>().features.shaderInt64 ||
        !supported.get<vk::PhysicalDeviceShaderAtomicInt64Features>().shaderBufferInt64Atomics) {
      throw NoDeviceError(info_.name +
                          " has no 64-bit integer buffer atomics (shaderBufferInt64Atomics), "
                          "which the sppm integrator sums its photons with");
    }
    addIfAvailable(VK_KHR_SHADER_ATOMIC_INT64_EXTENSION_NAME);
    features.shaderInt64 = VK_TRUE;
    atomics.shaderBufferInt64Atomics = VK_TRUE;
    createInfo.pNext = &atomics;
  }
  createInfo.setPEnabledExtensionNames(extensions);
  device = vk::raii::Device(physicalDevice, createInfo);
  queue = device.getQueue(queueFamily, 0);
} catch (const vk::IncompatibleDriverError&) {
  throw NoDeviceError("no Vulkan driver found (Debian: mesa-vulkan-drivers for lavapipe)");
} catch (const vk::InitializationFailedError& e) {
  throw NoDeviceError(std::string("Vulkan initialisation failed: ") + e.what());
} catch (const vk::SystemError&) {
  throw;
} catch (const NoDeviceError&) {
  throw;
} catch (const std::runtime_error& e) {
  // vk::raii::Context throws this when libvulkan.so.1 cannot be loaded.
  throw NoDeviceError(std::string("cannot load the Vulkan loader (Debian: libvulkan1): ") +
                      e.what());
}

std::vector<DeviceInfo> listVulkanDevices() {
  try {
    vk::raii::Context context;
    const vk::ApplicationInfo app("pt", 1, "pt", 1, VK_API_VERSION_1_3);
    vk::raii::Instance instance(context, vk::InstanceCreateInfo({}, &app));
    vk::raii::PhysicalDevices devices(instance);
    std::vector<DeviceInfo> result;
    for (uint32_t i = 0; i < devices.size(); ++i) result.push_back(describe(devices[i], i));
    return result;
  } catch (const vk::IncompatibleDriverError&) {
    throw NoDeviceError("no Vulkan driver found (Debian: mesa-vulkan-drivers for lavapipe)");
  }
}

}  // namespace pt
