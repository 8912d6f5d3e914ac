#include <jelly/geometry/detail/box.hpp>

#include <cmath>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/geometry/detail/body_shape_fields.hpp>

namespace jelly {

const FieldTable<BoxShape>& box_shape_fields() {
  using B = BoxShape;
  static const FieldTable<B> table{
      "BoxShape",
      "bodies[i]",
      "A lattice of nx x ny x nz particles filling a box of the given size",
      {
          integer_field<&B::n, 0>("nx", "", range_closed(2, 2000), "an integer in [2, 2000]",
                                  "Particles along the box's own x"),
          integer_field<&B::n, 1>("ny", "", range_closed(2, 2000), "an integer in [2, 2000]",
                                  "Particles along the box's own y"),
          integer_field<&B::n, 2>("nz", "", range_closed(2, 2000), "an integer in [2, 2000]",
                                  "Particles along the box's own z"),
          vec3_each_field<&B::size>("size", "m", range_above(0), "three finite sizes > 0 (m)",
                                    "Edge lengths along the box's own x, y, z"),
          pose_position_field<&B::pose, &Pose::position>("Where the box's centre is"),
          pose_rotation_field<&B::pose, &Pose::rotation_degrees>(),
      },
      // The pose's scale is no key of a box (its size is): only code can set it.
      [](const B& s, const std::string& prefix) {
        require(s.pose.scale == 1, prefix + "scale", s.pose.scale, "1 (give the size instead)");
      },
  };
  return table;
}

void BoxShape::validate(const std::string& prefix) const {
  validate_fields(box_shape_fields(), *this, prefix);
}

BodyPart BoxShape::build(const Material& material, const std::string& prefix) const {
  validate(prefix);
  LatticeGrid grid;
  grid.n = n;
  for (int a = 0; a < 3; ++a) grid.spacing[a] = size[a] / (n[a] - 1);
  grid.rotation = pose.rotation();
  grid.origin = pose.position - grid.rotation * (0.5 * size);
  return build_lattice(grid, material, "box");
}

void BoxShape::write(Json& j) const { write_fields(box_shape_fields(), *this, j); }

std::unique_ptr<BodyShape> BoxShape::read(JsonFields& f) {
  auto s = std::make_unique<BoxShape>();
  read_fields(box_shape_fields(), f, *s, f.prefix());
  return s;
}

}  // namespace jelly
