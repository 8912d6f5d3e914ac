#pragma once
// Reads a fuzzer's input bytes as a sequence of choices (libFuzzer's FuzzedDataProvider, reduced
// to what the jelly fuzz targets need and usable without clang). Past the end every read
// returns 0 or empty.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>

namespace jelly::fuzz {

class FuzzInput {
 public:
  FuzzInput(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}

  bool empty() const { return pos_ >= size_; }
  std::size_t remaining() const { return size_ - pos_; }

  std::uint8_t byte() { return pos_ < size_ ? data_[pos_++] : 0; }
  // A value in [0, n) (n > 0), from one or two bytes.
  std::size_t pick(std::size_t n) {
    std::size_t v = byte();
    if (n > 256) v = v << 8 | byte();
    return v % n;
  }
  bool flag() { return byte() & 1; }

  std::int64_t integer() {
    std::uint64_t v = 0;
    for (int i = 0; i < 8; ++i) v = v << 8 | byte();
    std::int64_t out;
    std::memcpy(&out, &v, sizeof out);
    return out;
  }

  // A double, often one of the values that break arithmetic.
  double number() {
    static constexpr double kSpecial[] = {0,
                                          -0.0,
                                          1,
                                          -1,
                                          0.5,
                                          1e-300,
                                          -1e-300,
                                          1e300,
                                          -1e300,
                                          std::numeric_limits<double>::infinity(),
                                          -std::numeric_limits<double>::infinity(),
                                          std::numeric_limits<double>::quiet_NaN(),
                                          std::numeric_limits<double>::denorm_min(),
                                          std::numeric_limits<double>::max(),
                                          2147483648.0,
                                          -2147483649.0};
    const std::uint8_t kind = byte();
    if (kind < 128) return kSpecial[kind % (sizeof kSpecial / sizeof kSpecial[0])];
    std::uint64_t bits = 0;
    for (int i = 0; i < 8; ++i) bits = bits << 8 | byte();
    double out;
    std::memcpy(&out, &bits, sizeof out);
    return out;
  }

  // Up to max_length bytes, ended early by a zero byte.
  std::string text(std::size_t max_length) {
    std::string out;
    while (out.size() < max_length && !empty()) {
      const char c = static_cast<char>(byte());
      if (c == 0) break;
      out += c;
    }
    return out;
  }

  // Everything left.
  std::string rest() {
    std::string out(reinterpret_cast<const char*>(data_ + pos_), remaining());
    pos_ = size_;
    return out;
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

}  // namespace jelly::fuzz
