#include <jelly/bench/csv_io.hpp>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <jelly/core/errors.hpp>

namespace jelly::bench {

namespace {

std::string quote(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += (c == '"') ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

std::vector<std::string> split_csv(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        cell += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        cell += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      cells.push_back(cell);
      cell.clear();
    } else {
      cell += c;
    }
  }
  cells.push_back(cell);
  return cells;
}

std::string one_line(std::string s) {
  for (char& c : s) {
    if (c == '\n') c = ' ';
  }
  return s;
}

}  // namespace

void write_csv(const std::string& path, const Table& table, const Metadata& metadata) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path);
  for (const auto& [key, value] : metadata) out << "# " << key << ": " << one_line(value) << "\n";
  out << "# table: " << table.name() << "\n";
  out << "# description: " << one_line(table.description()) << "\n";
  out << "# types: ";
  for (std::size_t i = 0; i < table.columns().size(); ++i) {
    out << (i ? "," : "") << (table.columns()[i].is_text ? "s" : "n");
  }
  out << "\n";
  for (std::size_t i = 0; i < table.columns().size(); ++i) {
    out << (i ? "," : "") << quote(table.columns()[i].name);
  }
  out << "\n";
  for (int r = 0; r < table.rows(); ++r) {
    for (std::size_t i = 0; i < table.columns().size(); ++i) {
      out << (i ? "," : "") << quote(table.cell_text(r, static_cast<int>(i)));
    }
    out << "\n";
  }
  if (!out) throw std::runtime_error("error while writing " + path);
}

Table read_csv(const std::string& path, Metadata* metadata) {
  std::ifstream in(path);
  if (!in) throw InputError("cannot read " + path);
  std::string line, name, description;
  std::vector<std::string> types;
  Metadata meta;
  int number = 0;
  const auto fail = [&](const std::string& why) {
    throw InputError(path + ":" + std::to_string(number) + ": " + why);
  };
  std::vector<std::string> header;
  while (std::getline(in, line)) {
    ++number;
    if (line.rfind("# ", 0) == 0) {
      const auto colon = line.find(": ");
      if (colon == std::string::npos) continue;
      const std::string key = line.substr(2, colon - 2), value = line.substr(colon + 2);
      if (key == "table") {
        name = value;
      } else if (key == "description") {
        description = value;
      } else if (key == "types") {
        types = split_csv(value);
      } else {
        meta[key] = value;
      }
      continue;
    }
    header = split_csv(line);
    break;
  }
  if (name.empty() || types.empty()) fail("not a jelly-bench table (no '# table:' or '# types:')");
  if (header.size() != types.size()) fail("the header does not match the types line");
  std::vector<std::string> spec;
  for (std::size_t i = 0; i < header.size(); ++i) {
    spec.push_back(types[i] == "s" ? header[i] + ":s" : header[i]);
  }
  Table table(name, description, spec);
  while (std::getline(in, line)) {
    ++number;
    if (line.empty()) continue;
    const std::vector<std::string> cells = split_csv(line);
    if (cells.size() != types.size()) fail("a row of " + std::to_string(cells.size()) + " cells");
    std::vector<Cell> row;
    for (std::size_t i = 0; i < cells.size(); ++i) {
      if (types[i] == "s") {
        row.emplace_back(cells[i]);
      } else {
        char* end = nullptr;
        const double v = std::strtod(cells[i].c_str(), &end);
        if (end == cells[i].c_str() || *end != '\0') fail("'" + cells[i] + "' is not a number");
        row.emplace_back(v);
      }
    }
    table.add_row(row);
  }
  if (metadata) *metadata = meta;
  return table;
}

}  // namespace jelly::bench
