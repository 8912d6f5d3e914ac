#include <jelly/geometry/cube.hpp>

#include <cmath>

#include <jelly/core/errors.hpp>
#include <jelly/core/json.hpp>

namespace jelly {

namespace {
// Counts of larger cubes overflow 64 bits (the springs are about 13 n^3).
constexpr std::int64_t kMaxCountedEdge = 500000;
void check_edge(std::int64_t n) {
  require(n >= 0 && n <= kMaxCountedEdge, "n", n,
          "an integer in [0, " + std::to_string(kMaxCountedEdge) + "] (particles per edge)");
}
}  // namespace

std::int64_t cube_particle_count(std::int64_t n) {
  check_edge(n);
  return n * n * n;
}

std::int64_t cube_spring_count(std::int64_t n) {
  check_edge(n);
  if (n < 2) return 0;
  const std::int64_t m = n - 1;
  return 3 * n * n * m + 6 * n * m * m + 4 * m * m * m + 3 * n * n * (n - 2);
}

void CubeShape::validate(const std::string& prefix) const {
  require(n >= 2 && n <= 400, prefix + "n", n, "an integer in [2, 400]");
  require(std::isfinite(edge_length) && edge_length > 0, prefix + "edge_length", edge_length,
          "a finite length > 0");
  require(origin.allFinite(), prefix + "origin", origin.transpose(), "finite coordinates");
}

BodyPart CubeShape::build(const Material& material, const std::string& prefix) const {
  validate(prefix);
  LatticeGrid grid;
  grid.n = {n, n, n};
  grid.spacing = Vec3::Constant(edge_length / (n - 1));
  grid.origin = origin;
  return build_lattice(grid, material, "cube");
}

void CubeShape::write(Json& j) const {
  j["n"] = n;
  j["edge_length"] = edge_length;
  j["origin"] = json_of(origin);
}

std::unique_ptr<BodyShape> CubeShape::read(JsonFields& f) {
  auto s = std::make_unique<CubeShape>();
  s->n = f.integer_or("n", s->n);
  s->edge_length = f.number_or("edge_length", s->edge_length);
  s->origin = f.vec3_or("origin", s->origin);
  s->validate(f.prefix());
  return s;
}

CubeShape CubeSpec::shape() const {
  CubeShape s;
  s.n = n;
  s.edge_length = edge_length;
  s.origin = origin;
  return s;
}

Material CubeSpec::material() const {
  Material m;
  m.springs = springs;
  m.particle_mass = particle_mass;
  return m;
}

void CubeSpec::validate() const {
  shape().validate("cube.");
  require(std::isfinite(particle_mass) && particle_mass > 0, "cube.particle_mass", particle_mass,
          "a finite mass > 0");
  material().validate("");
  require(gravity.allFinite(), "gravity", gravity.transpose(), "finite components");
}

Model build_cube(const CubeSpec& spec) {
  spec.validate();
  Model model;
  model.gravity = spec.gravity;
  model.add_body("jelly", spec.shape().build(spec.material(), "cube."));
  return model;
}

}  // namespace jelly
