#pragma once
// Splitting a sweep across processes or machines: work item k belongs to shard k mod N, and the
// CSV files of the shards merge back into the tables of an unsharded run (rows sorted by item).
#include <map>
#include <string>
#include <vector>

#include <jelly/bench/table.hpp>

namespace jelly::bench {

struct Shard {
  int index = 0;  // in [0, count)
  int count = 1;  // >= 1

  // "i/N"; throws jelly::InputError naming --shard otherwise.
  static Shard parse(const std::string& text);
  bool owns(long item) const { return item % count == index; }
  // "" for an unsharded run, else ".shard-i-of-N" (inserted before the file extension).
  std::string suffix() const;
  std::string text() const { return std::to_string(index) + "/" + std::to_string(count); }
};

struct MergedRun {
  std::string command;
  Metadata metadata;  // the first shard's, with "shard" replaced and "merged_from"
  std::map<std::string, Table> tables;  // by table name, rows sorted by "item"
};

// Reads jelly-bench CSV files, given as files or directories (every *.csv inside, or only the
// *.shard-* ones when there are any), groups them by
// table, checks that each table has every shard of one split exactly once and that all come from
// one command, and concatenates the rows in item order. Throws jelly::InputError otherwise.
MergedRun merge_csv(const std::vector<std::string>& paths);

}  // namespace jelly::bench
