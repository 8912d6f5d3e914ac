#pragma once
// What every jelly-bench run records beside its figures: the machine (CPU model, cores), the build
// type, the versions (jelly, compiler), the command line, the date and the machine's load.
#include <string>
#include <vector>

#include <jelly/bench/table.hpp>

namespace jelly::bench {

// Keys: cpu, cores (those the process may run on), hardware_cores, build_type, jelly_version,
// compiler, command_line, date_utc, load_average_start (write_outputs adds load_average_end and
// date_utc_end: figures measured while other programs ran say so).
Metadata run_metadata(const std::vector<std::string>& arguments);

// The CPU model from /proc/cpuinfo ("unknown" when it cannot be read).
std::string cpu_model();

// The load averages over 1, 5 and 15 minutes as /proc/loadavg gives them ("1.02 0.87 0.55"),
// "unknown" when it cannot be read.
std::string load_average();

// The time now, "YYYY-MM-DDTHH:MM:SSZ".
std::string utc_now();

}  // namespace jelly::bench
