#include <jelly/geometry/triangle_mesh.hpp>

#include <Eigen/Geometry>
#include <cmath>

namespace jelly {

Eigen::AlignedBox3d TriangleMesh::bounds() const {
  Eigen::AlignedBox3d box;
  for (const Vec3& v : vertices) box.extend(v);
  return box;
}

Real TriangleMesh::area() const {
  Real area = 0;
  for (const Triangle& t : triangles) {
    const Vec3 &a = vertices[t[0]], &b = vertices[t[1]], &c = vertices[t[2]];
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  return area;
}

Real TriangleMesh::enclosed_volume() const {
  Real volume = 0;
  for (const Triangle& t : triangles) {
    const Vec3 &a = vertices[t[0]], &b = vertices[t[1]], &c = vertices[t[2]];
    volume += a.dot(b.cross(c)) / 6;
  }
  return volume;
}

void TriangleMesh::add_quad(int a, int b, int c, int d) {
  triangles.push_back({a, b, c});
  triangles.push_back({a, c, d});
}

void TriangleMesh::append(const TriangleMesh& other) {
  const int shift = num_vertices();
  vertices.insert(vertices.end(), other.vertices.begin(), other.vertices.end());
  for (Triangle t : other.triangles)
    triangles.push_back({t[0] + shift, t[1] + shift, t[2] + shift});
}

namespace {

// Turns every triangle of a convex mesh around the origin to face away from it.
void orient_outward(TriangleMesh& mesh) {
  for (Triangle& t : mesh.triangles) {
    const Vec3& a = mesh.vertices[t[0]];
    const Vec3& b = mesh.vertices[t[1]];
    const Vec3& c = mesh.vertices[t[2]];
    if ((b - a).cross(c - a).dot(a + b + c) < 0) std::swap(t[1], t[2]);
  }
}

// Rings of vertices around y at the given heights and radii, joined into bands, plus a pole or
// cap centre at each end when its radius is 0 or the ring is closed by a fan.
TriangleMesh lathe(const std::vector<Real>& heights, const std::vector<Real>& radii, int segments) {
  TriangleMesh mesh;
  const int rings = static_cast<int>(heights.size());
  for (int r = 0; r < rings; ++r) {
    for (int s = 0; s < segments; ++s) {
      const Real phi = 2 * M_PI * s / segments;
      mesh.vertices.emplace_back(radii[r] * std::cos(phi), heights[r], radii[r] * std::sin(phi));
    }
  }
  for (int r = 0; r + 1 < rings; ++r) {
    for (int s = 0; s < segments; ++s) {
      const int s1 = (s + 1) % segments;
      mesh.add_quad(r * segments + s, r * segments + s1, (r + 1) * segments + s1,
                    (r + 1) * segments + s);
    }
  }
  // Close both ends with a fan around a centre vertex.
  for (int end : {0, rings - 1}) {
    const int centre = mesh.num_vertices();
    mesh.vertices.emplace_back(0, heights[end], 0);
    for (int s = 0; s < segments; ++s) {
      mesh.triangles.push_back({centre, end * segments + s, end * segments + (s + 1) % segments});
    }
  }
  orient_outward(mesh);
  return mesh;
}

}  // namespace

TriangleMesh box_mesh(const Vec3& size) {
  TriangleMesh mesh;
  for (int c = 0; c < 8; ++c) {
    mesh.vertices.emplace_back((c & 1 ? 0.5 : -0.5) * size.x(), (c & 2 ? 0.5 : -0.5) * size.y(),
                               (c & 4 ? 0.5 : -0.5) * size.z());
  }
  mesh.add_quad(0, 2, 3, 1);  // -z
  mesh.add_quad(4, 5, 7, 6);  // +z
  mesh.add_quad(0, 1, 5, 4);  // -y
  mesh.add_quad(2, 6, 7, 3);  // +y
  mesh.add_quad(0, 4, 6, 2);  // -x
  mesh.add_quad(1, 3, 7, 5);  // +x
  orient_outward(mesh);
  return mesh;
}

TriangleMesh square_mesh(const Vec3& normal, Real size) {
  const Vec3 n = normal.normalized();
  const Vec3 helper = std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  const Vec3 u = n.cross(helper).normalized();
  const Vec3 v = n.cross(u);
  // u x v = n: the quad -u-v, +u-v, +u+v, -u+v is counter-clockwise seen from the normal's side.
  const Vec3 uu = u.cross(v).dot(n) > 0 ? u : Vec3(-u);
  const Real h = 0.5 * size;
  TriangleMesh mesh;
  mesh.vertices = {h * (-uu - v), h * (uu - v), h * (uu + v), h * (-uu + v)};
  mesh.add_quad(0, 1, 2, 3);
  return mesh;
}

TriangleMesh sphere_mesh(Real radius, int rings, int segments) {
  std::vector<Real> heights, radii;
  for (int r = 1; r < rings; ++r) {
    const Real theta = M_PI * r / rings;
    heights.push_back(radius * std::cos(theta));
    radii.push_back(radius * std::sin(theta));
  }
  TriangleMesh mesh = lathe(heights, radii, segments);
  // The fan centres sit on the end rings' planes; move them to the poles.
  mesh.vertices[mesh.num_vertices() - 2] = Vec3(0, radius, 0);
  mesh.vertices[mesh.num_vertices() - 1] = Vec3(0, -radius, 0);
  orient_outward(mesh);
  return mesh;
}

TriangleMesh cylinder_mesh(Real radius, Real height, int segments) {
  return lathe({0.5 * height, -0.5 * height}, {radius, radius}, segments);
}

TriangleMesh capsule_mesh(Real radius, Real height, int rings, int segments) {
  std::vector<Real> heights, radii;
  for (int r = 1; r <= rings; ++r) {  // upper hemisphere, pole excluded
    const Real theta = 0.5 * M_PI * r / rings;
    heights.push_back(0.5 * height + radius * std::cos(theta));
    radii.push_back(radius * std::sin(theta));
  }
  for (int r = 0; r < rings; ++r) {  // lower hemisphere, from the equator
    const Real theta = 0.5 * M_PI * r / rings;
    heights.push_back(-0.5 * height - radius * std::sin(theta));
    radii.push_back(radius * std::cos(theta));
  }
  TriangleMesh mesh = lathe(heights, radii, segments);
  mesh.vertices[mesh.num_vertices() - 2] = Vec3(0, 0.5 * height + radius, 0);
  mesh.vertices[mesh.num_vertices() - 1] = Vec3(0, -0.5 * height - radius, 0);
  orient_outward(mesh);
  return mesh;
}

}  // namespace jelly
