#include <jelly/geometry/cube.hpp>

#include <cmath>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/geometry/detail/body_shape_fields.hpp>

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

const FieldTable<CubeShape>& cube_shape_fields() {
  using C = CubeShape;
  static const FieldTable<C> table{
      "CubeShape",
      "bodies[i]",
      "An n x n x n lattice of particles (the seed's cube), springs as the seed report's",
      {
          integer_field<&C::n>("n", "", range_closed(2, 400), "an integer in [2, 400]",
                               "Particles per edge"),
          number_field<&C::edge_length>("edge_length", "m", range_above(0), "a finite length > 0",
                                        "Edge length of the cube"),
          vec3_field<&C::origin>("origin", "m", range_finite(), "finite coordinates",
                                 "Where particle (0, 0, 0) sits"),
      },
  };
  return table;
}

void CubeShape::validate(const std::string& prefix) const {
  validate_fields(cube_shape_fields(), *this, prefix);
}

BodyPart CubeShape::build(const Material& material, const std::string& prefix) const {
  validate(prefix);
  LatticeGrid grid;
  grid.n = {n, n, n};
  grid.spacing = Vec3::Constant(edge_length / (n - 1));
  grid.origin = origin;
  return build_lattice(grid, material, "cube");
}

void CubeShape::write(Json& j) const { write_fields(cube_shape_fields(), *this, j); }

std::unique_ptr<BodyShape> CubeShape::read(JsonFields& f) {
  auto s = std::make_unique<CubeShape>();
  read_fields(cube_shape_fields(), f, *s, f.prefix());
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
