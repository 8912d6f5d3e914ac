#include <jelly/bench/shard.hpp>

#include <algorithm>
#include <filesystem>
#include <set>
#include <stdexcept>

#include <jelly/bench/csv_io.hpp>
#include <jelly/core/errors.hpp>

namespace jelly::bench {

Shard Shard::parse(const std::string& text) {
  const auto slash = text.find('/');
  Shard s;
  try {
    if (slash == std::string::npos) throw std::invalid_argument("no slash");
    std::size_t used = 0;
    s.index = std::stoi(text.substr(0, slash), &used);
    if (used != slash) throw std::invalid_argument("trailing");
    const std::string count = text.substr(slash + 1);
    s.count = std::stoi(count, &used);
    if (used != count.size()) throw std::invalid_argument("trailing");
  } catch (const std::exception&) {
    throw InputError("--shard", text, "i/N with integers 0 <= i < N, e.g. 0/4");
  }
  require(s.count >= 1 && s.index >= 0 && s.index < s.count, "--shard", text,
          "i/N with integers 0 <= i < N, e.g. 0/4");
  return s;
}

std::string Shard::suffix() const {
  if (count == 1) return "";
  return ".shard-" + std::to_string(index) + "-of-" + std::to_string(count);
}

MergedRun merge_csv(const std::vector<std::string>& paths) {
  namespace fs = std::filesystem;
  std::vector<std::string> files;
  for (const std::string& p : paths) {
    if (fs::is_directory(p)) {
      std::vector<std::string> inside;
      for (const auto& entry : fs::directory_iterator(p)) {
        if (entry.path().extension() == ".csv") inside.push_back(entry.path().string());
      }
      // A directory that holds shards also holds the tables merged from them: take the shards.
      std::vector<std::string> shards;
      for (const std::string& f : inside) {
        if (f.find(".shard-") != std::string::npos) shards.push_back(f);
      }
      if (!shards.empty()) inside = shards;
      std::sort(inside.begin(), inside.end());
      files.insert(files.end(), inside.begin(), inside.end());
    } else if (fs::exists(p)) {
      files.push_back(p);
    } else {
      throw InputError("merge: no file or directory " + p);
    }
  }
  if (files.empty()) throw InputError("merge: no CSV file found");

  struct Part {
    Shard shard;
    Table table;
    std::string file;
  };
  std::map<std::string, std::vector<Part>> parts;
  MergedRun run;
  std::string sources;
  for (const std::string& file : files) {
    Metadata meta;
    Table t = read_csv(file, &meta);
    const std::string command = meta.count("command") ? meta["command"] : "";
    if (run.command.empty()) {
      run.command = command;
      run.metadata = meta;
    } else if (command != run.command) {
      throw InputError("merge: " + file + " comes from '" + command + "', not '" + run.command +
                       "'");
    }
    const Shard shard = Shard::parse(meta.count("shard") ? meta["shard"] : "0/1");
    parts[t.name()].push_back({shard, std::move(t), file});
    sources += (sources.empty() ? "" : " ") + file;
  }
  for (auto& [name, list] : parts) {
    const int count = list.front().shard.count;
    std::set<int> seen;
    for (const Part& p : list) {
      if (p.shard.count != count) {
        throw InputError("merge: table " + name + " mixes splits into " + std::to_string(count) +
                         " and " + std::to_string(p.shard.count) + " shards (" + p.file + ")");
      }
      if (!seen.insert(p.shard.index).second) {
        throw InputError("merge: table " + name + " has shard " + p.shard.text() + " twice (" +
                         p.file + ")");
      }
    }
    if (static_cast<int>(seen.size()) != count) {
      throw InputError("merge: table " + name + " has " + std::to_string(seen.size()) + " of its " +
                       std::to_string(count) + " shards");
    }
    Table merged = list.front().table;
    for (std::size_t i = 1; i < list.size(); ++i) merged.append(list[i].table);
    if (merged.index_of("item") >= 0) merged.sort_by("item");
    run.tables[name] = std::move(merged);
  }
  run.metadata["shard"] = "0/1";
  run.metadata["merged_from"] = sources;
  return run;
}

}  // namespace jelly::bench
