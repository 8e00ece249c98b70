// Not a test: set-up for the sanitizer run of the tests (tools/test.sh). The Vulkan loader
// unloads lavapipe's driver (and the LLVM it links) when a test destroys its instance; on some
// CPUs the driver's LLVM keeps a small allocation in a global that is then gone, and
// LeakSanitizer, which runs at exit, reports it as a leak from an unnamed module in every test
// that rendered on lavapipe. Loading the driver once more, never to be unloaded, keeps its
// globals, and so that allocation, reachable; leaks of ours are still reported.
//
// Only where the loader can load a driver: the sanitized run hides it (VK_DRIVER_FILES names
// no file) for all but one test, and loading LLVM's relocations in every other test process
// doubled their start-up time.
#if defined(__SANITIZE_ADDRESS__)
#include <dlfcn.h>
#include <sys/stat.h>

#include <cstdlib>
#include <string>

namespace {

// True when `variable` is set and none of the ':'-separated paths it lists exists: the loader
// then finds no driver.
bool namesNoExistingFile(const char* variable) {
  const char* value = std::getenv(variable);
  if (value == nullptr) return false;
  const std::string paths = value;
  size_t begin = 0;
  while (begin <= paths.size()) {
    size_t end = paths.find(':', begin);
    if (end == std::string::npos) end = paths.size();
    struct stat info;
    if (end > begin && stat(paths.substr(begin, end - begin).c_str(), &info) == 0) return false;
    begin = end + 1;
  }
  return true;
}

const bool kLavapipeKeptLoaded = [] {
  // VK_DRIVER_FILES wins over VK_ICD_FILENAMES where both are set, as in the loader.
  const bool driverHidden = std::getenv("VK_DRIVER_FILES") != nullptr
                                ? namesNoExistingFile("VK_DRIVER_FILES")
                                : namesNoExistingFile("VK_ICD_FILENAMES");
  if (driverHidden) return false;
  // Absent on machines without Mesa's lavapipe: then there is nothing to keep.
  return dlopen("libvulkan_lvp.so", RTLD_NOW | RTLD_NODELETE) != nullptr;
}();

}  // namespace
#endif
