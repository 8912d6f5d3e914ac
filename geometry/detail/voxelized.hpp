#pragma once
// Body kind "voxelized": a closed triangle mesh (OBJ, STL, PLY) filled with the seed's lattice at
// a given spacing (a particle at every lattice point inside, springs between points both
// inside); its render surface is the mesh itself, each vertex embedded in a lattice cell.
#include <Eigen/Geometry>
#include <memory>
#include <string>
#include <vector>

#include <jelly/geometry/body_shape.hpp>
#include <jelly/geometry/detail/mesh_io.hpp>
#include <jelly/geometry/detail/pose.hpp>
#include <jelly/geometry/triangle_mesh.hpp>

namespace jelly {

// The lattice that fills `mesh` (in its own coordinates, placed by `pose`: scaled, rotated,
// moved) with points `spacing` apart (m, after scaling). The grid's axes are the mesh's axes
// turned by the pose; its points are centred on the scaled mesh's bounding box, as many along
// each axis as fit in it. A point is occupied when the mesh's generalized winding number there
// is >= 1/2 (inside, robust to small holes and self-intersections) or it lies on the mesh
// (within 1e-9 spacings: an axis-aligned box mesh whose sides are multiples of the spacing is
// filled up to its faces). A mesh oriented inwards is treated as turned outwards.
LatticeGrid voxelize(const TriangleMesh& mesh, Real spacing, const Pose& pose = {});

// The points of the bounding box's lattice (an upper bound on the particles of voxelize()).
long voxel_grid_points(const Eigen::AlignedBox3d& bounds, Real spacing, Real scale);

// The mesh as a render surface of a lattice body built from `grid` (whose particles are numbered
// as build_lattice numbers them): vertex v of `mesh` placed by `pose` is a weighted sum of the 8
// particles of a lattice cell whose corners are all occupied. The cell holding the vertex when it
// is fully occupied (trilinear weights, in [0, 1]); otherwise the nearest fully occupied cell
// (breadth-first over the cells from the vertex's cell, then the closest to the vertex among
// those around the one found), with its trilinear weights extrapolated (outside [0, 1], summing
// to 1). Either way the weights reproduce the vertex at rest and any affine (so any rigid)
// motion of the lattice, to rounding. Throws InputError naming `field` when no cell of the grid
// is fully occupied.
Surface embed_in_lattice(const LatticeGrid& grid, const TriangleMesh& mesh, const Pose& pose,
                         const std::string& field);

// A voxelized body from a mesh in memory: voxelize, build_lattice, embed_in_lattice; each vertex
// group becomes a particle group holding the particles its vertices are embedded in (pinning
// them holds the vertices exactly). Throws InputError naming `prefix`spacing when fewer than 8
// points are inside or no cell is fully inside.
BodyPart build_voxelized(const TriangleMesh& mesh, const std::vector<VertexGroup>& groups,
                         Real spacing, const Pose& pose, const Material& material,
                         const std::string& prefix);

// Body kind "voxelized": keys file (OBJ, STL or PLY; relative to the scene file's folder),
// spacing (m), scale, rotation_degrees, position (where the mesh's origin goes). The mesh is
// read and checked when the shape is validated (once per file name; copies share it).
struct VoxelizedShape final : BodyShapeOf<VoxelizedShape> {
  std::string file;  // absolute, or relative to the current directory
  Real spacing = 0;  // m between lattice points, > 0
  Pose pose;

  // Holes at most this many spacings across are filled (the winding number bridges them);
  // larger ones make the mesh invalid.
  static constexpr Real kMaxHoleSpacings = 2;

  std::string_view kind() const override { return "voxelized"; }
  // Also reads the mesh (InputError naming `prefix`file for a missing or bad one).
  void validate(const std::string& prefix) const override;
  BodyPart build(const Material& material, const std::string& prefix) const override;
  // The points of the lattice over the placed mesh's bounding box (reads the mesh if needed).
  long estimated_particles() const override;
  void write(Json& object) const override;
  static std::unique_ptr<BodyShape> read(JsonFields& fields);

  // The mesh as read (validate() or the first call reads it).
  const MeshFile& mesh(const std::string& prefix = "") const;
  // The checks of the mesh the file holds, after the fields' own (validate() runs both).
  void validate_mesh(const std::string& prefix) const;

 private:
  struct Cache;
  mutable std::shared_ptr<const Cache> cache_;
};

}  // namespace jelly
