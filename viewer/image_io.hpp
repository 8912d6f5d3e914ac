#pragma once
// PNG files of RGB images (rows top to bottom), through stb_image_write and stb_image (Debian's
// libstb).
#include <cstdint>
#include <string>
#include <vector>

namespace jelly::viewer {

struct Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;  // [height][width][3], top row first
};

// Throws std::runtime_error naming the path when it cannot be written.
void write_png(const std::string& path, int width, int height, const std::uint8_t* rgb);
// Throws std::runtime_error naming the path when it cannot be read.
Image read_png(const std::string& path);

}  // namespace jelly::viewer
