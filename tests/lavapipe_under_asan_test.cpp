// Not a test: set-up for the sanitizer run of the tests (tools/test.sh). The Vulkan loader
// unloads lavapipe's driver (and the LLVM it links) when a test destroys its instance; on some
// CPUs the driver's LLVM keeps a small allocation in a global that is then gone, and
// LeakSanitizer, which runs at exit, reports it as a leak from an unnamed module in every test
// that rendered on lavapipe. Loading the driver once more, never to be unloaded, keeps its
// globals, and so that allocation, reachable; leaks of ours are still reported.
#if defined(__SANITIZE_ADDRESS__)
#include <dlfcn.h>

namespace {

const bool kLavapipeKeptLoaded = [] {
  // Absent on machines without Mesa's lavapipe: then there is nothing to keep.
  return dlopen("libvulkan_lvp.so", RTLD_NOW | RTLD_NODELETE) != nullptr;
}();

}  // namespace
#endif
