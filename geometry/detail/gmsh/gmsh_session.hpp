#pragma once
// Gmsh's API is one global state: a session holds it, for one thread at a time, from
// initialize to finalize, with Gmsh's own printing off. Used to mesh geometry given through the
// API (tetrahedralize), never to open a user's file. Internal to the plugin
// libjelly_gmsh (geometry/detail/gmsh/).
#include <mutex>
#include <string>

#include <jelly/geometry/detail/tetmesh.hpp>

namespace jelly::detail {

class GmshSession {
 public:
  GmshSession();
  ~GmshSession();
  GmshSession(const GmshSession&) = delete;
  GmshSession& operator=(const GmshSession&) = delete;

  // The last error Gmsh logged during this session ("" when none, or when it repeats the one
  // logged before the session began).
  std::string last_error() const;
  // The current model's 4-node tetrahedra with their nodes (renumbered in increasing tag order)
  // and its physical groups (by name, or "physical_<dim>_<tag>"). Throws InputError naming
  // `field` = `value` for other 3D elements or an element naming a missing node.
  TetMesh tet_mesh(const std::string& field, const std::string& value) const;

 private:
  std::unique_lock<std::mutex> lock_;
  std::string error_before_;
};

}  // namespace jelly::detail
