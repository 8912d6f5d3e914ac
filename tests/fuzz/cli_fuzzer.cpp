// Fuzz target: the command lines of `jelly export` and `jelly render` (cli/app.cpp's run_jelly),
// argv built from the input: the subcommand, then words each chosen among the recording, the
// commands' options, numbers (often ones that break arithmetic) and free text. Every command line
// ends with one of jelly's exit codes (0 ok, 1, 2 bad input, 3), prints its errors and never
// changes the recording. The process works in a scratch folder of its own (free text never holds
// a '/' or starts with '.', so outputs stay there) holding a small recording made at start; what
// a command line writes there is removed after it.
#include <sys/stat.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "commands.hpp"
#include "fuzz/fuzz_file.hpp"
#include "fuzz/fuzz_input.hpp"
#include "fuzz/fuzz_target.hpp"

namespace jelly::fuzz {
namespace {

const char* const kRecording = "rec.h5";
const char* const kScene = "scene.json";

int run(std::vector<std::string> args) {
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  return cli::run_jelly(static_cast<int>(args.size()), argv.data());
}

// Size and modification time of the recording, to notice a command line that changed it.
std::string recording_stamp() {
  struct stat s {};
  if (stat(kRecording, &s) != 0) return "missing";
  return std::to_string(s.st_size) + "@" + std::to_string(s.st_mtim.tv_sec) + "." +
         std::to_string(s.st_mtim.tv_nsec);
}

// Free text as an argument: no '/' (no path out of the scratch folder), no leading '.'.
std::string word(FuzzInput& in) {
  std::string w = in.text(24);
  for (char& c : w) {
    if (c == '/') c = '_';
  }
  if (!w.empty() && w[0] == '.') w[0] = '_';
  return w;
}

std::string number(FuzzInput& in) {
  if (in.flag()) return std::to_string(static_cast<long long>(in.integer()));
  char text[64];
  std::snprintf(text, sizeof text, "%.17g", in.number());
  return text;
}

}  // namespace
}  // namespace jelly::fuzz

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  using namespace jelly::fuzz;
  if (chdir(scratch_folder().c_str()) != 0) fail("cannot enter " + scratch_folder());
  std::FILE* scene = std::fopen(kScene, "w");
  if (scene == nullptr) fail("cannot write the scene");
  std::fputs(R"({"cube": {"n": 3}, "terrains": [{"kind": "slope"}],
                 "integrator": {"name": "rk4", "dt": 0.001}, "duration": 0.03,
                 "output_interval": 0.01})",
             scene);
  std::fclose(scene);
  if (run({"jelly", "run", kScene, "-o", kRecording, "-q"}) != 0) fail("cannot record the scene");
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace jelly::fuzz;
  static const char* const kOptions[] = {
      "--obj-sequence", "--pc2",     "--overwrite", "-o",          "--output",
      "--width",        "--height",  "--fps",       "--start",     "--end",
      "--camera",       "--samples", "--crf",       "--particles", "--springs",
      "--no-shadows",   "--help",    "--",          "-",           "="};
  static const char* const kNames[] = {"out",          "out.pc2",   "out.obj",    "out.mp4",
                                       "out.gif",      "f%04d.png", "f%d%d.png",  "f%s.png",
                                       "f%99999d.png", "rec.xdmf",  "scene.json", "rec.h5"};
  FuzzInput in(data, size);
  std::vector<std::string> args = {"jelly", in.flag() ? "render" : "export"};
  const std::size_t words = in.pick(12);
  for (std::size_t i = 0; i < words; ++i) {
    switch (in.pick(5)) {
      case 0:
        args.push_back(kRecording);
        break;
      case 1:
        args.push_back(kOptions[in.pick(sizeof kOptions / sizeof kOptions[0])]);
        break;
      case 2:
        args.push_back(number(in));
        break;
      case 3:
        args.push_back(kNames[in.pick(sizeof kNames / sizeof kNames[0])]);
        break;
      default:
        args.push_back(word(in));
        break;
    }
  }
  const std::string before = recording_stamp();
  const int code = run(args);
  if (code < 0 || code > 3) fail("exit code " + std::to_string(code));
  if (recording_stamp() != before) fail("the command line changed the recording");
  // Keep the folder as it was: the recording and the scene.
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(".", error)) {
    const std::string name = entry.path().filename().string();
    if (name != kRecording && name != kScene) std::filesystem::remove_all(entry.path(), error);
  }
  return 0;
}
