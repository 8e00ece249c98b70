// The parameter lists' report of what nothing read (pbrt_params.h); the warning itself is the
// builder's (pbrt_builder.h), which knows --strict.
#include "scene/pbrt/pbrt_params.h"

#include "scene/pbrt/pbrt_builder.h"

namespace pt::pbrt {

void Params::reportUnused() const {
  for (const Param& p : own_) {
    if (!p.used) {
      builder_.warnOnce("unused " + context_ + " " + p.name, p.location,
                        context_ + ": parameter " + singleQuoted(p.declaration()) +
                            " ignored (not used by this renderer)");
    }
  }
}

}  // namespace pt::pbrt
