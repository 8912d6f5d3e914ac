#include <jelly/bench/table.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <stdexcept>

namespace jelly::bench {

Table::Table(std::string name, std::string description, const std::vector<std::string>& spec)
    : name_(std::move(name)), description_(std::move(description)) {
  for (const std::string& s : spec) {
    Column c;
    const auto colon = s.find(':');
    c.name = s.substr(0, colon);
    c.is_text = colon != std::string::npos && s.substr(colon + 1) == "s";
    columns_.push_back(std::move(c));
  }
}

int Table::rows() const {
  if (columns_.empty()) return 0;
  const Column& c = columns_.front();
  return static_cast<int>(c.is_text ? c.texts.size() : c.numbers.size());
}

void Table::add_row(const std::vector<Cell>& cells) {
  if (cells.size() != columns_.size()) {
    throw std::invalid_argument("table " + name_ + ": a row of " + std::to_string(cells.size()) +
                                " cells for " + std::to_string(columns_.size()) + " columns");
  }
  for (std::size_t i = 0; i < cells.size(); ++i) {
    Column& c = columns_[i];
    if (c.is_text != std::holds_alternative<std::string>(cells[i])) {
      throw std::invalid_argument("table " + name_ + ": column " + c.name + " takes " +
                                  (c.is_text ? "text" : "numbers"));
    }
  }
  for (std::size_t i = 0; i < cells.size(); ++i) {
    Column& c = columns_[i];
    if (c.is_text) {
      c.texts.push_back(std::get<std::string>(cells[i]));
    } else {
      c.numbers.push_back(std::get<double>(cells[i]));
    }
  }
}

void Table::append(const Table& other) {
  if (other.columns_.size() != columns_.size()) {
    throw std::invalid_argument("table " + name_ + ": cannot append a table of other columns");
  }
  for (std::size_t i = 0; i < columns_.size(); ++i) {
    Column& c = columns_[i];
    const Column& o = other.columns_[i];
    if (c.name != o.name || c.is_text != o.is_text) {
      throw std::invalid_argument("table " + name_ + ": column " + c.name + " differs from " +
                                  o.name);
    }
    c.texts.insert(c.texts.end(), o.texts.begin(), o.texts.end());
    c.numbers.insert(c.numbers.end(), o.numbers.begin(), o.numbers.end());
  }
}

void Table::sort_by(const std::string& column) {
  const int k = index_of(column);
  if (k < 0 || columns_[k].is_text) {
    throw std::invalid_argument("table " + name_ + ": no numeric column " + column);
  }
  std::vector<int> order(rows());
  std::iota(order.begin(), order.end(), 0);
  const std::vector<double>& key = columns_[k].numbers;
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return key[a] < key[b]; });
  for (Column& c : columns_) {
    if (c.is_text) {
      std::vector<std::string> t;
      for (int i : order) t.push_back(c.texts[i]);
      c.texts = std::move(t);
    } else {
      std::vector<double> t;
      for (int i : order) t.push_back(c.numbers[i]);
      c.numbers = std::move(t);
    }
  }
}

int Table::index_of(const std::string& column) const {
  for (std::size_t i = 0; i < columns_.size(); ++i) {
    if (columns_[i].name == column) return static_cast<int>(i);
  }
  return -1;
}

double Table::number(int row, const std::string& column) const {
  const int k = index_of(column);
  if (k < 0 || columns_[k].is_text) {
    throw std::invalid_argument("table " + name_ + ": no numeric column " + column);
  }
  return columns_[k].numbers.at(row);
}

const std::string& Table::text(int row, const std::string& column) const {
  const int k = index_of(column);
  if (k < 0 || !columns_[k].is_text) {
    throw std::invalid_argument("table " + name_ + ": no text column " + column);
  }
  return columns_[k].texts.at(row);
}

namespace {
std::string format_number(double v, int digits) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*g", digits, v);
  return buffer;
}
}  // namespace

std::string Table::cell_text(int row, int column) const {
  const Column& c = columns_.at(column);
  return c.is_text ? c.texts.at(row) : format_number(c.numbers.at(row), 17);
}

void Table::print(std::ostream& out) const {
  out << "== " << name_ << ": " << description_ << "\n";
  std::vector<std::vector<std::string>> cells(columns_.size());
  std::vector<std::size_t> width(columns_.size());
  for (std::size_t i = 0; i < columns_.size(); ++i) {
    const Column& c = columns_[i];
    width[i] = c.name.size();
    for (int r = 0; r < rows(); ++r) {
      cells[i].push_back(c.is_text ? c.texts[r] : format_number(c.numbers[r], 4));
      width[i] = std::max(width[i], cells[i].back().size());
    }
  }
  const auto line = [&](auto&& get) {
    for (std::size_t i = 0; i < columns_.size(); ++i) {
      const std::string s = get(i);
      out << (i ? "  " : "");
      if (columns_[i].is_text) {
        out << s << std::string(width[i] - s.size(), ' ');
      } else {
        out << std::string(width[i] - s.size(), ' ') << s;
      }
    }
    out << "\n";
  };
  line([&](std::size_t i) { return columns_[i].name; });
  for (int r = 0; r < rows(); ++r) line([&](std::size_t i) { return cells[i][r]; });
  out << "\n";
}

}  // namespace jelly::bench
