#pragma once
// The kind-specific part of a body's description (a subclass per body kind: the cube's n, a
// mesh file and spacing, ...): it validates itself, builds the body's particles, springs and
// surface for a material, and writes itself back as JSON. The registry (body_kinds.hpp)
// reads it.
#include <array>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <jelly/core/json_fwd.hpp>
#include <jelly/core/model.hpp>

// A lattice body: particles at the occupied points of a regular grid, joined by the seed's
// springs (structural to the axis neighbours, shear along the face and body diagonals of each
// cell, bending to the axis neighbours at distance 2) wherever both ends are occupied. The
// cube, the box and the voxelized mesh are lattices.
namespace jelly {

// Spring coefficients per type (structural, shear, bending) and how particle masses are set.
struct Material {
  // Indexed by SpringType: structural, shear, bending.
  std::array<SpringCoefficients, kSpringTypeCount> springs{
      SpringCoefficients{1400, 50}, SpringCoefficients{1400, 50}, SpringCoefficients{1400, 50}};
  Real particle_mass = 1;  // kg per particle, used when density is 0
  // kg/m^3 (a sheet: kg/m^2); > 0: each particle gets the mass of the volume (area) it stands
  // for, so that the body weighs density x its volume.
  Real density = 0;

  // Throws InputError naming `prefix`field.
  void validate(const std::string& prefix) const;
};

// A regular grid of points, some occupied: the lattice a cube, box or voxelized body is built on.
struct LatticeGrid {
  std::array<int, 3> n{2, 2, 2};  // points along the grid's x, y, z
  Vec3 spacing{1, 1, 1};          // m between neighbouring points along each axis
  Vec3 origin{0, 0, 0};           // position of point (0, 0, 0)
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // the grid's axes in the world
  // One flag per point, index (i n_y + j) n_z + k; empty = every point occupied.
  std::vector<char> occupied;

  // The number of grid points.
  int points() const { return n[0] * n[1] * n[2]; }
  // The index of point (i, j, k).
  int index(int i, int j, int k) const { return (i * n[1] + j) * n[2] + k; }
  bool is_occupied(int i, int j, int k) const;  // true when point (i, j, k) holds a particle
  Vec3 position(int i, int j, int k) const;     // the world position of point (i, j, k)
};

// Particles in grid-index order, springs grouped by their first particle (the seed cube's order:
// the 13 neighbour directions, then bending along x, y, z), and the boundary faces of the
// cells whose 8 corners are occupied as render surface (two triangles per face).
BodyPart build_lattice(const LatticeGrid& grid, const Material& material, const std::string& kind);

// The particle index of each grid point in a part from build_lattice, -1 where unoccupied.
std::vector<int> lattice_particle_indices(const LatticeGrid& grid);

}  // namespace jelly

namespace jelly {

// The shape of a body of one kind (cube, box, cloth, ...): its parameters, validated, written and
// built into a BodyPart.
class BodyShape {
 public:
  virtual ~BodyShape() = default;
  // The body kind's name in scenes ("cube", "cloth", ...).
  virtual std::string_view kind() const = 0;
  // A copy of the same class.
  virtual std::unique_ptr<BodyShape> clone() const = 0;
  // Throws InputError naming `prefix`field (a scene passes its JSON path, "bodies[0].").
  virtual void validate(const std::string& prefix) const = 0;
  // The body's particles (masses from `material`), springs and render surface. Throws
  // InputError naming `prefix`field for input that only building reveals (an empty mesh,
  // too few or too many particles).
  virtual BodyPart build(const Material& material, const std::string& prefix) const = 0;
  // Upper bound on the particles build() makes, known before building (memory checks).
  virtual long estimated_particles() const = 0;
  // Estimate of the springs build() makes (memory checks): the lattice's 13 per particle unless
  // the kind knows better.
  virtual long estimated_springs() const { return 13 * estimated_particles(); }
  // Writes the kind's own keys into `object`.
  virtual void write(Json& object) const = 0;
};

// Implements clone() for a shape class.
template <typename Derived>
class BodyShapeOf : public BodyShape {
 public:
  // A copy of the same class.
  std::unique_ptr<BodyShape> clone() const override {
    return std::make_unique<Derived>(static_cast<const Derived&>(*this));
  }
};

}  // namespace jelly

// Every body kind a scene can name, from one table: adding a kind is its own files (a
// BodyShape subclass and its builder) and one line there.
namespace jelly {

// One body kind of the registry: its name, description and how its keys are read.
struct BodyKindInfo {
  std::string_view name;         // the kind's name in scenes
  std::string_view description;  // one line, with the kind's keys
  // Reads the kind's keys from `fields` (which names the JSON path), validates them and returns
  // the shape; the keys every body has (name, kind, material, pins, ...) are the caller's.
  std::unique_ptr<BodyShape> (*read)(JsonFields& fields);
};

// Sorted by name.
const std::vector<BodyKindInfo>& body_kinds();
// Throws InputError naming `field` and listing the known kinds for an unknown name.
const BodyKindInfo& find_body_kind(std::string_view name, const std::string& field);

}  // namespace jelly
