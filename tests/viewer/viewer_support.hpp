#pragma once
// Helpers of the viewer tests: temporary folders, running the jelly program, recordings, and
// finding the jelly in a picture (its raspberry red against sky, ground and shadow, none red).
#include <sys/wait.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Core>

#include <jelly/core/types.hpp>
#include <jelly/viewer/camera.hpp>

#include "support/temp_dir.hpp"

namespace jelly::testing {

struct Result {
  int code = -1;
  std::string out, err;
};

inline std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// Runs a shell command with stdout and stderr captured.
inline Result run(const std::string& command, const TempDir& dir) {
  const std::string out = dir.file("run.out"), err = dir.file("run.err");
  const int status = std::system((command + " >'" + out + "' 2>'" + err + "' </dev/null").c_str());
  Result r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = read_text(out);
  r.err = read_text(err);
  return r;
}

// The jelly's colour: red well above green and blue, lit or in shadow.
inline bool is_jelly(const std::uint8_t* p) {
  return p[0] > 60 && p[0] > p[1] + 40 && p[0] > p[2] + 30;
}

// The share of an RGB image in the colours of bear_in_bowl's bears: red (the jelly's), green,
// yellow; the bowl, ground and sky are grey or pale blue.
inline double bear_fraction(const std::vector<std::uint8_t>& rgb) {
  long bear = 0;
  for (size_t i = 0; i + 2 < rgb.size(); i += 3) {
    const std::uint8_t* p = &rgb[i];
    const bool green = p[1] > 60 && p[1] > p[0] + 40 && p[1] > p[2] + 30;
    const bool yellow = p[0] > 120 && p[1] > 90 && p[0] > p[2] + 70 && p[1] > p[2] + 50;
    bear += is_jelly(p) || green || yellow;
  }
  return rgb.empty() ? 0.0 : 3.0 * static_cast<double>(bear) / static_cast<double>(rgb.size());
}

struct Box {
  float x0 = 1e9f, y0 = 1e9f, x1 = -1e9f, y1 = -1e9f;
  void add(float x, float y) {
    x0 = std::min(x0, x);
    y0 = std::min(y0, y);
    x1 = std::max(x1, x);
    y1 = std::max(y1, y);
  }
  bool contains(float x, float y, float margin = 0) const {
    return x >= x0 - margin && x <= x1 + margin && y >= y0 - margin && y <= y1 + margin;
  }
};

// The window-pixel box of the particles' projections.
inline Box projected_box(const viewer::Camera& camera, const VecX& x, int width, int height) {
  Box box;
  for (Eigen::Index i = 0; i + 2 < x.size(); i += 3) {
    const auto p = camera.project(x.segment<3>(i).cast<float>(), width, height);
    if (p) box.add(p->x(), p->y());
  }
  return box;
}

struct JellyPixels {
  long inside = 0;      // jelly-coloured pixels inside the box
  long outside = 0;     // jelly-coloured pixels outside the box grown by a margin
  long box_pixels = 0;  // pixels inside the box
  double fraction() const { return box_pixels > 0 ? double(inside) / double(box_pixels) : 0; }
};

// Counts the jelly's pixels of an RGB image (rows top to bottom) inside and outside `box`.
inline JellyPixels count_jelly(const std::vector<std::uint8_t>& rgb, int width, int height,
                               const Box& box, float margin = 3) {
  JellyPixels c;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const float cx = x + 0.5f, cy = y + 0.5f;
      const bool jelly = is_jelly(rgb.data() + 3 * (static_cast<size_t>(y) * width + x));
      if (box.contains(cx, cy)) {
        ++c.box_pixels;
        if (jelly) ++c.inside;
      } else if (!box.contains(cx, cy, margin) && jelly) {
        ++c.outside;
      }
    }
  return c;
}

}  // namespace jelly::testing
