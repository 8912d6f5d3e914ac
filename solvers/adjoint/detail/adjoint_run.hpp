#pragma once
// What the adjoints of implicit_euler and projective_dynamics share around their steps: the
// checks of a GradientProblem, the loss terms recorded in the forward run, the per-body
// bookkeeping of the result, and the gradients of the external forces at a step's end.
#include <vector>

#include <jelly/core/types.hpp>
#include <jelly/solvers/adjoint/detail/implicit_euler_adjoint.hpp>

namespace jelly {

struct Model;

// A problem's frames and driven pins, checked against the model (InputError naming the field).
struct AdjointFrames {
  std::vector<int> driven;     // [N] a particle's index in problem.driven_pins, or -1
  std::vector<char> at_frame;  // [steps + 1] whether the loss has a term at that frame
};
AdjointFrames check_gradient_problem(const Model& model, const GradientProblem& problem);

// The loss terms of the forward run: value summed, dL/dx and dL/dv kept per frame.
class AdjointLoss {
 public:
  AdjointLoss(const GradientProblem& problem, const AdjointFrames& frames, int unknowns);
  // The term at `frame` of `state`, when the loss has one there.
  void evaluate(int frame, const State& state);
  Real value() const { return value_; }
  bool at(int frame) const { return frames_.at_frame[frame] != 0; }
  const VecX& dx(int frame) const { return dl_dx_[frame]; }
  const VecX& dv(int frame) const { return dl_dv_[frame]; }

 private:
  const GradientProblem& problem_;
  const AdjointFrames& frames_;
  int unknowns_;
  Real value_ = 0;
  std::vector<VecX> dl_dx_, dl_dv_;
};

// Each spring's and each particle's body, and the result's per-body and per-force vectors sized
// and zeroed.
struct AdjointBodies {
  std::vector<int> spring_body, particle_body;
};
AdjointBodies start_gradient_result(const Model& model, const GradientProblem& problem,
                                    GradientResult& out);

// The external forces' terms of lambda . (scale f(t1, v1)) at the step's end t1: their vectors,
// drags and gusts, and the masses of the particles a constant force spreads over (v1: the
// velocities the wind's drag acts on).
void add_external_force_gradients(const Model& model, Real t1, const VecX& lambda, Real scale,
                                  const VecX& v1, const std::vector<int>& particle_body,
                                  GradientResult& out);

}  // namespace jelly
