#pragma once
// Internal (not installed). The springs' vertex graph and a colouring of it that every symmetry
// of the graph maps onto itself, for vertex-parallel block descent (the vbd integrator). The
// particles are first split into classes by colour refinement (Weisfeiler-Lehman: particles stay
// in one class while their neighbours' classes agree), which a graph automorphism (a mirror of a
// symmetric body, a swap of two identical bodies) maps onto themselves; the classes are then
// coloured greedily in their canonical order, each class one colour. Two particles of one
// colour share a spring only when they are in one class (mirror images across a plane of
// symmetry, say): the sweep updates a colour from the positions before it (Jacobi within the
// colour), so that its result does not depend on the order, the thread count or the particles'
// numbering, and mirror images of a symmetric input stay mirror images to round-off.
#include <vector>

#include <jelly/core/model.hpp>

namespace jelly {

struct VertexColouring {
  // Per particle i, its springs: spring[e] and the particle at their other end other[e] for
  // e in [spring_start[i], spring_start[i + 1]), in spring order.
  std::vector<int> spring_start;  // [N + 1]
  std::vector<int> spring;        // [2M]
  std::vector<int> other;         // [2M]
  // The particles' classes (canonical numbers: the same for particles an automorphism of the
  // graph exchanges).
  std::vector<int> particle_class;  // [N]
  // The particles of colour c: particles[p] for p in [colour_start[c], colour_start[c + 1]),
  // ascending.
  std::vector<int> colour_start;  // [colours + 1]
  std::vector<int> particles;     // [N]
  // Per colour: 1 when a spring joins two of its particles (then the sweep reads the colour's
  // positions from before it), else 0.
  std::vector<char> coupled;  // [colours]

  int colours() const { return static_cast<int>(colour_start.size()) - 1; }
  // The most particles any colour has.
  int largest_colour() const;
  int classes() const;
};

// The graph of `springs` over `num_particles` particles and its colouring (above): classes by
// at most `refinement_rounds` rounds of colour refinement, stopped early when a round splits no
// class, then greedy colours over the classes. Deterministic. Allocates (once per topology).
VertexColouring colour_vertices(int num_particles, const Springs& springs,
                                int refinement_rounds = 64);

}  // namespace jelly
