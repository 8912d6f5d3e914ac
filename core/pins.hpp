#pragma once
// Pinned particles: held at their anchor or moved along a prescribed Path. Every integrator
// honours them exactly: their accelerations are the path's during a step, their positions and
// velocities are set to the path's at its end (Integrator::step), and implicit methods make
// them constraints of their solve.
#include <vector>

#include <jelly/core/path.hpp>
#include <jelly/core/types.hpp>

namespace jelly {

struct Pins {
  std::vector<int> particles;  // global particle indices, each at most once
  std::vector<Vec3> anchors;   // position at t = 0 (where the path's offset is 0)
  std::vector<int> path;       // index into paths, per pin
  std::vector<Path> paths;

  int size() const { return static_cast<int>(particles.size()); }
  bool empty() const { return particles.empty(); }
  // Adds a path and returns its index.
  int add_path(Path p);
  // Pins `particle` at `anchor` (t = 0) moving along paths[path_index]; a particle pinned
  // twice keeps its first pin. Linear in the number of pins (it looks for the particle): many
  // new particles go through add_new.
  void add(int particle, const Vec3& anchor, int path_index);
  void add_fixed(int particle, const Vec3& anchor);
  // The pin of `particle` (its index k), or -1 when it is not pinned.
  int find(int particle) const;
  // Pins `particle` at `anchor` moving along `p`, or gives its pin that anchor and path when it
  // is pinned already (a path no other pin uses is replaced in place: driving a pin every step
  // does not grow `paths`).
  void set(int particle, const Vec3& anchor, Path p);
  // Frees `particle`; false when it was not pinned.
  bool remove(int particle);
  // Pins particles[j] at anchors[j] moving along paths[path_index], in time linear in their
  // number: the caller has checked that none is pinned yet and that each appears once.
  void add_new(const std::vector<int>& particles, const std::vector<Vec3>& anchors, int path_index);
  // The index of a fixed path, added if there is none.
  int fixed_path();
  bool all_fixed() const;

  Vec3 position(int k, Real t) const;
  PathSample sample(int k, Real t) const { return paths[path[k]].sample(t); }
  // Sets the positions and velocities of the pinned particles to their paths' at time t.
  void apply(Real t, VecX& x, VecX& v) const;
  // Replaces the accelerations of the pinned particles by their paths' at time t.
  void apply_acceleration(Real t, VecX& a) const;
  // Offsets every particle index by `shift` (a body appended after others).
  void shift_particles(int shift);
  // Throws InputError for an index out of range or a non-finite anchor.
  void validate(int num_particles) const;
};

}  // namespace jelly
