// The failure path of PT_CHECK and PT_DCHECK.
#include "common/check.h"

#include <cstdio>
#include <cstdlib>

namespace pt {

void checkFailed(const char* expr, const char* file, int line, const std::string& msg) {
  std::fprintf(stderr, "internal error: %s:%d: check failed: %s%s%s\n", file, line, expr,
               msg.empty() ? "" : ": ", msg.c_str());
  std::fflush(stderr);
  // _Exit, not exit: another thread may still be rendering, and running static destructors
  // under it could crash and hide the message. Outputs are written atomically (tmp + rename),
  // so no partial file is left behind. Under a debugger, break on pt::checkFailed.
  std::_Exit(kExitInternal);
}

}  // namespace pt
