#pragma once
// Internal (not installed). The springs' vertex graph and a greedy colouring of it, for
// vertex-parallel Gauss-Seidel (the vbd integrator): no two particles of one colour share a
// spring, so within a colour each particle's update reads only particles of other colours and
// the particles can be updated in any order, on any number of threads, with the same result.
#include <vector>

#include <jelly/core/model.hpp>

namespace jelly {

struct VertexColouring {
  // Per particle i, its springs: spring_[e] and the particle at their other end other_[e] for
  // e in [spring_start[i], spring_start[i + 1]), in spring order.
  std::vector<int> spring_start;  // [N + 1]
  std::vector<int> spring;        // [2M]
  std::vector<int> other;         // [2M]
  // The particles of colour c: particles[p] for p in [colour_start[c], colour_start[c + 1]),
  // ascending.
  std::vector<int> colour_start;  // [colours + 1]
  std::vector<int> particles;     // [N]

  int colours() const { return static_cast<int>(colour_start.size()) - 1; }
  // The most particles any colour has.
  int largest_colour() const;
};

// The graph of `springs` over `num_particles` particles and its greedy colouring in particle
// order (each particle takes the smallest colour none of its lower-numbered neighbours has): at
// most 1 + the largest degree colours. Deterministic. Allocates (once per topology).
VertexColouring colour_vertices(int num_particles, const Springs& springs);

}  // namespace jelly
