// Test-only program (not installed, not part of `pt`): fails an internal check on purpose so
// that check_test.cpp can see the exit status and message a real invariant failure gives.
#include <cstring>

#include "common/check.h"

int main(int argc, char** argv) {
  // "dcheck": a failing PT_DCHECK, which Release (NDEBUG) builds compile out.
  if (argc > 1 && std::strcmp(argv[1], "dcheck") == 0) {
    PT_DCHECK(argc < 0, "debug-only check");
    return 0;
  }
  PT_CHECK(argc < 0, "failed on purpose");
  return 0;
}
