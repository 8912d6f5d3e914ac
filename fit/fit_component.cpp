#include <jelly/core/components.hpp>

// The fit component (Ceres): spring and damper coefficients fitted to recordings (jelly fit).
namespace jelly {

void register_fit_component() {
  register_component({"fit", "spring and damper coefficients fitted to a recording (Ceres)"});
}

}  // namespace jelly
