#pragma once
// Where the tables of a jelly-bench command go: printed on stdout, one CSV file per table and one
// HDF5 file per command under the output directory (names carry the shard suffix), and the summary
// tables each command derives from its full results (computed only for unsharded or merged runs).
#include <ostream>
#include <string>
#include <vector>

#include <jelly/bench/shard.hpp>
#include <jelly/bench/table.hpp>

namespace jelly::bench {

// The tables `command` derives from its results: "order" for accuracy, "seed_claims" for seed;
// none for the others.
std::vector<Table> summary_tables(const std::string& command, const std::vector<Table>& results);

// Prints `tables` on `out` and writes <dir>/<table><suffix>.csv and <dir>/<command><suffix>.h5
// (creating dir). The metadata gets "command" and "shard".
void write_outputs(const std::string& command, const std::vector<Table>& tables, Metadata metadata,
                   const std::string& dir, const Shard& shard, std::ostream& out);

}  // namespace jelly::bench
