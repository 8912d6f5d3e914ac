// jelly._gradient: the discrete adjoints of implicit_euler and projective_dynamics
// (solvers/adjoint/) for jelly.gradient, which maps its arrays to scene paths
// (python/jelly/__init__.py).
#include <jelly/core/model.hpp>
#include <jelly/solvers/adjoint/detail/projective_dynamics_adjoint.hpp>
#include <jelly/solvers/simulator.hpp>

#include "common.hpp"

namespace jelly::python {

namespace {

// An (n, 3) float64 array copied from a flat vector.
py::array_t<double> copy_n3(const VecX& v) {
  py::array_t<double> out({static_cast<py::ssize_t>(v.size() / 3), py::ssize_t{3}});
  std::copy(v.data(), v.data() + v.size(), out.mutable_data());
  return out;
}

}  // namespace

void bind_adjoint(py::module_& m) {
  m.def(
      "_gradient",
      [](Simulator& sim, int steps, py::function loss, std::vector<int> frames,
         std::vector<int> pins, DoubleArray targets, int checkpoint_every) {
        GradientProblem problem;
        problem.steps = steps;
        problem.loss_frames = std::move(frames);
        problem.driven_pins = std::move(pins);
        problem.checkpoint_every = checkpoint_every;
        const size_t count = static_cast<size_t>(targets.size() / 3);
        require(targets.size() % 3 == 0, "pin_targets", targets.size(),
                "an array of shape (steps, pins, 3)");
        problem.pin_targets.resize(count);
        for (size_t k = 0; k < count; ++k)
          problem.pin_targets[k] =
              Vec3(targets.data()[3 * k], targets.data()[3 * k + 1], targets.data()[3 * k + 2]);
        problem.loss = [&](int frame, const State& s, VecX& dx, VecX& dv) -> Real {
          const py::object r = loss(copy_n3(s.x), copy_n3(s.v), frame);
          const auto t = r.cast<py::tuple>();
          require(t.size() == 3, "loss(x, v) at frame " + std::to_string(frame),
                  std::to_string(t.size()) + " values", "(value, dL/dx, dL/dv)");
          VecX gx = dx, gv = dv;  // (the right size: assign_n3 checks the arrays' shapes)
          assign_n3(gx, t[1].cast<DoubleArray>(), "dL/dx");
          assign_n3(gv, t[2].cast<DoubleArray>(), "dL/dv");
          dx += gx;
          dv += gv;
          return t[0].cast<Real>();
        };
        const GradientResult g = integrator_gradient(sim, problem);
        py::dict out;
        out["loss"] = g.loss;
        out["position"] = copy_n3(g.initial_position);
        out["velocity"] = copy_n3(g.initial_velocity);
        out["gravity"] = py::array_t<double>(3, g.gravity.data());
        out["ks"] = py::array_t<double>(static_cast<py::ssize_t>(g.ks.size()), g.ks.data());
        out["kd"] = py::array_t<double>(static_cast<py::ssize_t>(g.kd.size()), g.kd.data());
        out["particle_mass"] = py::array_t<double>(static_cast<py::ssize_t>(g.particle_mass.size()),
                                                   g.particle_mass.data());
        py::array_t<double> pt({static_cast<py::ssize_t>(g.pin_targets.size()), py::ssize_t{3}});
        for (size_t k = 0; k < g.pin_targets.size(); ++k)
          for (int d = 0; d < 3; ++d) pt.mutable_data()[3 * k + d] = g.pin_targets[k][d];
        out["pin_targets"] = pt;
        // The external forces' gradients, with each force's body (all its particles are one
        // body's) and kind, for the scene paths bodies[i].forces[k].<field>.
        const Model& model = sim.model();
        const auto forces = static_cast<py::ssize_t>(g.force_vector.size());
        py::array_t<double> fv({forces, py::ssize_t{3}});
        py::list force_body, force_kind;
        for (py::ssize_t e = 0; e < forces; ++e) {
          for (int d = 0; d < 3; ++d) fv.mutable_data()[3 * e + d] = g.force_vector[e][d];
          const ExternalForce& force = model.external_forces[e];
          int body = -1;
          for (int b = 0; b < model.num_bodies(); ++b) {
            const Body& range = model.bodies[b];
            if (force.particles.front() >= range.first_particle &&
                force.particles.front() < range.end_particle())
              body = b;
          }
          force_body.append(body);
          force_kind.append(std::string(external_force_kind_name(force.kind)));
        }
        out["force_vector"] = fv;
        out["force_drag"] = py::array_t<double>(forces, g.force_drag.data());
        out["force_gust"] = py::array_t<double>(forces, g.force_gust.data());
        out["force_body"] = force_body;
        out["force_kind"] = force_kind;
        out["contact_steps"] = g.contact_steps;
        out["slide_steps"] = g.slide_steps;
        out["bounce_steps"] = g.bounce_steps;
        out["pair_steps"] = g.pair_steps;
        out["pair_slide_steps"] = g.pair_slide_steps;
        out["pair_bounce_steps"] = g.pair_bounce_steps;
        out["pair_projected_steps"] = g.pair_projected_steps;
        out["newton_unconverged_steps"] = g.newton_unconverged_steps;
        out["forward_residual"] = g.forward_residual;
        out["backward_solver"] = g.backward_solver;
        out["backward_iterations"] = g.backward_iterations;
        out["forward_seconds"] = g.forward_seconds;
        out["backward_seconds"] = g.backward_seconds;
        return out;
      },
      py::arg("simulator"), py::arg("steps"), py::arg("loss"), py::arg("frames"), py::arg("pins"),
      py::arg("pin_targets"), py::arg("checkpoint_every") = 0,
      "Internal (jelly.gradient): runs `simulator` for `steps` steps and returns the loss and "
      "its gradient as a dict of arrays.");
}

}  // namespace jelly::python
