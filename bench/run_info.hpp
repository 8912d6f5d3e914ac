#pragma once
// What every jelly-bench run records beside its figures: the machine (CPU model, cores), the build
// type, the versions (jelly, compiler), the command line and the date.
#include <string>
#include <vector>

#include <jelly/bench/table.hpp>

namespace jelly::bench {

// Keys: cpu, cores (those the process may run on), hardware_cores, build_type, jelly_version,
// compiler, command_line, date_utc.
Metadata run_metadata(const std::vector<std::string>& arguments);

// The CPU model from /proc/cpuinfo ("unknown" when it cannot be read).
std::string cpu_model();

}  // namespace jelly::bench
