#include <jelly/core/errors.hpp>

#include "commands.hpp"

// `jelly fit` in a jelly built without the component fit (JELLY_WITH_FIT=OFF).
namespace jelly::cli {

int fit_command(const FitArgs& args) {
  throw InputError("recording", "\"" + args.recording + "\"",
                   "a jelly with the component fit to fit it: this one was built without it "
                   "(JELLY_WITH_FIT=OFF; `jelly list` shows the components)");
}

}  // namespace jelly::cli
