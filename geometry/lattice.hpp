#pragma once
// A lattice body: particles at the occupied points of a regular grid, joined by the seed's
// springs (structural to the axis neighbours, shear along the face and body diagonals of each
// cell, bending to the axis neighbours at distance 2) wherever both ends are occupied. The
// cube, the box and the voxelized mesh are lattices.
#include <array>
#include <string>
#include <vector>

#include <jelly/core/body.hpp>
#include <jelly/core/springs.hpp>

namespace jelly {

// Spring coefficients per type (structural, shear, bending) and how particle masses are set.
struct Material {
  std::array<SpringCoefficients, kSpringTypeCount> springs{
      SpringCoefficients{1400, 50}, SpringCoefficients{1400, 50}, SpringCoefficients{1400, 50}};
  Real particle_mass = 1;  // kg per particle, used when density is 0
  // kg/m^3 (a sheet: kg/m^2); > 0: each particle gets the mass of the volume (area) it stands
  // for, so that the body weighs density x its volume.
  Real density = 0;

  // Throws InputError naming `prefix`field.
  void validate(const std::string& prefix) const;
};

struct LatticeGrid {
  std::array<int, 3> n{2, 2, 2};  // points along the grid's x, y, z
  Vec3 spacing = Vec3::Ones();    // m between neighbouring points along each axis
  Vec3 origin = Vec3::Zero();     // position of point (0, 0, 0)
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // the grid's axes in the world
  // One flag per point, index (i n_y + j) n_z + k; empty = every point occupied.
  std::vector<char> occupied;

  int points() const { return n[0] * n[1] * n[2]; }
  int index(int i, int j, int k) const { return (i * n[1] + j) * n[2] + k; }
  bool is_occupied(int i, int j, int k) const;
  Vec3 position(int i, int j, int k) const;
};

// Particles in grid-index order, springs grouped by their first particle (the seed cube's order:
// the 13 neighbour directions, then bending along x, y, z), and the boundary faces of the
// cells whose 8 corners are occupied as render surface (two triangles per face).
BodyPart build_lattice(const LatticeGrid& grid, const Material& material, const std::string& kind);

// The particle index of each grid point in a part from build_lattice, -1 where unoccupied.
std::vector<int> lattice_particle_indices(const LatticeGrid& grid);

}  // namespace jelly
