#include <jelly/core/model.hpp>

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

void Springs::append(const Springs& other, int shift) {
  for (int s = 0; s < other.size(); ++s) {
    a.push_back(other.a[s] + shift);
    b.push_back(other.b[s] + shift);
  }
  rest_length.insert(rest_length.end(), other.rest_length.begin(), other.rest_length.end());
  ks.insert(ks.end(), other.ks.begin(), other.ks.end());
  kd.insert(kd.end(), other.kd.begin(), other.kd.end());
  type.insert(type.end(), other.type.begin(), other.type.end());
}

}  // namespace jelly
