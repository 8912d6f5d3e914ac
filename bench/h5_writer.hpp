#pragma once
// Writes the tables of one jelly-bench command to HDF5 (C API): group /<command> with the run's
// metadata as string attributes, and one subgroup per table holding one dataset per column
// (float64, or variable-length UTF-8 strings) plus a "description" attribute.
#include <string>
#include <vector>

#include <jelly/bench/table.hpp>

namespace jelly::bench {

// Creates or truncates `path`. Throws std::runtime_error when HDF5 fails.
void write_h5(const std::string& path, const std::string& command, const std::vector<Table>& tables,
              const Metadata& metadata);

}  // namespace jelly::bench
