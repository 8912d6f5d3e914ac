#include <jelly/core/pins.hpp>

#include <algorithm>
#include <string>

#include <jelly/core/errors.hpp>

namespace jelly {

int Pins::add_path(Path p) {
  paths.push_back(std::move(p));
  return static_cast<int>(paths.size()) - 1;
}

void Pins::add(int particle, const Vec3& anchor, int path_index) {
  if (std::find(particles.begin(), particles.end(), particle) != particles.end()) return;
  particles.push_back(particle);
  anchors.push_back(anchor);
  path.push_back(path_index);
}

void Pins::add_fixed(int particle, const Vec3& anchor) { add(particle, anchor, fixed_path()); }

void Pins::add_new(const std::vector<int>& new_particles, const std::vector<Vec3>& new_anchors,
                   int path_index) {
  particles.insert(particles.end(), new_particles.begin(), new_particles.end());
  anchors.insert(anchors.end(), new_anchors.begin(), new_anchors.end());
  path.insert(path.end(), new_particles.size(), path_index);
}

int Pins::fixed_path() {
  for (int p = static_cast<int>(paths.size()) - 1; p >= 0; --p) {
    if (paths[p].is_fixed()) return p;
  }
  return add_path(Path());
}

int Pins::find(int particle) const {
  const auto at = std::find(particles.begin(), particles.end(), particle);
  return at == particles.end() ? -1 : static_cast<int>(at - particles.begin());
}

void Pins::set(int particle, const Vec3& anchor, Path p) {
  const int k = find(particle);
  if (k < 0) {
    particles.push_back(particle);
    anchors.push_back(anchor);
    path.push_back(add_path(std::move(p)));
    return;
  }
  anchors[k] = anchor;
  const int shared = static_cast<int>(std::count(path.begin(), path.end(), path[k]));
  if (shared == 1)
    paths[path[k]] = std::move(p);
  else
    path[k] = add_path(std::move(p));
}

bool Pins::remove(int particle) {
  const int k = find(particle);
  if (k < 0) return false;
  particles.erase(particles.begin() + k);
  anchors.erase(anchors.begin() + k);
  path.erase(path.begin() + k);
  return true;
}

bool Pins::all_fixed() const {
  return std::all_of(path.begin(), path.end(), [&](int p) { return paths[p].is_fixed(); });
}

Vec3 Pins::position(int k, Real t) const {
  const Path& p = paths[path[k]];
  return p.is_fixed() ? anchors[k] : Vec3(anchors[k] + p.sample(t).offset);
}

void Pins::apply(Real t, VecX& x, VecX& v) const {
  for (int k = 0; k < size(); ++k) {
    const int i = particles[k];
    const Path& p = paths[path[k]];
    if (p.is_fixed()) {
      particle(x, i) = anchors[k];
      particle(v, i).setZero();
    } else {
      const PathSample s = p.sample(t);
      particle(x, i) = anchors[k] + s.offset;
      particle(v, i) = s.velocity;
    }
  }
}

void Pins::apply_acceleration(Real t, VecX& a) const {
  for (int k = 0; k < size(); ++k) {
    const Path& p = paths[path[k]];
    particle(a, particles[k]) = p.is_fixed() ? Vec3::Zero() : p.sample(t).acceleration;
  }
}

void Pins::shift_particles(int shift) {
  for (int& p : particles) p += shift;
}

void Pins::validate(int num_particles) const {
  require(anchors.size() == particles.size() && path.size() == particles.size(), "pins.size",
          anchors.size(), "one anchor and one path per pinned particle");
  for (int k = 0; k < size(); ++k) {
    const std::string at = "pins[" + std::to_string(k) + "]";
    require(particles[k] >= 0 && particles[k] < num_particles, at + ".particle", particles[k],
            "a particle index in [0, " + std::to_string(num_particles) + ")");
    require(anchors[k].allFinite(), at + ".anchor", anchors[k].transpose(), "finite coordinates");
    require(path[k] >= 0 && path[k] < static_cast<int>(paths.size()), at + ".path", path[k],
            "a path index");
  }
}

}  // namespace jelly
