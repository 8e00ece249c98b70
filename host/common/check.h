// Error tiers of the host (docs/errors.md): InputError for bad user input (one line naming the
// file and the field or line), PT_CHECK / PT_DCHECK for internal invariants (a bug if one fires).
#pragma once

#include <stdexcept>
#include <string>

namespace pt {

// Thrown for anything wrong with what the user gave us. what() is the whole message, already
// prefixed with the file name, e.g. "configs/x.json: materials[2].reflectance: expected 3
// numbers". The command line prints it as one line and exits with kExitInputError.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Exit statuses of the command-line tool.
inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;     // images differ (diff), render had invalid samples
inline constexpr int kExitInputError = 2;  // bad scene, mesh, image or command line
inline constexpr int kExitNoDevice = 3;    // no Vulkan driver or no suitable device
inline constexpr int kExitInternal = 4;    // an invariant failed: a bug
// SIGINT or SIGTERM stopped a render: what was complete is written (images, film state).
inline constexpr int kExitInterrupted = 5;

// Prints "internal error: FILE:LINE: check failed: EXPR: MSG" and exits with kExitInternal.
[[noreturn]] void checkFailed(const char* expr, const char* file, int line, const std::string& msg);

}  // namespace pt

// Invariant check that stays on in release builds: prints the expression and exits with
// kExitInternal (no abort, so no core dump).
#define PT_CHECK(cond, ...)                                                              \
  do {                                                                                   \
    if (!(cond)) ::pt::checkFailed(#cond, __FILE__, __LINE__, std::string{__VA_ARGS__}); \
  } while (0)

// The same check for hot paths (once per sample or per ray): on in debug builds, compiled out
// under NDEBUG (Release). The condition is still type-checked there but never evaluated.
#ifdef NDEBUG
#define PT_DCHECK(cond, ...) \
  do {                       \
    (void)sizeof(!(cond));   \
  } while (0)
#else
#define PT_DCHECK(cond, ...) PT_CHECK(cond, __VA_ARGS__)
#endif
