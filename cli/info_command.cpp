#include <cstdio>
#include <filesystem>

#include <jelly/io/h5_recorder.hpp>

#include "commands.hpp"
#include "exit_codes.hpp"
#include "output.hpp"

namespace jelly::cli {

int info_command(const std::string& path) {
  std::string text = describe_file(path);
  if (!text.empty() && text.back() != '\n') text += '\n';
  // The XDMF sidecar beside it (ParaView opens that, not the .h5).
  const std::string sidecar = xdmf_path_for(path);
  std::error_code error;
  text += "sidecar:       " +
          (sidecar != path && std::filesystem::exists(sidecar, error)
               ? sidecar + " (open it in ParaView)"
               : "none (`jelly xdmf " + path + "` writes it, for ParaView)") +
          '\n';
  std::fputs(text.c_str(), stdout);
  return kExitOk;
}

}  // namespace jelly::cli
