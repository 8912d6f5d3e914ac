#include <jelly/viewer/scene_builder.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

namespace jelly::viewer {

namespace {

unsigned long next_topology() {
  static std::atomic<unsigned long> counter{0};
  return ++counter;
}

}  // namespace

void bounds_of(const VecX& x, Vec3& lo, Vec3& hi) {
  lo.setConstant(std::numeric_limits<Real>::max());
  hi.setConstant(std::numeric_limits<Real>::lowest());
  for (Eigen::Index i = 0; i + 2 < x.size(); i += 3) {
    lo = lo.cwiseMin(x.segment<3>(i));
    hi = hi.cwiseMax(x.segment<3>(i));
  }
}

void bounds_of(const std::vector<VecX>& frames, Vec3& lo, Vec3& hi) {
  lo.setConstant(std::numeric_limits<Real>::max());
  hi.setConstant(std::numeric_limits<Real>::lowest());
  for (const VecX& x : frames) {
    Vec3 a, b;
    bounds_of(x, a, b);
    lo = lo.cwiseMin(a);
    hi = hi.cwiseMax(b);
  }
}

SceneBuilder::SceneBuilder(const Model& model, std::vector<BodySurface> surfaces, Terrains terrains,
                           const Vec3& focus_lo, const Vec3& focus_hi)
    : num_particles_(model.num_particles()),
      surfaces_(std::move(surfaces)),
      terrains_(std::move(terrains)) {
  const Vec3 centre = 0.5 * (focus_lo + focus_hi);
  const Real size = focus_lo.x() <= focus_hi.x() ? (focus_hi - focus_lo).norm() : 1.0;
  const Real extent = std::max<Real>(150, 8 * size);
  focus_ = centre.cast<float>();
  extent_ = static_cast<float>(extent);
  bool has_floor = false;
  Real lowest = focus_lo.x() <= focus_hi.x() ? focus_lo.y() : 0;
  for (const auto& terrain : terrains_) {
    meshes_.push_back(terrain_mesh(*terrain, centre, extent));
    has_floor = has_floor || is_ground(*terrain);
    if (is_ground(*terrain)) continue;
    const Eigen::Isometry3d pose = terrain_pose(*terrain, 0);
    for (const Vec3& v : meshes_.back().vertices) lowest = std::min(lowest, (pose * v).y());
  }
  floor_ = !has_floor;
  floor_height_ = static_cast<float>(std::floor(lowest - 1.0));

  const Springs& s = model.springs;
  springs_.reserve(static_cast<size_t>(s.size()));
  Real mean_length = 0;
  for (int k = 0; k < s.size(); ++k) {
    springs_.push_back({s.a[k], s.b[k]});
    rest_length_.push_back(static_cast<float>(s.rest_length[k]));
    type_.push_back(static_cast<int>(s.type[k]));
    if (s.type[k] == SpringType::kStructural) mean_length += s.rest_length[k];
  }
  const int structural = s.count(SpringType::kStructural);
  if (structural > 0) particle_radius_ = static_cast<float>(0.18 * mean_length / structural);
}

RenderScene SceneBuilder::make_scene(const VecX& x, Real t) const {
  RenderScene scene;
  scene.topology = next_topology();
  for (size_t b = 0; b < surfaces_.size(); ++b) {
    SurfaceView body;
    body.name = surfaces_[b].name;
    body.triangles = surfaces_[b].triangles;
    body.positions.assign(static_cast<size_t>(3 * surfaces_[b].num_vertices()), 0.0f);
    body.color = (surfaces_[b].color ? *surfaces_[b].color : palette_color(static_cast<int>(b)))
                     .cast<float>();
    body.first_particle = surfaces_[b].first_particle;
    body.num_particles = surfaces_[b].num_particles;
    scene.bodies.push_back(std::move(body));
  }
  for (size_t i = 0; i < terrains_.size(); ++i) {
    TerrainView view;
    view.name = std::string(terrains_[i]->kind());
    for (const Vec3& v : meshes_[i].vertices)
      view.vertices.insert(
          view.vertices.end(),
          {static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z())});
    view.triangles = meshes_[i].triangles;
    view.casts_shadow = !is_ground(*terrains_[i]);
    if (terrains_[i]->kind() == "elevator") view.color = Vec3f(0.55f, 0.58f, 0.66f);
    scene.terrains.push_back(std::move(view));
  }
  scene.particles.assign(static_cast<size_t>(3 * num_particles_), 0.0f);
  // Bodies without a surface are seen as their particles.
  bool any_surface = false;
  for (const BodySurface& s : surfaces_) any_surface = any_surface || !s.triangles.empty();
  scene.show_particles = !any_surface;
  scene.particle_radius = particle_radius_;
  scene.springs = springs_;
  scene.spring_rest_length = rest_length_;
  scene.spring_type = type_;
  scene.focus = focus_;
  scene.ground_extent = extent_;
  scene.floor = floor_;
  scene.floor_height = floor_height_;
  update(x, t, scene);
  return scene;
}

void SceneBuilder::update(const VecX& x, Real t, RenderScene& scene) const {
  for (size_t b = 0; b < surfaces_.size() && b < scene.bodies.size(); ++b)
    surfaces_[b].vertices(x, scene.bodies[b].positions.data());
  const Eigen::Index n = std::min<Eigen::Index>(x.size(), scene.particles.size());
  for (Eigen::Index i = 0; i < n; ++i) scene.particles[i] = static_cast<float>(x[i]);
  for (size_t i = 0; i < terrains_.size() && i < scene.terrains.size(); ++i)
    scene.terrains[i].pose = terrain_pose(*terrains_[i], t).matrix().cast<float>();
}

}  // namespace jelly::viewer
