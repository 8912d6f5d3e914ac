#include <jelly/core/model.hpp>

#include <cmath>
#include <string>

#include <jelly/core/errors.hpp>

namespace jelly {

void Surface::add_particle_vertex(int p) {
  particles.push_back(p);
  weights.push_back(1.0);
  offsets.push_back(static_cast<int>(particles.size()));
}

void Surface::add_vertex(const int* vertex_particles, const Real* vertex_weights, int count) {
  for (int k = 0; k < count; ++k) {
    particles.push_back(vertex_particles[k]);
    weights.push_back(vertex_weights[k]);
  }
  offsets.push_back(static_cast<int>(particles.size()));
}

void Surface::shift_particles(int shift) {
  for (int& p : particles) p += shift;
}

Vec3 Surface::vertex(const VecX& x, int v) const {
  Vec3 sum = Vec3::Zero();
  for (int k = offsets[v]; k < offsets[v + 1]; ++k) sum += weights[k] * particle(x, particles[k]);
  return sum;
}

void Surface::vertices(const VecX& x, RowMatrixX3& out) const {
  const int n = num_vertices();
  if (out.rows() != n) out.resize(n, 3);
  for (int v = 0; v < n; ++v) out.row(v) = vertex(x, v).transpose();
}

void Surface::validate(int num_particles, const std::string& field) const {
  require(!offsets.empty() && offsets.front() == 0 &&
              offsets.back() == static_cast<int>(particles.size()) &&
              particles.size() == weights.size(),
          field + ".offsets", offsets.size(), "offsets from 0 to the number of weights");
  // (A field's name is built only for a message, as in Model::validate.)
  for (int v = 0; v < num_vertices(); ++v) {
    const bool ok = offsets[v + 1] > offsets[v];
    if (!ok)
      require(ok, field + ".vertex[" + std::to_string(v) + "]", v,
              "a vertex with at least one particle");
  }
  for (std::size_t k = 0; k < particles.size(); ++k) {
    const bool particle_ok = particles[k] >= 0 && particles[k] < num_particles;
    const bool weight_ok = std::isfinite(weights[k]);
    if (particle_ok && weight_ok) continue;
    require(particle_ok, field + ".particles[" + std::to_string(k) + "]", particles[k],
            "a particle index of the model");
    require(weight_ok, field + ".weights[" + std::to_string(k) + "]", weights[k],
            "a finite weight");
  }
  const int nv = num_vertices();
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    for (int c : triangles[t]) {
      const bool ok = c >= 0 && c < nv;
      if (!ok)
        require(ok, field + ".triangles[" + std::to_string(t) + "]", c,
                "a vertex index of the surface");
    }
  }
}

}  // namespace jelly
