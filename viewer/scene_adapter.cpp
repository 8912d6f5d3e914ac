#include <jelly/viewer/scene_adapter.hpp>

#include <Eigen/Geometry>
#include <cmath>
#include <optional>

#include <jelly/geometry/cube.hpp>
#include <jelly/io/scene.hpp>
#include <jelly/terrain/plane.hpp>

namespace jelly::viewer {

namespace {

// A recording without bodies or scene: one body of all particles, a cube's lattice when there
// are n^3 of them (the seed cube: particle (i, j, k) at index (i n + j) n + k).
BodySurface all_particles(const Model& model) {
  BodySurface body;
  body.name = "jelly";
  body.num_particles = model.num_particles();
  const int n = static_cast<int>(std::lround(std::cbrt(static_cast<double>(body.num_particles))));
  if (n >= 2 && n * n * n == body.num_particles) {
    CubeSpec spec;
    spec.n = n;
    const Model cube = build_cube(spec);
    static_cast<Surface&>(body) = cube.bodies.front().surface;
  }
  return body;
}

}  // namespace

Vec3 palette_color(int index) {
  static const Vec3 kColors[] = {
      {0.85, 0.13, 0.22}, {0.16, 0.45, 0.85}, {0.95, 0.62, 0.10}, {0.20, 0.66, 0.34}};
  const int n = static_cast<int>(sizeof kColors / sizeof kColors[0]);
  return kColors[((index % n) + n) % n];
}

void BodySurface::vertices(const VecX& x, float* out) const {
  const int count = num_vertices();
  for (int v = 0; v < count; ++v) {
    const Vec3 p = vertex(x, v);
    out[3 * v] = static_cast<float>(p.x());
    out[3 * v + 1] = static_cast<float>(p.y());
    out[3 * v + 2] = static_cast<float>(p.z());
  }
}

void BodySurface::vertices(const VecX& x, double* out) const {
  const int count = num_vertices();
  for (int v = 0; v < count; ++v) Eigen::Map<Vec3>(out + 3 * v) = vertex(x, v);
}

std::vector<BodySurface> body_surfaces(const Model& model) {
  std::vector<BodySurface> out;
  for (const Body& b : model.bodies) {
    BodySurface s;
    static_cast<Surface&>(s) = b.surface;
    s.name = b.name;
    s.first_particle = b.first_particle;
    s.num_particles = b.num_particles;
    s.color = b.color;
    out.push_back(std::move(s));
  }
  return out;
}

std::vector<BodySurface> recording_surfaces(const Recording& recording) {
  std::optional<Model> scene_model;  // the recording's scene, made once when needed
  const auto scene = [&]() -> const Model* {
    if (!scene_model && !recording.scene_json.empty()) {
      try {
        scene_model =
            make_model(parse_scene(recording.scene_json, {}, "the recording's scene_json"));
      } catch (const InputError&) {
        // A scene this version cannot read: the particles alone, the palette's colours.
        scene_model = Model{};
      }
    }
    return scene_model ? &*scene_model : nullptr;
  };
  if (!recording.model.bodies.empty()) {
    std::vector<BodySurface> out = body_surfaces(recording.model);
    // A file written before bodies carried their colour: the scene's.
    for (BodySurface& body : out) {
      if (body.color || recording.scene_json.empty()) continue;
      if (const Model* model = scene())
        if (const Body* b = model->find_body(body.name)) body.color = b->color;
    }
    return out;
  }
  const Model* model = scene();
  if (model != nullptr && !model->bodies.empty() &&
      model->num_particles() == recording.model.num_particles())
    return body_surfaces(*model);
  return {all_particles(recording.model)};
}

TriangleMesh terrain_mesh(const Terrain& terrain, const Vec3& focus, Real extent) {
  const auto* plane = dynamic_cast<const Plane*>(&terrain);
  if (plane == nullptr) return terrain.render_mesh();
  // The plane's frame has its origin at plane->point(): the square goes around the foot of the
  // focus, in that frame.
  const Vec3 n = plane->unit_normal();
  const Vec3 foot = focus - n * n.dot(focus - plane->point());
  TriangleMesh mesh = square_mesh(n, 2 * extent);
  for (Vec3& v : mesh.vertices) v += foot - plane->point();
  return mesh;
}

Eigen::Isometry3d terrain_pose(const Terrain& terrain, Real t) { return terrain.pose(t); }

bool is_ground(const Terrain& terrain) { return dynamic_cast<const Plane*>(&terrain) != nullptr; }

Terrains recording_terrains(const Recording& recording) {
  Terrains terrains;
  if (recording.scene_json.empty()) return terrains;
  const Scene scene = parse_scene(recording.scene_json, {}, "the recording's scene_json");
  for (const auto& spec : scene.terrains) terrains.push_back(spec->make());
  return terrains;
}

}  // namespace jelly::viewer
