#include <jelly/viewer/scene_adapter.hpp>

#include <cmath>

#include <jelly/io/scene.hpp>
#include <jelly/terrain/elevator.hpp>
#include <jelly/terrain/plane.hpp>

namespace jelly::viewer {

namespace {

// The n with n^3 == count, or 0.
int cube_edge(int count) {
  const int n = static_cast<int>(std::lround(std::cbrt(static_cast<double>(count))));
  return n >= 2 && n * n * n == count ? n : 0;
}

// The lattice boundary faces of an n^3 cube: vertices are the boundary particles in index
// order, two triangles per boundary quad, turned to face outwards.
void lattice_boundary(int n, BodySurface& s) {
  std::vector<int> vertex_of(static_cast<size_t>(n) * n * n, -1);
  const auto on_boundary = [n](int i) { return i == 0 || i == n - 1; };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) {
        if (!on_boundary(i) && !on_boundary(j) && !on_boundary(k)) continue;
        const int p = (i * n + j) * n + k;
        vertex_of[p] = s.num_vertices();
        s.particles.push_back(p);
        s.weights.push_back(1.0);
        s.offsets.push_back(static_cast<int>(s.particles.size()));
      }
  // Face `axis` at lattice coordinate `side` (0 or n - 1); (u, v) span the other two axes.
  for (int axis = 0; axis < 3; ++axis) {
    const int u_axis = (axis + 1) % 3, v_axis = (axis + 2) % 3;
    for (const int side : {0, n - 1}) {
      // u x v points along +axis; outward is +axis on the far side, -axis on the near one.
      const bool flip = side == 0;
      for (int u = 0; u + 1 < n; ++u)
        for (int v = 0; v + 1 < n; ++v) {
          const auto index = [&](int du, int dv) {
            int c[3];
            c[axis] = side;
            c[u_axis] = u + du;
            c[v_axis] = v + dv;
            return vertex_of[(c[0] * n + c[1]) * n + c[2]];
          };
          const int a = index(0, 0), b = index(1, 0), c = index(1, 1), d = index(0, 1);
          if (flip) {
            s.triangles.push_back({a, c, b});
            s.triangles.push_back({a, d, c});
          } else {
            s.triangles.push_back({a, b, c});
            s.triangles.push_back({a, c, d});
          }
        }
    }
  }
}

}  // namespace

Vec3 BodySurface::vertex(const VecX& x, int v) const {
  Vec3 p = Vec3::Zero();
  for (int k = offsets[v]; k < offsets[v + 1]; ++k) p += weights[k] * particle(x, particles[k]);
  return p;
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
  BodySurface body;
  body.name = "jelly";
  body.first_particle = 0;
  body.num_particles = model.num_particles();
  if (const int n = cube_edge(model.num_particles())) lattice_boundary(n, body);
  return {body};
}

TerrainMesh terrain_mesh(const Terrain& terrain, const Vec3& focus, Real extent) {
  TerrainMesh mesh;
  if (const auto* plane = dynamic_cast<const Plane*>(&terrain)) {
    const Vec3 n = plane->unit_normal();
    const Vec3 centre = focus - n * n.dot(focus - plane->point());
    // Two directions in the plane: u from the axis least aligned with n.
    Eigen::Index least = 0;
    n.cwiseAbs().minCoeff(&least);
    const Vec3 u = n.cross(Vec3::Unit(least)).normalized() * extent;
    const Vec3 w = n.cross(u);
    mesh.vertices = {centre - u - w, centre + u - w, centre + u + w, centre - u + w};
    // (u x w) = (n x u) x ... : orient by the normal.
    const Vec3 normal =
        (mesh.vertices[1] - mesh.vertices[0]).cross(mesh.vertices[2] - mesh.vertices[0]);
    if (normal.dot(n) > 0)
      mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
    else
      mesh.triangles = {{0, 2, 1}, {0, 3, 2}};
  } else if (const auto* elevator = dynamic_cast<const Elevator*>(&terrain)) {
    const ElevatorSpec& spec = elevator->spec();
    const Real hx = spec.size_x / 2, hz = spec.size_z / 2;
    const Real depth = std::min<Real>(spec.thickness, 0.3);
    const Vec3 lo(-hx, -depth, -hz), hi(hx, 0, hz);
    // Six faces with their own vertices (flat shading), each CCW seen from outside.
    for (int axis = 0; axis < 3; ++axis) {
      const int u_axis = (axis + 1) % 3, v_axis = (axis + 2) % 3;
      for (const bool far : {false, true}) {
        const int base = static_cast<int>(mesh.vertices.size());
        for (const auto& [du, dv] : {std::pair{0, 0}, {1, 0}, {1, 1}, {0, 1}}) {
          Vec3 p;
          p[axis] = far ? hi[axis] : lo[axis];
          p[u_axis] = du ? hi[u_axis] : lo[u_axis];
          p[v_axis] = dv ? hi[v_axis] : lo[v_axis];
          mesh.vertices.push_back(p);
        }
        if (far)
          mesh.triangles.insert(mesh.triangles.end(),
                                {{base, base + 1, base + 2}, {base, base + 2, base + 3}});
        else
          mesh.triangles.insert(mesh.triangles.end(),
                                {{base, base + 2, base + 1}, {base, base + 3, base + 2}});
      }
    }
  }
  return mesh;
}

Eigen::Isometry3d terrain_pose(const Terrain& terrain, Real t) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  if (dynamic_cast<const Elevator*>(&terrain) != nullptr) pose.translation() = terrain.position(t);
  return pose;
}

bool is_ground(const Terrain& terrain) { return dynamic_cast<const Plane*>(&terrain) != nullptr; }

Terrains recording_terrains(const Recording& recording) {
  Terrains terrains;
  if (recording.scene_json.empty()) return terrains;
  const Scene scene = parse_scene(recording.scene_json, {}, "the recording's scene_json");
  for (const auto& spec : scene.terrains) terrains.push_back(spec->make());
  return terrains;
}

}  // namespace jelly::viewer
