#pragma once
// Vertex block descent (Chen et al., SIGGRAPH 2024): backward Euler's incremental potential
//   G(x) = sum_i m_i / (2 h^2) |x_i - y_i|^2 + E_springs(x),   y = x^t + h v^t + h^2 a_ext,
// minimised by `iterations` sweeps of block coordinate descent: colour by colour of the springs'
// vertex graph (detail/vertex_colouring.hpp: a colouring every symmetry of the graph keeps, so
// that mirror images stay mirror images), each particle takes one Newton step on its own
// 3x3 block (its inertia, springs, dampers and anchor springs; the springs' Hessians made
// definite as implicit_euler's clamp does), with the particles of one colour in parallel;
// optionally Chebyshev-accelerated; v = (x - x^t) / h. Contact with terrains and between bodies
// is the Simulator's after the step (the explicit integrators' split, docs/contact.md); the
// coulomb terrains can also enter each block as penalty energies (VbdOptions::contact_hardness).
#include <vector>

#include <jelly/solvers/integrators/detail/vertex_colouring.hpp>
#include <jelly/solvers/integrators/integrator.hpp>
#include <jelly/solvers/integrators/integrator_options.hpp>

namespace jelly {

class Vbd final : public Integrator {
 public:
  // Throws InputError for invalid options.
  explicit Vbd(VbdOptions options = {});

  std::string_view name() const override { return "vbd"; }
  int order() const override { return 1; }
  // Every sweep decreases the incremental potential of backward Euler: stable at any step.
  bool is_implicit() const override { return true; }
  // steps, sweeps, colours.
  Statistics statistics() const override;

  const VbdOptions& options() const { return options_; }
  // The colouring of the last step's model (empty before the first step).
  const VertexColouring& colouring() const { return graph_; }

 protected:
  StepResult do_step(const Dynamics& dynamics, State& state, Real h) override;

 private:
  // Rebuilds the graph and its colouring when the springs' topology or the particle count
  // changed (allocates); otherwise nothing.
  void prepare(const Model& model);
  // One sweep over every colour on up to `threads` threads.
  void sweep(const Model& model, const AnchorSprings* anchors, Real h, Real t1, VecX& x,
             int threads);
  // One particle's Newton step on its block of G at x: its new position.
  Vec3 update_particle(const Model& model, const AnchorSprings* anchors, Real h, Real t1, int i,
                       const VecX& x) const;

  VbdOptions options_;
  VertexColouring graph_;
  std::vector<int> spring_a_, spring_b_;             // the topology graph_ was built for
  std::vector<char> pinned_;                         // [N]
  std::vector<Real> edge_rest_, edge_ks_, edge_kd_;  // [2M]: per graph entry, its spring's
  std::vector<int> anchor_first_;                 // [N]: first anchor spring of a particle, or -1
  std::vector<int> anchor_next_;                  // [A]: the particle's next anchor spring, or -1
  std::vector<const Terrain*> penalty_terrains_;  // the coulomb terrains of this step
  VecX gap_;  // [N]: each particle's thickness against them (contact/detail/thickness.hpp)
  VecX x0_, y_, previous_, before_previous_, f_;
  VecX next_;  // [3N]: a coupled colour's new positions before they replace x
  long sweeps_ = 0;
};

}  // namespace jelly
