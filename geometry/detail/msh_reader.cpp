#include <jelly/geometry/detail/msh_reader.hpp>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <climits>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <string_view>
#include <utility>
#include <vector>

#include <jelly/core/errors.hpp>
#include <jelly/geometry/detail/mesh_file.hpp>

namespace jelly::detail {

namespace {

using NodeTag = long long;
using Key = std::pair<int, int>;  // (dimension, tag)

struct ElementType {
  int type, dim, nodes;
  const char* name;
};

// Gmsh's element types of order 1 and 2 (GmshDefines.h: MSH_LIN_2 = 1, ..., MSH_PYR_13 = 19).
constexpr ElementType kElementTypes[] = {
    {1, 1, 2, "2-node line"},           {2, 2, 3, "3-node triangle"},
    {3, 2, 4, "4-node quadrangle"},     {4, 3, 4, "4-node tetrahedron"},
    {5, 3, 8, "8-node hexahedron"},     {6, 3, 6, "6-node prism"},
    {7, 3, 5, "5-node pyramid"},        {8, 1, 3, "3-node line"},
    {9, 2, 6, "6-node triangle"},       {10, 2, 9, "9-node quadrangle"},
    {11, 3, 10, "10-node tetrahedron"}, {12, 3, 27, "27-node hexahedron"},
    {13, 3, 18, "18-node prism"},       {14, 3, 14, "14-node pyramid"},
    {15, 0, 1, "1-node point"},         {16, 2, 8, "8-node quadrangle"},
    {17, 3, 20, "20-node hexahedron"},  {18, 3, 15, "15-node prism"},
    {19, 3, 13, "13-node pyramid"}};
constexpr int kTetrahedron = 4;

// Sections Gmsh writes that hold data only: skipped to their end marker.
constexpr std::string_view kSkippedSections[] = {
    "Comments", "NodeData",      "ElementData",      "ElementNodeData",
    "Periodic", "GhostElements", "Parametrizations", "InterpolationScheme"};

// A word as a message shows it: at most 40 characters, anything unprintable as '?'.
std::string shown(std::string_view word) {
  std::string s(word.substr(0, 40));
  for (char& c : s) {
    if (!std::isprint(static_cast<unsigned char>(c))) c = '?';
  }
  return word.size() > 40 ? s + "..." : s;
}

// How a number is stored in a binary MSH 4.1 section: an int (4 bytes) or a size_t (8).
enum class Width { kInt, kSize };

// The whitespace-separated words of the file, with the line each starts on; or, in the sections
// of a binary file, its numbers (little-endian, as the file's endianness check requires).
class MshWords {
 public:
  MshWords(const std::string& path, std::string field)
      : field_(std::move(field)), value_(quoted(path)) {
    std::ifstream in(path, std::ios::binary);
    text_.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    if (in.bad()) fail_file("a file that can be read (a read error)");
  }

  // The next word, "" at the end of the file.
  std::string_view next() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) {
      if (text_[pos_++] == '\n') ++line_;
    }
    const std::size_t start = pos_;
    while (pos_ < text_.size() && !std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
    return std::string_view(text_).substr(start, pos_ - start);
  }
  std::string_view word(const std::string& what) {
    const std::string_view w = next();
    if (w.empty()) fail(what + ", found the end of the file");
    return w;
  }
  // Enters (skipping the newline after the section's name) or leaves a binary section.
  void set_binary(bool binary) {
    binary_ = binary;
    if (binary && pos_ < text_.size() && text_[pos_] == '\n') {
      ++pos_;
      ++line_;
    }
  }
  long long integer(const std::string& what, long long lo, long long hi,
                    Width width = Width::kInt) {
    if (binary_) {
      const std::size_t bytes = width == Width::kInt ? 4 : 8;
      if (text_.size() - pos_ < bytes) fail(what + ", found the end of the file");
      std::int32_t i = 0;
      std::uint64_t u = 0;
      if (width == Width::kInt) {
        std::memcpy(&i, text_.data() + pos_, 4);
      } else {
        std::memcpy(&u, text_.data() + pos_, 8);
      }
      pos_ += bytes;
      const bool in_range = width == Width::kInt ? (i >= lo && i <= hi)
                                                 : (u <= static_cast<std::uint64_t>(LLONG_MAX) &&
                                                    static_cast<long long>(u) >= lo &&
                                                    static_cast<long long>(u) <= hi);
      if (!in_range) {
        fail(what + " from " + std::to_string(lo) + " to " + std::to_string(hi) + ", found " +
             (width == Width::kInt ? std::to_string(i) : std::to_string(u)) + " (binary)");
      }
      return width == Width::kInt ? i : static_cast<long long>(u);
    }
    const std::string_view w = word(what);
    long long v = 0;
    const auto [end, error] = std::from_chars(w.data(), w.data() + w.size(), v);
    if (error != std::errc() || end != w.data() + w.size() || v < lo || v > hi) {
      fail(what + " from " + std::to_string(lo) + " to " + std::to_string(hi) + ", found '" +
           shown(w) + "'");
    }
    return v;
  }
  // A number of items in the file: each takes at least two bytes (a digit and a separator), or
  // four in a binary section.
  long long count(const std::string& what) {
    if (binary_) {
      return integer(what + " (at most one per 4 bytes of the file)", 0,
                     static_cast<long long>(text_.size() / 4), Width::kSize);
    }
    return integer(what + " (at most one per 2 bytes of the file)", 0,
                   static_cast<long long>(text_.size() / 2));
  }
  int tag(const std::string& what) { return static_cast<int>(integer(what, INT_MIN, INT_MAX)); }
  NodeTag node_tag() { return integer("a node tag", 1, LLONG_MAX, Width::kSize); }
  double real(const char* what) {
    if (binary_) {
      if (text_.size() - pos_ < 8) fail(std::string(what) + ", found the end of the file");
      double v = 0;
      std::memcpy(&v, text_.data() + pos_, 8);
      pos_ += 8;
      return v;
    }
    const std::string_view w = word(what);
    double v = 0;
    const auto [end, error] = std::from_chars(w.data(), w.data() + w.size(), v);
    if (error != std::errc() || end != w.data() + w.size()) {
      fail(std::string(what) + " (a number), found '" + shown(w) + "'");
    }
    return v;
  }
  void expect(const std::string& marker) {
    const std::string_view w = next();
    if (w != marker) fail("'" + marker + "', found '" + (w.empty() ? "the end" : shown(w)) + "'");
  }
  // The rest of the current line, without surrounding blanks.
  std::string_view rest_of_line() {
    const std::size_t end = std::min(text_.find('\n', pos_), text_.size());
    std::string_view rest = std::string_view(text_).substr(pos_, end - pos_);
    pos_ = end;
    const std::size_t first = rest.find_first_not_of(" \t\r");
    if (first == std::string_view::npos) return {};
    return rest.substr(first, rest.find_last_not_of(" \t\r") + 1 - first);
  }
  int line() const { return line_; }

  [[noreturn]] void fail(const std::string& why) const {
    fail_file("line " + std::to_string(line_) + ": " + why);
  }
  [[noreturn]] void fail_file(const std::string& why) const {
    throw InputError(field_, value_, "a Gmsh mesh (MSH 2.2 or 4.1): " + why);
  }

 private:
  std::string field_, value_, text_;
  std::size_t pos_ = 0;
  int line_ = 1;
  bool binary_ = false;
};

class MshParser {
 public:
  explicit MshParser(MshWords& words) : w_(words) {}

  TetMesh parse() {
    std::set<std::string> seen;
    for (std::string_view word = w_.next(); !word.empty(); word = w_.next()) {
      if (word.front() != '$') {
        w_.fail("a section such as $Nodes, found '" + shown(word) +
                "' (a mesh file is data: Gmsh script such as Merge or SystemCall is not read)");
      }
      const std::string name(word.substr(1));
      if (seen.empty() && name != "MeshFormat") {
        w_.fail("$MeshFormat first, found '" + shown(word) + "'");
      }
      const bool skipped = std::find(std::begin(kSkippedSections), std::end(kSkippedSections),
                                     name) != std::end(kSkippedSections);
      if (!skipped && !seen.insert(name).second) {
        w_.fail("one $" + name + " section (a second $" + name + " starts here)");
      }
      if (name == "MeshFormat") {
        format();
      } else if (name == "PhysicalNames") {
        physical_names();
      } else if (name == "Entities" && v4_) {
        entities();
      } else if (name == "Nodes") {
        nodes();
      } else if (name == "Elements") {
        elements();
      } else if (skipped) {
        skip(name);
      } else {
        w_.fail(
            "a section of a mesh ($PhysicalNames, $Entities in MSH 4.1, $Nodes, $Elements) or "
            "of data that is skipped ($Comments, $NodeData, $ElementData, $ElementNodeData, "
            "$Periodic, $GhostElements, $Parametrizations, $InterpolationScheme), found '" +
            shown(word) + "'");
      }
    }
    return mesh();
  }

 private:
  void format() {
    const std::string version(w_.word("a version"));
    if (version == "4.1") {
      v4_ = true;
    } else if (version != "2.2" && version != "2" && version != "2.0" && version != "2.1") {
      w_.fail("version " + shown(version) +
              ": ASCII MSH 2.2 or 4.1 is what is read (Gmsh writes them with "
              "Mesh.MshFileVersion = 2.2 or 4.1)");
    }
    const std::string file_type(w_.word("a file-type"));
    binary_ = file_type == "1" && v4_;
    if (file_type != "0" && !binary_) {
      w_.fail("file-type " + shown(file_type) + (file_type == "1" ? " (binary MSH 2)" : "") +
              ": ASCII MSH 2.2 or 4.1 (file-type 0) or binary MSH 4.1 is what is read (Gmsh "
              "writes them with Mesh.MshFileVersion = 2.2 or 4.1, binary with Mesh.Binary = 1 "
              "and 4.1 only)");
    }
    if (binary_) {
      w_.integer("a data-size (that of a size_t)", 8, 8);
      w_.set_binary(true);
      w_.integer("the binary one (1 in this machine's byte order: little-endian)", 1, 1);
      w_.set_binary(false);
    } else {
      w_.integer("a data-size", 1, 16);
    }
    w_.expect("$EndMeshFormat");
  }

  void physical_names() {
    const long long n = w_.count("the number of physical names");
    for (long long i = 0; i < n; ++i) {
      const int dim = static_cast<int>(w_.integer("a dimension", 0, 3));
      const int tag = w_.tag("a physical tag");
      const std::string_view name = w_.rest_of_line();
      if (name.size() < 2 || name.front() != '"' || name.back() != '"') {
        w_.fail("a name in double quotes after the dimension and the tag, found '" + shown(name) +
                "'");
      }
      names_[{dim, tag}] = std::string(name.substr(1, name.size() - 2));
    }
    w_.expect("$EndPhysicalNames");
  }

  void entities() {
    w_.set_binary(binary_);
    long long counts[4];
    for (long long& c : counts) c = w_.count("the number of entities of a dimension");
    for (int dim = 0; dim < 4; ++dim) {
      for (long long i = 0; i < counts[dim]; ++i) {
        const int tag = w_.tag("an entity tag");
        for (int k = 0; k < (dim == 0 ? 3 : 6); ++k) w_.real("a coordinate of its box");
        std::vector<int>& physicals = entity_physicals_[{dim, tag}];
        const long long np = w_.count("the number of physical tags");
        for (long long p = 0; p < np; ++p) physicals.push_back(w_.tag("a physical tag"));
        if (dim > 0) {
          const long long nb = w_.count("the number of bounding entities");
          for (long long b = 0; b < nb; ++b) w_.tag("a bounding entity tag");
        }
      }
    }
    w_.set_binary(false);
    w_.expect("$EndEntities");
  }

  // A MSH 4 section's blocks must hold as many items as its header says.
  void require_block_total(const char* what, long long total, long long read) {
    if (read == total) return;
    w_.fail(std::string("as many ") + what + " in the blocks as the section's header says (" +
            std::to_string(total) + "; the blocks have " + std::to_string(read) + ")");
  }

  void add_node(NodeTag tag) {
    Vec3 p;
    for (int k = 0; k < 3; ++k) p[k] = w_.real("a coordinate");
    nodes_.emplace_back(tag, p);
  }

  void nodes() {
    if (!v4_) {
      const long long n = w_.count("the number of nodes");
      for (long long i = 0; i < n; ++i) add_node(w_.node_tag());
    } else {
      w_.set_binary(binary_);
      const long long blocks = w_.count("the number of node blocks");
      const long long total = w_.count("the number of nodes");
      w_.integer("the smallest node tag", 0, LLONG_MAX, Width::kSize);
      w_.integer("the largest node tag", 0, LLONG_MAX, Width::kSize);
      long long read = 0;
      std::vector<NodeTag> tags;
      for (long long b = 0; b < blocks; ++b) {
        const int dim = static_cast<int>(w_.integer("an entity dimension", 0, 3));
        w_.tag("an entity tag");
        const bool parametric = w_.integer("parametric (0 or 1)", 0, 1) == 1;
        const long long n = w_.count("the number of nodes in the block");
        tags.clear();
        for (long long i = 0; i < n; ++i) tags.push_back(w_.node_tag());
        for (NodeTag tag : tags) {
          add_node(tag);
          for (int k = 0; parametric && k < dim; ++k) w_.real("a parametric coordinate");
        }
        read += n;
      }
      require_block_total("nodes", total, read);
      w_.set_binary(false);
    }
    w_.expect("$EndNodes");
  }

  const ElementType& element_type() {
    const long long type = w_.integer("an element type", 1, INT_MAX);
    for (const ElementType& t : kElementTypes) {
      if (t.type == type) {
        if (t.dim == 3 && t.type != kTetrahedron) {
          w_.fail(std::string("a mesh of 4-node tetrahedra (it has 3D elements of type ") + t.name +
                  ")");
        }
        return t;
      }
    }
    w_.fail("element type " + std::to_string(type) +
            " is not one this reader knows (1 to 19: points, lines, triangles, quadrangles, "
            "tetrahedra, hexahedra, prisms and pyramids of order 1 or 2)");
  }

  void add_element(const ElementType& type, const std::vector<int>& physicals) {
    std::array<NodeTag, 27> nodes{};
    for (int k = 0; k < type.nodes; ++k) nodes[k] = w_.node_tag();
    if (type.type == kTetrahedron) tets_.push_back({nodes[0], nodes[1], nodes[2], nodes[3]});
    for (int p : physicals) {
      std::vector<NodeTag>& group = groups_[{type.dim, p}];
      group.insert(group.end(), nodes.begin(), nodes.begin() + type.nodes);
    }
  }

  void elements() {
    std::vector<int> physicals;
    if (!v4_) {
      const long long n = w_.count("the number of elements");
      for (long long i = 0; i < n; ++i) {
        w_.integer("an element tag", 1, LLONG_MAX);
        const ElementType& type = element_type();
        const long long tags = w_.count("the number of tags");
        physicals.clear();
        for (long long t = 0; t < tags; ++t) {
          const int tag = w_.tag("a tag");
          if (t == 0 && tag != 0) physicals.push_back(tag);  // the first tag: physical group
        }
        add_element(type, physicals);
      }
    } else {
      w_.set_binary(binary_);
      const long long blocks = w_.count("the number of element blocks");
      const long long total = w_.count("the number of elements");
      w_.integer("the smallest element tag", 0, LLONG_MAX, Width::kSize);
      w_.integer("the largest element tag", 0, LLONG_MAX, Width::kSize);
      long long read = 0;
      for (long long b = 0; b < blocks; ++b) {
        const int dim = static_cast<int>(w_.integer("an entity dimension", 0, 3));
        const int entity = w_.tag("an entity tag");
        const ElementType& type = element_type();
        const long long n = w_.count("the number of elements in the block");
        const auto it = entity_physicals_.find({dim, entity});
        physicals = it == entity_physicals_.end() ? std::vector<int>() : it->second;
        for (long long i = 0; i < n; ++i) {
          w_.integer("an element tag", 1, LLONG_MAX, Width::kSize);
          add_element(type, physicals);
        }
        read += n;
      }
      require_block_total("elements", total, read);
      w_.set_binary(false);
    }
    w_.expect("$EndElements");
  }

  void skip(const std::string& name) {
    const int start = w_.line();
    const std::string end = "$End" + name;
    for (std::string_view word = w_.next(); word != end; word = w_.next()) {
      if (word.empty()) {
        w_.fail("'" + end + "' to close the section opened on line " + std::to_string(start) +
                ", found the end of the file");
      }
    }
  }

  TetMesh mesh() {
    // Vertices in increasing tag order.
    std::sort(nodes_.begin(), nodes_.end(),
              [](const auto& x, const auto& y) { return x.first < y.first; });
    TetMesh mesh;
    mesh.vertices.reserve(nodes_.size());
    for (std::size_t i = 0; i < nodes_.size(); ++i) {
      if (i > 0 && nodes_[i].first == nodes_[i - 1].first) {
        w_.fail_file("each node tag once (it has node " + std::to_string(nodes_[i].first) +
                     " twice)");
      }
      mesh.vertices.push_back(nodes_[i].second);
    }
    const auto vertex = [&](NodeTag tag) {
      const auto it = std::lower_bound(
          nodes_.begin(), nodes_.end(), tag,
          [](const std::pair<NodeTag, Vec3>& n, NodeTag t) { return n.first < t; });
      if (it == nodes_.end() || it->first != tag) {
        w_.fail_file("an element names node " + std::to_string(tag) +
                     ", which the file does not have");
      }
      return static_cast<int>(it - nodes_.begin());
    };
    mesh.tets.reserve(tets_.size());
    for (const auto& t : tets_)
      mesh.tets.push_back({vertex(t[0]), vertex(t[1]), vertex(t[2]), vertex(t[3])});
    for (const auto& [key, tags] : groups_) {
      VertexGroup g;
      const auto name = names_.find(key);
      g.name = name != names_.end()
                   ? name->second
                   : "physical_" + std::to_string(key.first) + "_" + std::to_string(key.second);
      g.vertices.reserve(tags.size());
      for (NodeTag t : tags) g.vertices.push_back(vertex(t));
      std::sort(g.vertices.begin(), g.vertices.end());
      g.vertices.erase(std::unique(g.vertices.begin(), g.vertices.end()), g.vertices.end());
      mesh.groups.push_back(std::move(g));
    }
    return mesh;
  }

  MshWords& w_;
  bool v4_ = false;
  bool binary_ = false;  // a binary MSH 4.1 file: its sections but $PhysicalNames are binary
  std::map<Key, std::string> names_;
  std::map<Key, std::vector<int>> entity_physicals_;  // (dim, entity) -> physical tags (4.1)
  std::vector<std::pair<NodeTag, Vec3>> nodes_;
  std::vector<std::array<NodeTag, 4>> tets_;
  std::map<Key, std::vector<NodeTag>> groups_;  // (dim, physical) -> the nodes of its elements
};

}  // namespace

TetMesh read_msh(const std::string& path, const std::string& field) {
  MshWords words(path, field);
  return MshParser(words).parse();
}

}  // namespace jelly::detail
