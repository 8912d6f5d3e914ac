#include <jelly/solvers/integrators/integrator.hpp>

#include <cmath>
#include <cstdio>

#include <jelly/core/errors.hpp>
#include <jelly/solvers/contact/detail/body_contact.hpp>
#include <jelly/solvers/contact/detail/contact_solver.hpp>
#include <jelly/solvers/integrators/registry.hpp>

namespace jelly {

std::string tolerance_text(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}

StepResult Integrator::step(const Dynamics& dynamics, State& state, Real h) {
  require(std::isfinite(h) && h > 0, "dt", h, "a finite time step > 0");
  const Eigen::Index n = dynamics.model().num_dofs();
  require(state.x.size() == n && state.v.size() == n, "state.size", state.x.size(),
          "3 x the number of particles (" + std::to_string(n) + ")");
  if (dynamics.has_in_evaluation_contact() && !integrator_supports_in_evaluation_contact(name()))
    throw InputError("terrains.contact.model", "\"seed_framework\"",
                     in_evaluation_contact_requirement(name()));
  StepResult result = do_step(dynamics, state, h);
  if (result.ok) ++steps_;
  return result;
}

std::string in_evaluation_contact_requirement(std::string_view integrator) {
  return "a contact model other than seed_framework with integrator " + std::string(integrator) +
         ": seed_framework acts inside every force evaluation, which only the explicit "
         "integrators (explicit_euler, midpoint, rk4, symplectic_euler) support; use \"seed\" "
         "(the same rules once per step)";
}

void Integrator::restore_internal_state(const std::vector<Real>& /*data*/) {}

Statistics Integrator::statistics() const { return {{"steps", static_cast<double>(steps_)}}; }

std::string Integrator::without_force_jacobian() const {
  return std::string(name()) +
         (is_adaptive() ? "'s Newton matrix leaves it out (more Newton iterations or smaller steps)"
                        : " treats it explicitly within each step");
}

void finish_step(const StepResult& result, ContactSolver& contacts, BodyContact* bodies,
                 const Model& model, const Terrains& terrains, const State& before, State& state,
                 Real h, int threads) {
  // Bodies first, then the terrains: a terrain has the last word on where a particle may be.
  if (bodies != nullptr && !result.contact.bodies) bodies->resolve(model, before, state, h);
  if (result.contact.terrains) {
    contacts.resolve(model, terrains, before, state, h, ContactSolver::Scope::kUnsolvedOnly,
                     threads);
    contacts.add_resolved(result.contact.particles);
  } else {
    contacts.resolve(model, terrains, before, state, h, ContactSolver::Scope::kAll, threads);
  }
  if (!model.pins.empty()) model.pins.apply(state.t, state.x, state.v);
}

void ensure_size(VecX& v, Eigen::Index n) {
  if (v.size() != n) v.setZero(n);
}

}  // namespace jelly
