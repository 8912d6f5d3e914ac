#include <jelly/bench/output.hpp>

#include <filesystem>

#include <jelly/bench/accuracy.hpp>
#include <jelly/bench/csv_io.hpp>
#include <jelly/bench/h5_writer.hpp>
#include <jelly/bench/run_info.hpp>
#include <jelly/bench/seed_table.hpp>

namespace jelly::bench {

namespace {
const Table* find(const std::vector<Table>& tables, const std::string& name) {
  for (const Table& t : tables) {
    if (t.name() == name) return &t;
  }
  return nullptr;
}
}  // namespace

std::vector<Table> summary_tables(const std::string& command, const std::vector<Table>& results) {
  if (command == "accuracy") {
    const Table* accuracy = find(results, "accuracy");
    const Table* reference = find(results, "accuracy_reference");
    if (accuracy && reference) return {convergence_orders(*accuracy, *reference)};
  }
  if (command == "seed") {
    if (const Table* seed = find(results, "seed")) return {seed_claims(*seed)};
  }
  return {};
}

void write_outputs(const std::string& command, const std::vector<Table>& tables, Metadata metadata,
                   const std::string& dir, const Shard& shard, std::ostream& out) {
  metadata["command"] = command;
  // A merge keeps the shards' own load figures (read back with their metadata).
  if (!metadata.count("load_average_end")) {
    metadata["load_average_end"] = load_average();
    metadata["date_utc_end"] = utc_now();
  }
  metadata["shard"] = shard.text();
  std::filesystem::create_directories(dir);
  for (const Table& t : tables) {
    t.print(out);
    write_csv(dir + "/" + t.name() + shard.suffix() + ".csv", t, metadata);
  }
  const std::string h5 = dir + "/" + command + shard.suffix() + ".h5";
  write_h5(h5, command, tables, metadata);
  out << "wrote " << tables.size() << " table(s) as CSV and " << h5 << "\n";
}

}  // namespace jelly::bench
