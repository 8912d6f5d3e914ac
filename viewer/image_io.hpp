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

// Written beside the path and renamed (a failed write leaves an existing file as it was). Throws
// InputError when its folder is missing or not writable, std::runtime_error naming the path when
// the write fails.
void write_png(const std::string& path, int width, int height, const std::uint8_t* rgb);
// Throws std::runtime_error naming the path when it cannot be read.
Image read_png(const std::string& path);

}  // namespace jelly::viewer
