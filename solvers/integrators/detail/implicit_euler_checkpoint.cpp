#include <jelly/solvers/integrators/detail/implicit_euler_checkpoint.hpp>

#include <cmath>

#include <jelly/core/errors.hpp>

namespace jelly {

std::vector<Real> ImplicitEulerCheckpoint::to_numbers() const {
  std::vector<Real> out;
  out.reserve(2 + warm_start.size() + body_pairs.size() + contact_set.size());
  out.push_back(static_cast<Real>(warm_start.size()));
  out.insert(out.end(), warm_start.data(), warm_start.data() + warm_start.size());
  if (!body_pairs.empty()) {
    out.push_back(-1.0 - static_cast<Real>(body_pairs.size()));
    out.insert(out.end(), body_pairs.begin(), body_pairs.end());
  }
  out.insert(out.end(), contact_set.begin(), contact_set.end());
  return out;
}

ImplicitEulerCheckpoint ImplicitEulerCheckpoint::from_numbers(const std::vector<Real>& data) {
  ImplicitEulerCheckpoint c;
  if (data.empty()) return c;
  const Real n = data[0];
  require(n >= 0 && n == std::floor(n) && n + 1 <= static_cast<Real>(data.size()),
          "integrator state (warm start size)", n, "the size of a saved implicit_euler state");
  const size_t size = static_cast<size_t>(n);
  c.warm_start = Eigen::Map<const VecX>(data.data() + 1, static_cast<Eigen::Index>(size));
  size_t at = 1 + size;
  if (at < data.size() && data[at] < 0) {
    const Real count = -1 - data[at];
    require(count >= 0 && count == std::floor(count) &&
                at + 1 + count <= static_cast<Real>(data.size()),
            "integrator state (body contact pairs)", data[at],
            "the size of a saved implicit_euler state");
    ++at;
    c.body_pairs.assign(
        data.begin() + static_cast<std::ptrdiff_t>(at),
        data.begin() + static_cast<std::ptrdiff_t>(at + static_cast<size_t>(count)));
    at += static_cast<size_t>(count);
  }
  c.contact_set.assign(data.begin() + static_cast<std::ptrdiff_t>(at), data.end());
  return c;
}

}  // namespace jelly
