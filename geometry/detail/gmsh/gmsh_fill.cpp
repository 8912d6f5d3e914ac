// The plugin libjelly_gmsh: the part of tetrahedralize that calls Gmsh
// (geometry/detail/gmsh_plugin.hpp says why it is a library of its own).
#include <cmath>

#include <gmsh.h>

#include <jelly/core/errors.hpp>
#include <jelly/geometry/detail/gmsh/gmsh_session.hpp>
#include <jelly/geometry/detail/gmsh_plugin.hpp>
#include <jelly/version.hpp>

namespace jelly::detail {

namespace {

TetMesh gmsh_fill_surface(const TriangleMesh& surface, Real size, const std::string& field,
                          const std::string& value) {
  GmshSession session;
  const auto fail = [&](const std::string& why) {
    throw InputError(field, value, "a surface Gmsh can fill with tetrahedra: " + why);
  };
  try {
    gmsh::model::add("jelly");
    const int entity = gmsh::model::addDiscreteEntity(2);
    std::vector<std::size_t> tags(surface.vertices.size()), nodes;
    std::vector<double> coord;
    coord.reserve(3 * surface.vertices.size());
    for (std::size_t v = 0; v < surface.vertices.size(); ++v) {
      tags[v] = v + 1;
      coord.insert(coord.end(), surface.vertices[v].data(), surface.vertices[v].data() + 3);
    }
    nodes.reserve(3 * surface.triangles.size());
    for (const Triangle& t : surface.triangles) {
      for (int c : t) nodes.push_back(static_cast<std::size_t>(c) + 1);
    }
    gmsh::model::mesh::addNodes(2, entity, tags, coord);
    gmsh::model::mesh::addElementsByType(entity, 2, {}, nodes);  // 3-node triangles
    if (size > 0) {
      // Patches that can each be mapped to a plane, remeshed at the given size.
      gmsh::model::mesh::classifySurfaces(M_PI, true, true, M_PI);
      gmsh::model::mesh::createGeometry();
      gmsh::option::setNumber("Mesh.MeshSizeMax", size);
      gmsh::option::setNumber("Mesh.MeshSizeMin", 0.5 * size);
    } else {
      gmsh::model::mesh::createTopology();
    }
    gmsh::vectorpair surfaces;
    gmsh::model::getEntities(surfaces, 2);
    std::vector<int> surface_tags;
    for (const auto& dim_tag : surfaces) surface_tags.push_back(dim_tag.second);
    const int loop = gmsh::model::geo::addSurfaceLoop(surface_tags);
    const int volume = gmsh::model::geo::addVolume({loop});
    gmsh::model::geo::synchronize();
    gmsh::model::setPhysicalName(2, gmsh::model::addPhysicalGroup(2, surface_tags), "boundary");
    gmsh::model::setPhysicalName(3, gmsh::model::addPhysicalGroup(3, {volume}), "volume");
    gmsh::model::mesh::generate(3);
  } catch (const std::string& e) {
    fail(e);
  } catch (const std::exception& e) {
    fail(e.what());
  }
  if (const std::string e = session.last_error(); !e.empty()) fail(e);
  return session.tet_mesh(field, value);
}

constexpr GmshPlugin kPlugin{kGmshPluginAbi, JELLY_VERSION_STRING, &gmsh_fill_surface};

}  // namespace

}  // namespace jelly::detail

extern "C" __attribute__((visibility("default"))) const jelly::detail::GmshPlugin*
jelly_gmsh_plugin() {
  return &jelly::detail::kPlugin;
}
