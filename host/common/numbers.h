// Constants in double precision, for the host's double-precision sums and tables (the
// shaders' float kPi is in sampling.h).
#pragma once

#include <numbers>

namespace pt {

inline constexpr double kPiD = std::numbers::pi;

}  // namespace pt
