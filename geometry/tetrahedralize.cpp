#include <jelly/geometry/tetrahedralize.hpp>

#include <cmath>

#include <gmsh.h>

#include <jelly/core/errors.hpp>
#include <jelly/geometry/detail/gmsh_session.hpp>
#include <jelly/geometry/mesh_io.hpp>

namespace jelly {

TetMesh tetrahedralize(const TriangleMesh& surface, Real size, const std::string& field,
                       const std::string& name, const std::string& size_field) {
  const std::string value = "\"" + name + "\"";
  require(std::isfinite(size) && size >= 0, size_field, size,
          "a finite element size >= 0 (0 = keep the surface's triangles)");
  require(surface.num_triangles() > 0, field, value, "a surface with at least one triangle");
  const MeshTopology topo = mesh_topology(surface);
  require(topo.manifold(), field, value,
          "a manifold, consistently oriented surface (each edge in two triangles running through "
          "it in opposite directions)");
  require_small_holes(topo, 0, field, name, "Gmsh fills only closed surfaces");

  detail::GmshSession session;
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
  TetMesh mesh = session.tet_mesh(field, value);
  drop_unused_vertices(mesh);
  if (mesh.tets.empty()) fail("Gmsh made no tetrahedron");
  validate_tet_mesh(mesh, field, value);
  return mesh;
}

}  // namespace jelly
