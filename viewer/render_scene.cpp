#include <jelly/viewer/render_scene.hpp>

#include <limits>

namespace jelly::viewer {

void RenderScene::particle_bounds(Vec3f& lo, Vec3f& hi) const {
  lo.setConstant(std::numeric_limits<float>::max());
  hi.setConstant(std::numeric_limits<float>::lowest());
  for (size_t i = 0; i + 2 < particles.size(); i += 3) {
    const Vec3f p(particles[i], particles[i + 1], particles[i + 2]);
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
}

}  // namespace jelly::viewer
