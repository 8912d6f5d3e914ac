#include <jelly/solvers/adjoint/detail/adjoint_run.hpp>

#include <algorithm>
#include <cmath>
#include <string>

#include <jelly/core/errors.hpp>
#include <jelly/core/model.hpp>
#include <jelly/core/state.hpp>

namespace jelly {

AdjointFrames check_gradient_problem(const Model& model, const GradientProblem& problem) {
  const int steps = problem.steps;
  require(steps >= 1, "steps", steps, "an integer >= 1");
  require(problem.checkpoint_every >= 0, "checkpoint_every", problem.checkpoint_every,
          "0 (store every step) or a number of steps >= 1");
  require(static_cast<bool>(problem.loss), "loss", "none", "a function");
  const int np = model.num_particles();
  const int pins = static_cast<int>(problem.driven_pins.size());
  require(problem.pin_targets.size() == static_cast<size_t>(steps) * pins, "pin_targets",
          problem.pin_targets.size(), "steps x driven pins = " + std::to_string(steps * pins));
  AdjointFrames frames;
  frames.driven.assign(np, -1);
  for (int p = 0; p < pins; ++p) {
    const int particle = problem.driven_pins[p];
    require(particle >= 0 && particle < np && model.pins.find(particle) >= 0,
            "driven_pins[" + std::to_string(p) + "]", particle, "a pinned particle");
    require(frames.driven[particle] < 0, "driven_pins[" + std::to_string(p) + "]", particle,
            "each pinned particle once");
    frames.driven[particle] = p;
  }
  frames.at_frame.assign(steps + 1, 0);
  if (problem.loss_frames.empty()) frames.at_frame[steps] = 1;
  for (int f : problem.loss_frames) {
    require(f >= 0 && f <= steps, "loss_frames", f, "frames 0 to " + std::to_string(steps));
    frames.at_frame[f] = 1;
  }
  return frames;
}

AdjointLoss::AdjointLoss(const GradientProblem& problem, const AdjointFrames& frames, int unknowns)
    : problem_(problem),
      frames_(frames),
      unknowns_(unknowns),
      dl_dx_(frames.at_frame.size()),
      dl_dv_(frames.at_frame.size()) {}

void AdjointLoss::evaluate(int frame, const State& state) {
  if (!at(frame)) return;
  dl_dx_[frame].setZero(unknowns_);
  dl_dv_[frame].setZero(unknowns_);
  const Real value = problem_.loss(frame, state, dl_dx_[frame], dl_dv_[frame]);
  require(std::isfinite(value) && dl_dx_[frame].allFinite() && dl_dv_[frame].allFinite(),
          "loss at frame " + std::to_string(frame), value, "finite values and derivatives");
  value_ += value;
}

AdjointBodies start_gradient_result(const Model& model, const GradientProblem& problem,
                                    GradientResult& out) {
  const int bodies = model.num_bodies();
  out.ks.assign(static_cast<size_t>(kSpringTypeCount) * bodies, 0.0);
  out.kd.assign(out.ks.size(), 0.0);
  out.particle_mass.assign(bodies, 0.0);
  out.pin_targets.assign(problem.pin_targets.size(), Vec3::Zero());
  out.force_vector.assign(model.external_forces.size(), Vec3::Zero());
  out.force_drag.assign(model.external_forces.size(), 0.0);
  out.force_gust.assign(model.external_forces.size(), 0.0);
  AdjointBodies map;
  map.spring_body.assign(model.springs.size(), 0);
  map.particle_body.assign(model.num_particles(), 0);
  for (int b = 0; b < bodies; ++b) {
    const Body& body = model.bodies[b];
    std::fill(map.spring_body.begin() + body.first_spring,
              map.spring_body.begin() + body.end_spring(), b);
    std::fill(map.particle_body.begin() + body.first_particle,
              map.particle_body.begin() + body.end_particle(), b);
  }
  return map;
}

void add_external_force_gradients(const Model& model, Real t1, const VecX& lambda, Real scale,
                                  const VecX& v1, const std::vector<int>& particle_body,
                                  GradientResult& out) {
  // A constant force spread by mass (f_i = m_i w / total), wind (f_i = drag (w - v1_i)), point
  // forces (f_i = w), w = vector (1 + gust sin(2 pi f t1)).
  for (size_t e = 0; e < model.external_forces.size(); ++e) {
    const ExternalForce& force = model.external_forces[e];
    if (t1 < force.start || t1 >= force.end) continue;
    const Real wave = std::sin(2 * M_PI * force.gust_frequency * t1);
    const Real factor = 1 + force.gust * wave;
    const Vec3 w = force.vector * factor;
    Vec3 sum = Vec3::Zero();  // d(scale lambda . f)/d(w)
    switch (force.kind) {
      case ExternalForceKind::kConstant: {
        // A body's masses all change together: d(m_i / total) = [i in body] / total - m_i (its
        // particles among the force's) / total^2.
        Real total = 0;
        for (int i : force.particles) total += model.mass[i];
        Real weighted = 0;  // sum_i scale m_i lambda_i . w / total^2
        for (int i : force.particles) {
          const Vec3 l = particle(lambda, i);
          sum += (scale * model.mass[i] / total) * l;
          out.particle_mass[particle_body[i]] += scale * l.dot(w) / total;
          weighted += scale * model.mass[i] * l.dot(w) / (total * total);
        }
        for (int i : force.particles) out.particle_mass[particle_body[i]] -= weighted;
        break;
      }
      case ExternalForceKind::kWind:
        for (int i : force.particles) {
          const Vec3 l = particle(lambda, i);
          sum += (scale * force.drag) * l;
          out.force_drag[e] += scale * l.dot(w - particle(v1, i));
        }
        break;
      case ExternalForceKind::kPoint:
        for (int i : force.particles) sum += scale * particle(lambda, i);
        break;
    }
    out.force_vector[e] += factor * sum;
    out.force_gust[e] += wave * sum.dot(force.vector);
  }
}

}  // namespace jelly
