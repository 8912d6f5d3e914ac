#include <jelly/geometry/detail/tetgen_reader.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <jelly/core/errors.hpp>
#include <jelly/geometry/detail/mesh_file.hpp>

namespace jelly::detail {

namespace {

// The non-comment lines of a TetGen file, split into words.
class TetgenLines {
 public:
  TetgenLines(const std::string& path, const std::string& field, const std::string& value)
      : in_(path), path_(path), field_(field), value_(value) {
    std::error_code ec;
    bytes_ = static_cast<long>(std::filesystem::file_size(path, ec));
    if (ec) bytes_ = 0;
  }

  std::istringstream next(const char* what) {
    std::string text;
    while (std::getline(in_, text)) {
      ++line_;
      const std::size_t hash = text.find('#');
      if (hash != std::string::npos) text.resize(hash);
      if (text.find_first_not_of(" \t\r") != std::string::npos) return std::istringstream(text);
    }
    fail(std::string("a ") + what + ", found the end of the file");
  }
  // Fails unless `count` items of at least `min_bytes` bytes each fit in the file.
  void require_fits(long count, int min_bytes, const std::string& items,
                    const std::string& item) const {
    if (count > bytes_ / min_bytes) {
      fail(std::to_string(count) + " " + items + ": at most one " + item + " per " +
           std::to_string(min_bytes) + " bytes of the file (" + std::to_string(bytes_) + " bytes)");
    }
  }
  [[noreturn]] void fail(const std::string& why) const {
    throw InputError(field_, value_,
                     "a TetGen mesh: " + path_ + " line " + std::to_string(line_) + ": " + why);
  }

 private:
  std::ifstream in_;
  std::string path_, field_, value_;
  long bytes_ = 0;
  int line_ = 0;
};

}  // namespace

TetMesh read_tetgen(const std::string& base, const std::string& field, const std::string& value) {
  const std::string node_path = base + ".node", ele_path = base + ".ele";
  require_mesh_file(node_path, field, value);
  require_mesh_file(ele_path, field, value);

  TetMesh mesh;
  std::map<long, std::vector<int>> markers, regions;
  long first_index = 0;
  {
    TetgenLines lines(node_path, field, value);
    long count = 0, attributes = 0;
    int dim = 0, has_marker = 0;
    if (!(lines.next("header") >> count >> dim >> attributes >> has_marker) || count < 0 ||
        dim != 3 || attributes < 0 || (has_marker != 0 && has_marker != 1)) {
      lines.fail("a header '<points> 3 <attributes> <0|1>'");
    }
    // A vertex line holds at least "0 0 0 0\n", an attribute at least " 0".
    lines.require_fits(count, 8, "vertices", "vertex");
    lines.require_fits(attributes, 2, "attributes", "attribute");
    mesh.vertices.reserve(count);
    for (long i = 0; i < count; ++i) {
      std::istringstream line = lines.next("vertex");
      long index;
      Vec3 p;
      if (!(line >> index >> p.x() >> p.y() >> p.z())) lines.fail("'<index> <x> <y> <z>'");
      if (i == 0) first_index = index;
      if ((first_index != 0 && first_index != 1) || index != first_index + i) {
        lines.fail("vertices numbered in order from 0 or 1");
      }
      double skip;
      for (long a = 0; a < attributes; ++a) {
        if (!(line >> skip)) {
          lines.fail("'<index> <x> <y> <z>' and the header's " + std::to_string(attributes) +
                     " attributes");
        }
      }
      long marker = 0;
      if (has_marker == 1 && (line >> marker) && marker != 0) markers[marker].push_back(i);
      mesh.vertices.push_back(p);
    }
  }
  {
    TetgenLines lines(ele_path, field, value);
    long count = 0, attributes = 0;
    int nodes = 0;
    if (!(lines.next("header") >> count >> nodes >> attributes) || count < 0 ||
        (nodes != 4 && nodes != 10) || attributes < 0) {
      lines.fail("a header '<tetrahedra> <4|10> <attributes>'");
    }
    // A tetrahedron line holds at least "0 0 1 2 3\n".
    lines.require_fits(count, 10, "tetrahedra", "tetrahedron");
    lines.require_fits(attributes, 2, "attributes", "attribute");
    mesh.tets.reserve(count);
    for (long i = 0; i < count; ++i) {
      std::istringstream line = lines.next("tetrahedron");
      long index, c[10];
      line >> index;
      for (int k = 0; k < nodes; ++k) line >> c[k];
      if (!line) lines.fail("'<index> <" + std::to_string(nodes) + " vertex indices>'");
      if (nodes == 10) lines.fail("4-node tetrahedra (this file has 10-node ones)");
      Tet tet;
      for (int k = 0; k < 4; ++k) {
        if (c[k] < first_index || c[k] - first_index >= mesh.num_vertices()) {
          lines.fail("vertex index " + std::to_string(c[k]) + " out of range");
        }
        tet[k] = static_cast<int>(c[k] - first_index);
      }
      mesh.tets.push_back(tet);
      double region;
      if (attributes > 0) {
        if (!(line >> region))
          lines.fail("the header's " + std::to_string(attributes) + " attributes");
        if (!(std::abs(region) < 2147483647.0)) {
          lines.fail("a region attribute of magnitude below 2^31 (found " + to_text(region) + ")");
        }
        for (int k = 0; k < 4; ++k) regions[std::lround(region)].push_back(tet[k]);
      }
    }
  }
  const auto add = [&](const std::string& prefix, std::map<long, std::vector<int>>& groups) {
    for (auto& [key, vertices] : groups) {
      std::sort(vertices.begin(), vertices.end());
      vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
      mesh.groups.push_back({prefix + std::to_string(key), std::move(vertices)});
    }
  };
  add("region_", regions);
  add("marker_", markers);
  return mesh;
}

}  // namespace jelly::detail
