#include <jelly/core/cube.hpp>

#include <cmath>

#include <jelly/core/errors.hpp>

namespace jelly {

void CubeSpec::validate() const {
  require(n >= 2 && n <= 400, "cube.n", n, "an integer in [2, 400]");
  require(std::isfinite(edge_length) && edge_length > 0, "cube.edge_length", edge_length,
          "a finite length > 0");
  require(origin.allFinite(), "cube.origin", origin.transpose(), "finite coordinates");
  require(std::isfinite(particle_mass) && particle_mass > 0, "cube.particle_mass", particle_mass,
          "a finite mass > 0");
  for (int t = 0; t < kSpringTypeCount; ++t) {
    const std::string name = "springs." + std::string(spring_type_name(SpringType(t)));
    require(std::isfinite(springs[t].ks) && springs[t].ks >= 0, name + ".ks", springs[t].ks,
            "a finite stiffness >= 0");
    require(std::isfinite(springs[t].kd) && springs[t].kd >= 0, name + ".kd", springs[t].kd,
            "a finite damping >= 0");
  }
  require(gravity.allFinite(), "gravity", gravity.transpose(), "finite components");
}

namespace {

struct Offset {
  int di, dj, dk;
  SpringType type;
};

// Each neighbour direction once (the opposite direction is the same spring).
constexpr std::array<Offset, 13> kOffsets{{
    {1, 0, 0, SpringType::kStructural},
    {0, 1, 0, SpringType::kStructural},
    {0, 0, 1, SpringType::kStructural},
    {1, 1, 0, SpringType::kShear},
    {1, -1, 0, SpringType::kShear},
    {1, 0, 1, SpringType::kShear},
    {1, 0, -1, SpringType::kShear},
    {0, 1, 1, SpringType::kShear},
    {0, 1, -1, SpringType::kShear},
    {1, 1, 1, SpringType::kShear},
    {1, 1, -1, SpringType::kShear},
    {1, -1, 1, SpringType::kShear},
    {1, -1, -1, SpringType::kShear},
}};

}  // namespace

Model build_cube(const CubeSpec& spec) {
  spec.validate();
  const int n = spec.n;
  const int count = n * n * n;
  const Real spacing = spec.edge_length / (n - 1);

  Model model;
  model.mass = VecX::Constant(count, spec.particle_mass);
  model.gravity = spec.gravity;
  model.rest_position.resize(3 * count);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k)
        particle(model.rest_position, cube_index(n, i, j, k)) =
            spec.origin + spacing * Vec3(i, j, k);

  const auto inside = [n](int i) { return i >= 0 && i < n; };
  const auto connect = [&](int i, int j, int k, int di, int dj, int dk, SpringType type) {
    if (!inside(i + di) || !inside(j + dj) || !inside(k + dk)) return;
    const int a = cube_index(n, i, j, k);
    const int b = cube_index(n, i + di, j + dj, k + dk);
    const Real rest = (particle(model.rest_position, a) - particle(model.rest_position, b)).norm();
    model.springs.add(a, b, rest, spec.springs[static_cast<int>(type)], type);
  };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) {
        for (const Offset& o : kOffsets) connect(i, j, k, o.di, o.dj, o.dk, o.type);
        connect(i, j, k, 2, 0, 0, SpringType::kBending);
        connect(i, j, k, 0, 2, 0, SpringType::kBending);
        connect(i, j, k, 0, 0, 2, SpringType::kBending);
      }
  return model;
}

State rest_state(const Model& model) {
  State state;
  state.t = 0;
  state.x = model.rest_position;
  state.v = VecX::Zero(model.num_dofs());
  return state;
}

}  // namespace jelly
