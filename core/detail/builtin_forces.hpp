#pragma once
// jelly's own forces as Force plugins (core/force.hpp): gravity, the springs and dampers, the
// model's external forces (constant, wind, point) and anchor springs. The Simulator evaluates
// them through its vectorised force loop; these are the same forces through the interface a
// user's force implements, so that every force, ours and theirs, is checked the same way
// (check_force_jacobian) and can be added to a model built by hand.
#include <memory>
#include <vector>

#include <jelly/core/force.hpp>
#include <jelly/core/model.hpp>

namespace jelly {

// m g on every particle of `model` (read at each evaluation: live edits of gravity and masses
// show).
class GravityForce final : public Force {
 public:
  explicit GravityForce(const Model& model) : model_(&model) {}
  std::string name() const override { return "gravity"; }
  void add_forces(Real t, const VecX& x, const VecX& v, VecX& f) const override;
  bool has_jacobian() const override { return true; }  // zero

 private:
  const Model* model_;
};

// The springs and dampers of `model` with their exact Jacobians (no definiteness fix).
class SpringForce final : public Force {
 public:
  explicit SpringForce(const Model& model) : model_(&model) {}
  std::string name() const override { return "springs"; }
  void add_forces(Real t, const VecX& x, const VecX& v, VecX& f) const override;
  bool has_jacobian() const override { return true; }
  void add_jacobian(Real t, const VecX& x, const VecX& v, ForceJacobian& j) const override;

 private:
  const Model* model_;
};

// The model's external forces (constant, wind, point); wind's drag is its df/dv.
class ExternalForces final : public Force {
 public:
  explicit ExternalForces(const Model& model) : model_(&model) {}
  std::string name() const override { return "external_forces"; }
  void add_forces(Real t, const VecX& x, const VecX& v, VecX& f) const override;
  bool has_jacobian() const override { return true; }
  void add_jacobian(Real t, const VecX& x, const VecX& v, ForceJacobian& j) const override;

 private:
  const Model* model_;
};

// Springs from particles to points (core/force.hpp).
class AnchorForce final : public Force {
 public:
  explicit AnchorForce(AnchorSprings anchors) : anchors_(std::move(anchors)) {}
  std::string name() const override { return "anchors"; }
  void add_forces(Real t, const VecX& x, const VecX& v, VecX& f) const override;
  bool has_jacobian() const override { return true; }
  void add_jacobian(Real t, const VecX& x, const VecX& v, ForceJacobian& j) const override;
  void validate(int num_particles) const override { validate_anchors(anchors_, num_particles); }

 private:
  AnchorSprings anchors_;
};

// Every built-in force acting on `model` (gravity, springs, external forces, and anchors when
// given): their sum is Dynamics' force without contact.
std::vector<std::unique_ptr<Force>> builtin_forces(const Model& model,
                                                   const AnchorSprings& anchors = {});

}  // namespace jelly
