// Micro-benchmarks of the mesh bodies: voxelizing a 100,000-triangle mesh (winding-number tree,
// inside test of every lattice point, the whole body with its embedded surface), building the
// springs of a 100,000-tet mesh, and reading both kinds of file.
#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include <benchmark/benchmark.h>

#include <jelly/geometry/detail/mesh_io.hpp>
#include <jelly/geometry/detail/pose.hpp>
#include <jelly/geometry/detail/tet_mesh_io.hpp>
#include <jelly/geometry/detail/tetmesh.hpp>
#include <jelly/geometry/detail/voxelized.hpp>
#include <jelly/geometry/detail/winding_number.hpp>
#include <jelly/jelly.hpp>

namespace {

using namespace jelly;

// A closed, bumpy sphere of about 99,000 triangles with a second sphere through it (the
// overlapping parts a mesh made of primitives has): about 100,000 triangles, bounding box
// close to a cube of side 2.2.
const TriangleMesh& big_mesh() {
  static const TriangleMesh mesh = [] {
    TriangleMesh m = sphere_mesh(1, 160, 310);
    for (Vec3& v : m.vertices) {
      const Real theta = std::acos(std::clamp(v.y(), -1.0, 1.0)), phi = std::atan2(v.z(), v.x());
      v *= 1 + 0.08 * std::sin(5 * theta) * std::sin(7 * phi);
    }
    TriangleMesh inner = sphere_mesh(0.5, 16, 32);
    for (Vec3& v : inner.vertices) v += Vec3(0.6, 0, 0);
    m.append(inner);
    return m;
  }();
  return mesh;
}

// The spacing that puts `points` lattice points along the longest side of the box.
Real spacing_for(const TriangleMesh& mesh, int points) {
  return mesh.bounds().diagonal().maxCoeff() / (points - 1) * (1 + 1e-9);
}

void BM_WindingNumberTree(benchmark::State& bench) {
  const TriangleMesh& mesh = big_mesh();
  for (auto _ : bench) {
    WindingNumber w(mesh);
    benchmark::DoNotOptimize(&w);
  }
  bench.counters["triangles"] = mesh.num_triangles();
}
BENCHMARK(BM_WindingNumberTree)->Unit(benchmark::kMillisecond);

// voxelize(): the tree plus the inside test of every lattice point.
void BM_Voxelize(benchmark::State& bench) {
  const TriangleMesh& mesh = big_mesh();
  const Real h = spacing_for(mesh, static_cast<int>(bench.range(0)));
  long inside = 0, points = 0;
  for (auto _ : bench) {
    const LatticeGrid grid = voxelize(mesh, h);
    inside = 0;
    for (char c : grid.occupied) inside += c;
    points = grid.points();
  }
  bench.counters["triangles"] = mesh.num_triangles();
  bench.counters["lattice_points"] = static_cast<double>(points);
  bench.counters["inside"] = static_cast<double>(inside);
}
BENCHMARK(BM_Voxelize)->Arg(30)->Arg(60)->Unit(benchmark::kMillisecond);

// The whole body: voxelize, lattice particles and springs, the mesh embedded as its surface.
void BM_BuildVoxelized(benchmark::State& bench) {
  const TriangleMesh& mesh = big_mesh();
  const Real h = spacing_for(mesh, static_cast<int>(bench.range(0)));
  int particles = 0, springs = 0;
  for (auto _ : bench) {
    const BodyPart part = build_voxelized(mesh, {}, h, Pose{}, Material{}, "");
    particles = part.num_particles();
    springs = part.springs.size();
  }
  bench.counters["particles"] = particles;
  bench.counters["springs"] = springs;
  bench.counters["surface_vertices"] = mesh.num_vertices();
}
BENCHMARK(BM_BuildVoxelized)->Arg(30)->Unit(benchmark::kMillisecond);

// A box of nx x ny x nz cubes, each split into 6 tets around its diagonal: 6 nx ny nz tets
// (25 x 25 x 27 cubes: 101,250 tets).
const TetMesh& big_tet_mesh() {
  static const TetMesh mesh = [] {
    const int nx = 25, ny = 25, nz = 27;
    TetMesh m;
    const auto id = [&](int i, int j, int k) { return (i * (ny + 1) + j) * (nz + 1) + k; };
    for (int i = 0; i <= nx; ++i)
      for (int j = 0; j <= ny; ++j)
        for (int k = 0; k <= nz; ++k) m.vertices.emplace_back(0.1 * i, 0.1 * j, 0.1 * k);
    const int axes[6][3] = {{1, 2, 4}, {1, 4, 2}, {2, 1, 4}, {2, 4, 1}, {4, 1, 2}, {4, 2, 1}};
    for (int i = 0; i < nx; ++i)
      for (int j = 0; j < ny; ++j)
        for (int k = 0; k < nz; ++k) {
          const auto corner = [&](int c) {
            return id(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1));
          };
          for (const auto& a : axes) {
            m.tets.push_back({corner(0), corner(a[0]), corner(a[0] + a[1]), corner(7)});
          }
        }
    return m;
  }();
  return mesh;
}

void BM_TetEdges(benchmark::State& bench) {
  const TetMesh& mesh = big_tet_mesh();
  std::size_t edges = 0;
  for (auto _ : bench) edges = tet_edges(mesh.tets).size();
  bench.counters["tets"] = mesh.num_tets();
  bench.counters["edges"] = static_cast<double>(edges);
}
BENCHMARK(BM_TetEdges)->Unit(benchmark::kMillisecond);

// The whole body: springs along the unique edges, lumped masses, boundary surface.
void BM_BuildTetmesh(benchmark::State& bench) {
  const TetMesh& mesh = big_tet_mesh();
  Material material;
  material.density = 1000;
  int springs = 0, triangles = 0;
  for (auto _ : bench) {
    const BodyPart part = build_tetmesh(mesh, Pose{}, material, "");
    springs = part.springs.size();
    triangles = part.surface.num_triangles();
  }
  bench.counters["tets"] = mesh.num_tets();
  bench.counters["springs"] = springs;
  bench.counters["boundary_triangles"] = triangles;
}
BENCHMARK(BM_BuildTetmesh)->Unit(benchmark::kMillisecond);

std::string temp_file(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("jelly_geometry_benchmark_" + name)).string();
}

void BM_ReadMesh(benchmark::State& bench, const char* extension) {
  const std::string path = temp_file(std::string("mesh") + extension);
  write_mesh(path, big_mesh());
  for (auto _ : bench) {
    const MeshFile m = read_mesh(path, "file");
    benchmark::DoNotOptimize(m.mesh.triangles.data());
  }
  std::filesystem::remove(path);
  bench.counters["triangles"] = big_mesh().num_triangles();
}
BENCHMARK_CAPTURE(BM_ReadMesh, obj, ".obj")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ReadMesh, stl, ".stl")->Unit(benchmark::kMillisecond);

void BM_ReadMsh(benchmark::State& bench) {
  const std::string path = temp_file("tets.msh");
  write_msh(path, big_tet_mesh());
  for (auto _ : bench) {
    const TetMesh m = read_tet_mesh(path, "file");
    benchmark::DoNotOptimize(m.tets.data());
  }
  std::filesystem::remove(path);
  bench.counters["tets"] = big_tet_mesh().num_tets();
}
BENCHMARK(BM_ReadMsh)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
