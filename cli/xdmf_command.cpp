#include <cstdio>
#include <filesystem>

#include <jelly/core/errors.hpp>
#include <jelly/io/h5_recorder.hpp>

#include "commands.hpp"
#include "exit_codes.hpp"

namespace jelly::cli {

int xdmf_command(const XdmfArgs& args) {
  const std::string sidecar = xdmf_path_for(args.recording);
  if (sidecar == args.recording) {
    throw InputError("'" + args.recording +
                     "' is named like a sidecar: give the recording (.h5), not its .xdmf");
  }
  if (!std::filesystem::exists(args.recording)) {
    throw InputError("'" + args.recording + "': no such file");
  }
  std::error_code error;
  // Through a symbolic or hard link the sidecar's name can be the recording itself.
  if (std::filesystem::equivalent(sidecar, args.recording, error)) {
    throw InputError("'" + sidecar + "', the sidecar of '" + args.recording +
                     "', is the recording itself (the same file): it would be overwritten");
  }
  if (std::filesystem::exists(sidecar, error) && !args.overwrite) {
    throw InputError("'" + sidecar +
                     "' exists: pass --overwrite to replace it (it is rewritten from the "
                     "recording)");
  }
  const std::string state = paraview_state_path_for(args.recording);
  if (args.state && std::filesystem::exists(state, error) && !args.overwrite) {
    throw InputError("'" + state +
                     "' exists: pass --overwrite to replace it (it is rewritten from "
                     "the recording)");
  }
  XdmfOptions options;
  options.strain = !args.no_strain;
  const std::string written = write_xdmf_for_recording(args.recording, options);
  // With a folder: ParaView's Xdmf3 readers misread a bare file name (docs/output.md).
  const std::string open = written.find('/') == std::string::npos ? "./" + written : written;
  std::printf("wrote %s (open it in ParaView: paraview %s)\n", written.c_str(), open.c_str());
  if (args.state) {
    const std::string written_state = write_paraview_state(args.recording);
    std::printf("wrote %s (open it in ParaView: paraview --state=%s)\n", written_state.c_str(),
                written_state.c_str());
  }
  return kExitOk;
}

}  // namespace jelly::cli
