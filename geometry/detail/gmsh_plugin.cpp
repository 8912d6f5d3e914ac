#include <jelly/geometry/detail/gmsh_plugin.hpp>

#include <mutex>
#include <stdexcept>

#include <jelly/version.hpp>

#ifdef JELLY_GMSH_LINKED
extern "C" const jelly::detail::GmshPlugin* jelly_gmsh_plugin();
#elif defined(JELLY_GMSH_PLUGIN)
#include <dlfcn.h>
#endif

namespace jelly::detail {

namespace {

struct Loaded {
  GmshFill fill = nullptr;
  std::string why;  // empty when fill is set
};

std::string check_plugin(const GmshPlugin* plugin, const std::string& file) {
  if (plugin == nullptr || plugin->abi != kGmshPluginAbi || plugin->fill == nullptr ||
      plugin->version == nullptr || std::string(plugin->version) != JELLY_VERSION_STRING) {
    return file + " belongs to another build of jelly (this is " JELLY_VERSION_STRING
                  "); install the one built with this libjelly";
  }
  return "";
}

#if !defined(JELLY_GMSH_LINKED) && defined(JELLY_GMSH_PLUGIN)
// The folder of the loaded libjelly: the plugin is installed (and built) beside it.
std::string own_folder() {
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&gmsh_unavailable_reason), &info) == 0 ||
      info.dli_fname == nullptr) {
    return "";
  }
  const std::string path = info.dli_fname;
  const std::size_t slash = path.rfind('/');
  return slash == std::string::npos ? std::string() : path.substr(0, slash + 1);
}
#endif

Loaded load() {
  Loaded loaded;
#ifdef JELLY_GMSH_LINKED
  loaded.why = check_plugin(jelly_gmsh_plugin(), "the linked Gmsh part");
#elif defined(JELLY_GMSH_PLUGIN)
  const std::string file = own_folder() + kGmshPluginFile;
  // Kept loaded for the process' life: Gmsh's global state is not meant to be unloaded.
  void* handle = dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL | RTLD_NODELETE);
  if (handle == nullptr) {
    const char* error = dlerror();
    loaded.why = "meshing needs Gmsh, through " + file + ", which could not be loaded (" +
                 (error != nullptr ? error : "no reason given") +
                 "); install libgmsh (scripts/install-deps.sh) and jelly's libjelly_gmsh";
    return loaded;
  }
  const auto entry = reinterpret_cast<const GmshPlugin* (*)()>(dlsym(handle, kGmshPluginSymbol));
  if (entry == nullptr) {
    loaded.why = file + " has no symbol " + kGmshPluginSymbol + ": not a jelly Gmsh plugin";
    return loaded;
  }
  loaded.why = check_plugin(entry(), file);
  if (loaded.why.empty()) loaded.fill = entry()->fill;
  return loaded;
#else
  loaded.why =
      "this jelly was built without Gmsh (JELLY_WITH_GMSH=OFF): meshing a surface into "
      "tetrahedra is not available; load a tet mesh file (.msh, .node/.ele) instead";
#endif
#ifdef JELLY_GMSH_LINKED
  if (loaded.why.empty()) loaded.fill = jelly_gmsh_plugin()->fill;
#endif
  return loaded;
}

const Loaded& loaded() {
  static const Loaded once = load();  // thread-safe initialisation
  return once;
}

}  // namespace

GmshFill gmsh_fill() {
  if (loaded().fill == nullptr) throw std::runtime_error(loaded().why);
  return loaded().fill;
}

std::string gmsh_unavailable_reason() { return loaded().why; }

}  // namespace jelly::detail
