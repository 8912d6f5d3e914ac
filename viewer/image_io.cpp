#include <jelly/viewer/image_io.hpp>

#include <cstring>
#include <stdexcept>

#include <jelly/core/detail/file_replacement.hpp>

#include <stb/stb_image.h>
#include <stb/stb_image_write.h>

namespace jelly::viewer {

void write_png(const std::string& path, int width, int height, const std::uint8_t* rgb) {
  stbi_write_png_compression_level = 4;  // faster than the default 8, for slightly larger files
  // Encoded in memory (stbi_write_png ignores failed writes of its file), then written beside the
  // path and renamed: a failed write leaves an existing image as it was.
  std::string png;
  const auto append = [](void* context, void* data, int size) {
    static_cast<std::string*>(context)->append(static_cast<const char*>(data),
                                               static_cast<size_t>(size));
  };
  if (!stbi_write_png_to_func(append, &png, width, height, 3, rgb, 3 * width))
    throw std::runtime_error("cannot encode the PNG file '" + path + "'");
  jelly::detail::replace_file(path, png);
}

Image read_png(const std::string& path) {
  int w = 0, h = 0, channels = 0;
  unsigned char* data = stbi_load(path.c_str(), &w, &h, &channels, 3);
  if (data == nullptr)
    throw std::runtime_error("cannot read the image '" + path + "': " + stbi_failure_reason());
  Image image;
  image.width = w;
  image.height = h;
  image.rgb.assign(data, data + static_cast<size_t>(w) * h * 3);
  stbi_image_free(data);
  return image;
}

}  // namespace jelly::viewer
