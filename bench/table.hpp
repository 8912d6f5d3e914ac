#pragma once
// A result table of jelly-bench: named columns of numbers or text, filled row by row, printed on
// stdout and written as CSV and HDF5. Rows of a sweep carry the work item that produced them
// (column "item"), so that shards can be merged back into the order of an unsharded run.
#include <map>
#include <ostream>
#include <string>
#include <variant>
#include <vector>

namespace jelly::bench {

using Cell = std::variant<double, std::string>;

struct Column {
  std::string name;
  bool is_text = false;
  std::vector<double> numbers;     // when !is_text
  std::vector<std::string> texts;  // when is_text
};

class Table {
 public:
  Table() = default;
  // `spec` lists the columns as "name" (number) or "name:s" (text).
  Table(std::string name, std::string description, const std::vector<std::string>& spec);

  const std::string& name() const { return name_; }
  const std::string& description() const { return description_; }
  const std::vector<Column>& columns() const { return columns_; }
  int rows() const;
  // Throws std::invalid_argument when the cells do not match the columns.
  void add_row(const std::vector<Cell>& cells);
  // Appends the rows of `other`, which must have the same columns.
  void append(const Table& other);
  // Stable sort of the rows by the numeric column `column`.
  void sort_by(const std::string& column);

  int index_of(const std::string& column) const;  // -1 when absent
  double number(int row, const std::string& column) const;
  const std::string& text(int row, const std::string& column) const;
  // The cell as text: numbers with up to 17 significant digits (round-trips).
  std::string cell_text(int row, int column) const;

  // A readable, aligned table (numbers with 4 significant digits).
  void print(std::ostream& out) const;

 private:
  std::string name_, description_;
  std::vector<Column> columns_;
};

// Metadata recorded with every table: machine, build, versions, command line.
using Metadata = std::map<std::string, std::string>;

}  // namespace jelly::bench
