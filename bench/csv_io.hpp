#pragma once
// Tables as CSV files: "# key: value" lines for the metadata, "# table: name", "# description:",
// "# types: n,s,..." (number or text per column), then a header and the rows. Numbers are written
// with 17 significant digits, so a table read back equals the one written.
#include <string>

#include <jelly/bench/table.hpp>

namespace jelly::bench {

void write_csv(const std::string& path, const Table& table, const Metadata& metadata);
// Throws jelly::InputError naming the file and line when it is not a jelly-bench CSV.
Table read_csv(const std::string& path, Metadata* metadata = nullptr);

}  // namespace jelly::bench
