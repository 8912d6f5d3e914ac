#include <jelly/bench/run_info.hpp>

#include <ctime>
#include <fstream>
#include <thread>

#include <jelly/core/detail/parallel.hpp>
#include <jelly/version.hpp>

#ifndef JELLY_BENCH_BUILD_TYPE
#define JELLY_BENCH_BUILD_TYPE "unknown"
#endif

namespace jelly::bench {

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0) {
      const auto colon = line.find(':');
      if (colon != std::string::npos) return line.substr(line.find_first_not_of(' ', colon + 1));
    }
  }
  return "unknown";
}

std::string load_average() {
  std::ifstream in("/proc/loadavg");
  std::string one, five, fifteen;
  if (!(in >> one >> five >> fifteen)) return "unknown";
  return one + " " + five + " " + fifteen;
}

std::string utc_now() {
  char date[64];
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return date;
}

Metadata run_metadata(const std::vector<std::string>& arguments) {
  Metadata m;
  m["cpu"] = cpu_model();
  // The cores this process may run on (its CPU affinity: a Slurm task's allocation, taskset),
  // which the default thread count uses; and the machine's.
  m["cores"] = std::to_string(parallel::available_cores());
  m["hardware_cores"] = std::to_string(std::thread::hardware_concurrency());
  m["build_type"] = JELLY_BENCH_BUILD_TYPE;
  m["jelly_version"] = JELLY_VERSION_STRING;
#if defined(__clang__)
  m["compiler"] = std::string("clang ") + __clang_version__;
#elif defined(__GNUC__)
  m["compiler"] = std::string("gcc ") + __VERSION__;
#else
  m["compiler"] = "unknown";
#endif
  std::string command;
  for (const std::string& a : arguments) command += (command.empty() ? "" : " ") + a;
  m["command_line"] = command;
  m["date_utc"] = utc_now();
  m["load_average_start"] = load_average();
  return m;
}

}  // namespace jelly::bench
