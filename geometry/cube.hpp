#pragma once
// The seed's jelly cube: an n x n x n particle lattice joined by structural, shear and bending
// springs, each spring stored once.
#include <array>
#include <cstdint>

#include <jelly/core/model.hpp>
#include <jelly/core/state.hpp>
#include <jelly/geometry/body_shape.hpp>

namespace jelly {

// Particles and springs of an n x n x n cube: n^3 and
// 3 n^2 (n - 1) + 6 n (n - 1)^2 + 4 (n - 1)^3 + 3 n^2 (n - 2) (structural, face and body
// diagonals, bending; 12,876 for n = 10).
// Throw InputError naming n for n < 0 or n > 500000 (whose counts would overflow).
std::int64_t cube_particle_count(std::int64_t n);
std::int64_t cube_spring_count(std::int64_t n);  // the springs of a cube of n^3 particles

// Body kind "cube": n particles per edge, edge_length, origin = position of particle (0, 0, 0).
struct CubeShape final : BodyShapeOf<CubeShape> {
  int n = 10;                                   // particles per edge, >= 2
  Real edge_length = 4;                         // m, > 0
  Vec3 origin{-20.0 / 9, 61.0 / 9, -20.0 / 9};  // position of particle (0, 0, 0)

  // "cube".
  std::string_view kind() const override { return "cube"; }
  void validate(const std::string& prefix) const override;
  BodyPart build(const Material& material, const std::string& prefix) const override;
  long estimated_particles() const override { return cube_particle_count(n); }
  long estimated_springs() const override { return cube_spring_count(n); }
  void write(Json& object) const override;
  // Reads the kind's keys from `fields`.
  static std::unique_ptr<BodyShape> read(JsonFields& fields);
};

// The seed scene's one cube with its material and gravity, for building a one-body model in
// code.
struct CubeSpec {
  int n = 10;                                   // particles per edge, >= 2
  Real edge_length = 4;                         // m, > 0
  Vec3 origin{-20.0 / 9, 61.0 / 9, -20.0 / 9};  // position of particle (0, 0, 0)
  Real particle_mass = 1;                       // kg, > 0
  // Indexed by SpringType: structural, shear, bending.
  std::array<SpringCoefficients, kSpringTypeCount> springs{
      SpringCoefficients{1400, 50}, SpringCoefficients{1400, 50}, SpringCoefficients{1400, 50}};
  Vec3 gravity{0, -9.8, 0};  // m/s^2

  CubeShape shape() const;    // the cube's shape (n, edge_length, origin)
  Material material() const;  // springs and particle mass
  // Throws InputError naming the first invalid field (cube.n, springs.shear.kd, gravity).
  void validate() const;
};

// Particle (i, j, k) of the lattice has index (i * n + j) * n + k and sits at
// origin + (i, j, k) * edge_length / (n - 1). Springs: structural to the +x, +y, +z neighbours;
// shear along the 6 face and 4 body diagonals of each unit cell; bending to the axis neighbours
// at distance 2. For n = 10: 2700 + 7776 + 2400 = 12,876 springs. One body, named "jelly".
Model build_cube(const CubeSpec& spec);

// The index of lattice particle (i, j, k) of a cube of n per edge.
inline int cube_index(int n, int i, int j, int k) { return (i * n + j) * n + k; }

}  // namespace jelly
