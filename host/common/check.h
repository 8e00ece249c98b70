// Error tiers of the host: InputError for bad user input (one line naming the file and the
// field or line), PT_CHECK for internal invariants (a bug in this program if it fires).
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

[[noreturn]] void checkFailed(const char* expr, const char* file, int line, const std::string& msg);

}  // namespace pt

// Invariant check that stays on in release builds; fails loudly with the expression.
#define PT_CHECK(cond, ...)                                                              \
  do {                                                                                   \
    if (!(cond)) ::pt::checkFailed(#cond, __FILE__, __LINE__, std::string{__VA_ARGS__}); \
  } while (0)
