#include <jelly/geometry/detail/gmsh/gmsh_session.hpp>

#include <algorithm>
#include <unordered_map>

#include <gmsh.h>

#include <jelly/core/errors.hpp>

namespace jelly::detail {

namespace {

constexpr int kGmshTetrahedron = 4;  // MSH element type: 4-node tetrahedron

std::mutex& gmsh_mutex() {
  static std::mutex m;
  return m;
}

}  // namespace

GmshSession::GmshSession() : lock_(gmsh_mutex()) {
  gmsh::initialize(0, nullptr, /*readConfigFiles=*/false);
  gmsh::option::setNumber("General.Terminal", 0);
  gmsh::option::setNumber("General.Verbosity", 1);  // errors only, into the logger
  gmsh::option::setNumber("General.NumThreads", 1);
  gmsh::logger::getLastError(error_before_);
}

GmshSession::~GmshSession() { gmsh::finalize(); }

std::string GmshSession::last_error() const {
  std::string error;
  gmsh::logger::getLastError(error);
  return error == error_before_ ? std::string() : error;
}

TetMesh GmshSession::tet_mesh(const std::string& field, const std::string& value) const {
  const auto fail = [&](const std::string& why) {
    throw InputError(field, value, "a surface Gmsh fills with tetrahedra: " + why);
  };
  std::vector<int> types;
  gmsh::model::mesh::getElementTypes(types, 3);
  for (int type : types) {
    if (type == kGmshTetrahedron) continue;
    std::string name;
    int dim, order, nodes, primary;
    std::vector<double> local;
    gmsh::model::mesh::getElementProperties(type, name, dim, order, nodes, local, primary);
    throw InputError(field, value,
                     "a mesh of 4-node tetrahedra (it has 3D elements of type " + name + ")");
  }

  std::vector<std::size_t> node_tags;
  std::vector<double> coord, parametric;
  gmsh::model::mesh::getNodes(node_tags, coord, parametric, -1, -1, false, false);
  // Node tags are any positive numbers: vertex indices in increasing tag order.
  std::vector<std::size_t> order(node_tags.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](std::size_t x, std::size_t y) { return node_tags[x] < node_tags[y]; });
  TetMesh mesh;
  std::unordered_map<std::size_t, int> index;
  index.reserve(node_tags.size());
  for (std::size_t k : order) {
    if (!index.emplace(node_tags[k], mesh.num_vertices()).second) continue;
    mesh.vertices.emplace_back(coord[3 * k], coord[3 * k + 1], coord[3 * k + 2]);
  }
  const auto vertex = [&](std::size_t tag) {
    const auto it = index.find(tag);
    if (it == index.end()) {
      fail("an element names node " + std::to_string(tag) + ", which the file does not have");
    }
    return it->second;
  };

  std::vector<std::size_t> element_tags, element_nodes;
  gmsh::model::mesh::getElementsByType(kGmshTetrahedron, element_tags, element_nodes);
  mesh.tets.resize(element_tags.size());
  for (std::size_t e = 0; e < element_tags.size(); ++e) {
    for (int c = 0; c < 4; ++c) mesh.tets[e][c] = vertex(element_nodes[4 * e + c]);
  }

  gmsh::vectorpair groups;
  gmsh::model::getPhysicalGroups(groups);
  for (const auto& [dim, tag] : groups) {
    VertexGroup g;
    gmsh::model::getPhysicalName(dim, tag, g.name);
    if (g.name.empty()) g.name = "physical_" + std::to_string(dim) + "_" + std::to_string(tag);
    std::vector<std::size_t> tags;
    std::vector<double> unused;
    gmsh::model::mesh::getNodesForPhysicalGroup(dim, tag, tags, unused);
    for (std::size_t t : tags) g.vertices.push_back(vertex(t));
    std::sort(g.vertices.begin(), g.vertices.end());
    g.vertices.erase(std::unique(g.vertices.begin(), g.vertices.end()), g.vertices.end());
    mesh.groups.push_back(std::move(g));
  }
  return mesh;
}

}  // namespace jelly::detail
