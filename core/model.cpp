#include <jelly/core/model.hpp>

#include <cmath>
#include <string>

#include <jelly/core/errors.hpp>

namespace jelly {

std::string_view spring_type_name(SpringType type) {
  switch (type) {
    case SpringType::kStructural:
      return "structural";
    case SpringType::kShear:
      return "shear";
    case SpringType::kBending:
      return "bending";
  }
  return "unknown";
}

void Springs::add(int a_index, int b_index, Real rest, SpringCoefficients c, SpringType t) {
  a.push_back(a_index);
  b.push_back(b_index);
  rest_length.push_back(rest);
  ks.push_back(c.ks);
  kd.push_back(c.kd);
  type.push_back(t);
}

int Springs::count(SpringType t) const {
  int n = 0;
  for (SpringType s : type) n += (s == t);
  return n;
}

void Springs::set_coefficients(SpringType t, SpringCoefficients c) {
  for (int s = 0; s < size(); ++s) {
    if (type[s] == t) {
      ks[s] = c.ks;
      kd[s] = c.kd;
    }
  }
}

void Model::validate() const {
  const int n = num_particles();
  for (int i = 0; i < n; ++i) {
    require(std::isfinite(mass[i]) && mass[i] > 0, "mass[" + std::to_string(i) + "]", mass[i],
            "a finite mass > 0");
  }
  require(rest_position.size() == 3 * n, "rest_position.size", rest_position.size(),
          "3 x the number of particles");
  require(gravity.allFinite(), "gravity", gravity.transpose(), "finite components");
  for (int s = 0; s < springs.size(); ++s) {
    const std::string at = "springs[" + std::to_string(s) + "]";
    require(springs.a[s] >= 0 && springs.a[s] < n, at + ".a", springs.a[s],
            "a particle index in [0, " + std::to_string(n) + ")");
    require(springs.b[s] >= 0 && springs.b[s] < n && springs.b[s] != springs.a[s], at + ".b",
            springs.b[s], "a particle index in [0, N) other than a");
    require(std::isfinite(springs.rest_length[s]) && springs.rest_length[s] > 0,
            at + ".rest_length", springs.rest_length[s], "a finite length > 0");
    require(std::isfinite(springs.ks[s]) && springs.ks[s] >= 0, at + ".ks", springs.ks[s],
            "a finite stiffness >= 0");
    require(std::isfinite(springs.kd[s]) && springs.kd[s] >= 0, at + ".kd", springs.kd[s],
            "a finite damping >= 0");
  }
}

}  // namespace jelly
