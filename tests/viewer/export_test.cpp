// The exports' normals, terrains and glTF, read back: OBJ vertex normals are unit and outward,
// the terrains and obstacles are written beside the bodies (a moving one per frame, where the
// recording says it was), and the .glb (read with tinygltf) holds every body's surface at every
// frame, its colour, the exact frame times and the obstacles' motion.
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <jelly/core/errors.hpp>
#include <jelly/geometry/cube.hpp>
#include <jelly/geometry/triangle_mesh.hpp>
#include <jelly/io/detail/export.hpp>
#include <jelly/io/h5_recorder.hpp>
#include <jelly/io/recording.hpp>
#include <jelly/io/scene.hpp>
#include <jelly/viewer/detail/exports.hpp>
#include <jelly/viewer/scene_adapter.hpp>

#ifdef JELLY_WITH_TINYGLTF
#include <tiny_gltf.h>
#endif

#include "viewer/viewer_support.hpp"

namespace jelly {
namespace {

using testing::TempDir;

// A coloured cube, an uncoloured cloth, the ground and a box obstacle that slides and spins,
// recorded every 0.01 s for 0.1 s (11 frames).
constexpr const char* kSceneJson = R"({
  "bodies": [
    {"kind": "cube", "name": "red", "n": 3, "edge_length": 1, "origin": [-0.5, 1, -0.5],
     "color": [0.8, 0.2, 0.1]},
    {"kind": "cloth", "name": "sheet", "nu": 4, "nv": 4, "size_u": 1, "size_v": 1,
     "position": [2, 2, 0]}
  ],
  "gravity": [0, -9.8, 0],
  "terrains": [
    {"kind": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]},
    {"kind": "box", "center": [3, 0.5, 3], "size": [1, 1, 1],
     "motion": {"kind": "oscillation", "amplitude": [0.5, 0, 0], "frequency": 1, "phase": 0},
     "angular_velocity_degrees": [0, 90, 0]}
  ],
  "integrator": {"name": "rk4", "dt": 0.001},
  "duration": 0.1,
  "output_interval": 0.01
})";

Recording record_scene(const TempDir& dir) {
  { std::ofstream(dir.file("scene.json")) << kSceneJson; }
  const Scene scene = load_scene(dir.file("scene.json"));
  Simulator sim = make_simulator(scene);
  RecorderOptions options;
  options.scene_json = scene_to_json(scene);
  options.write_xdmf = false;
  {
    H5Recorder recorder(dir.file("r.h5"), sim, options);
    sim.add_observer(recorder);
    EXPECT_TRUE(sim.run_until(0.1).ok());
  }
  return read_recording(dir.file("r.h5"));
}

Vec3 centroid(const std::vector<Vec3>& points) {
  Vec3 c = Vec3::Zero();
  for (const Vec3& p : points) c += p;
  return c / static_cast<Real>(points.size());
}

// A cube's surface normals: unit length and outward (along the vertex minus the centre), also
// after a write and a read.
TEST(ExportNormals, CubeVertexNormalsAreUnitAndOutward) {
  CubeSpec spec;
  spec.n = 4;
  const Model model = build_cube(spec);
  const auto surfaces = viewer::body_surfaces(model);
  ASSERT_EQ(surfaces.size(), 1u);
  TempDir dir;
  write_obj(dir.file("cube.obj"), viewer::surface_objects(surfaces, model.rest_position));
  const std::vector<ObjObject> read = read_obj(dir.file("cube.obj"));
  ASSERT_EQ(read.size(), 1u);
  const ObjObject& o = read[0];
  ASSERT_EQ(o.normals.size(), o.vertices.size());
  ASSERT_FALSE(o.vertices.empty());
  EXPECT_EQ(o.triangles, surfaces[0].triangles);
  const Vec3 c = centroid(o.vertices);
  for (size_t v = 0; v < o.vertices.size(); ++v) {
    EXPECT_NEAR(o.normals[v].norm(), 1.0, 1e-6) << v;
    // Corners and edges average their faces: still well within 90 degrees of the outward ray.
    EXPECT_GT(o.normals[v].dot((o.vertices[v] - c).normalized()), 0.5) << v;
  }
  // The text: "vn" lines and faces "f a//a b//b c//c".
  const std::string text = testing::read_text(dir.file("cube.obj"));
  EXPECT_NE(text.find("\nvn "), std::string::npos);
  EXPECT_NE(text.find("//"), std::string::npos);
}

// A face's vertex normal is the area-weighted mean: on a flat patch it is the patch's normal; a
// single triangle's winding decides its side.
TEST(ExportNormals, AreaWeightedAndFollowTheWinding) {
  const std::vector<Vec3> v = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
  std::vector<Vec3> n;
  vertex_normals(v, {{0, 1, 2}, {1, 3, 2}}, n);
  for (const Vec3& x : n) EXPECT_LT((x - Vec3::UnitZ()).norm(), 1e-15);
  vertex_normals(v, {{0, 2, 1}}, n);
  EXPECT_LT((n[0] + Vec3::UnitZ()).norm(), 1e-15);
  EXPECT_LT((n[3] - Vec3::UnitY()).norm(), 1e-15);  // in no triangle: +y, still unit
  // Two faces at vertex 0: the larger one weighs more.
  vertex_normals({{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0, 0, 1}}, {{0, 1, 2}, {0, 3, 1}}, n);
  // Twice the area times the unit normal, summed: 4 z (area 2) + 2 y (area 1).
  const Vec3 expected = Vec3(0, 2, 4).normalized();
  EXPECT_LT((n[0] - expected).norm(), 1e-15);
}

// A box keeps flat faces (a vertex per corner and face), a sphere stays smooth.
TEST(ExportNormals, CreaseNormalsKeepABoxFlatAndASphereSmooth) {
  const TriangleMesh box = box_mesh(Vec3(1, 2, 3));
  const ObjObject flat = crease_normals("box", box.vertices, box.triangles);
  EXPECT_EQ(flat.vertices.size(), 24u);
  for (const Triangle& t : flat.triangles) {
    const Vec3 face = (flat.vertices[t[1]] - flat.vertices[t[0]])
                          .cross(flat.vertices[t[2]] - flat.vertices[t[0]])
                          .normalized();
    for (int i : t) EXPECT_LT((flat.normals[i] - face).norm(), 1e-12);
  }
  const TriangleMesh sphere = sphere_mesh(1.0);
  const ObjObject smooth = crease_normals("sphere", sphere.vertices, sphere.triangles);
  EXPECT_LE(smooth.vertices.size(), sphere.vertices.size() + 64);  // seams at most
  for (size_t v = 0; v < smooth.vertices.size(); ++v)
    EXPECT_GT(smooth.normals[v].dot(smooth.vertices[v].normalized()), 0.99) << v;
}

// The OBJ sequence: the bodies with normals per frame, the ground as one square covering the
// bodies' motion, the moving box once per frame where the recording says its centre was.
TEST(ExportObjSequence, TerrainsAndObstaclesBesideTheBodies) {
  TempDir dir;
  const Recording rec = record_scene(dir);
  ASSERT_EQ(rec.frames(), 11);
  ASSERT_EQ(viewer::export_obj_sequence(rec, dir.file("seq")), 11);
  const std::vector<ObjObject> frame = read_obj(dir.file("seq/frame_0005.obj"));
  ASSERT_EQ(frame.size(), 2u);
  for (const ObjObject& o : frame) {
    ASSERT_EQ(o.normals.size(), o.vertices.size()) << o.name;
    for (const Vec3& n : o.normals) EXPECT_NEAR(n.norm(), 1.0, 1e-6);
  }
  const Vec3 c = centroid(frame[0].vertices);
  for (size_t v = 0; v < frame[0].vertices.size(); ++v)
    EXPECT_GT(frame[0].normals[v].dot(frame[0].vertices[v] - c), 0) << v;

  const std::vector<ObjObject> ground = read_obj(dir.file("seq/terrain_0_plane.obj"));
  ASSERT_EQ(ground.size(), 1u);
  ASSERT_EQ(ground[0].vertices.size(), 4u);
  Vec3 lo = Vec3::Constant(1e9), hi = Vec3::Constant(-1e9);
  for (const Vec3& v : ground[0].vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  EXPECT_EQ(lo.y(), 0);
  EXPECT_EQ(hi.y(), 0);
  for (const Vec3& n : ground[0].normals) EXPECT_LT((n - Vec3::UnitY()).norm(), 1e-7);
  for (const VecX& x : rec.position)
    for (Eigen::Index i = 0; i < x.size(); i += 3) {
      EXPECT_GT(x[i], lo.x());
      EXPECT_LT(x[i], hi.x());
      EXPECT_GT(x[i + 2], lo.z());
      EXPECT_LT(x[i + 2], hi.z());
    }
  EXPECT_LT(hi.x() - lo.x(), 20);  // sized to the scene, not the viewer's 150 m

  EXPECT_FALSE(std::filesystem::exists(dir.file("seq/terrain_1_box.obj")));
  ASSERT_EQ(rec.terrains.size(), 2u);
  for (int k = 0; k < rec.frames(); ++k) {
    char name[64];
    std::snprintf(name, sizeof name, "seq/terrain_1_box_%04d.obj", k);
    const std::vector<ObjObject> box = read_obj(dir.file(name));
    ASSERT_EQ(box.size(), 1u) << name;
    EXPECT_LT((centroid(box[0].vertices) - rec.terrains[1].position[k]).norm(), 1e-7) << name;
  }
  // It moved.
  EXPECT_GT((rec.terrains[1].position[10] - rec.terrains[1].position[0]).norm(), 0.1);
}

TEST(ExactFrameTimes, SumsOfStepsBecomeProducts) {
  std::vector<Real> t = {0, 0, 0};
  for (int s = 0; s < 3000; ++s) t[2] += 0.001;
  t[1] = 0.1 + 1e-15;
  ASSERT_NE(t[2], 3.0);
  EXPECT_EQ(exact_frame_times(t, 0.001, 0.1), (std::vector<Real>{0, 0.1, 30 * 0.1}));
  // An interval that is no multiple of dt: the frames fall on steps, multiples of dt.
  EXPECT_EQ(exact_frame_times({0.017000000000000005}, 0.001, 1.0 / 60),
            std::vector<Real>{17 * 0.001});
  // Every step (interval 0), and dt unknown: as recorded.
  EXPECT_EQ(exact_frame_times({0.0030000000000000001}, 0.001, 0), std::vector<Real>{3 * 0.001});
  EXPECT_EQ(exact_frame_times({0.123}, 0, 0.1), std::vector<Real>{0.123});
}

#ifdef JELLY_WITH_TINYGLTF

// The floats of accessor `index`.
const float* floats(const tinygltf::Model& m, int index) {
  const tinygltf::Accessor& a = m.accessors.at(static_cast<size_t>(index));
  EXPECT_EQ(a.componentType, TINYGLTF_COMPONENT_TYPE_FLOAT);
  const tinygltf::BufferView& v = m.bufferViews.at(static_cast<size_t>(a.bufferView));
  return reinterpret_cast<const float*>(m.buffers.at(static_cast<size_t>(v.buffer)).data.data() +
                                        v.byteOffset + a.byteOffset);
}

const tinygltf::Node& node_named(const tinygltf::Model& m, const std::string& name) {
  for (const tinygltf::Node& n : m.nodes)
    if (n.name == name) return n;
  throw std::runtime_error("no node " + name);
}

double srgb_to_linear(double c) {
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

TEST(ExportGltf, ReadBackEveryFrameColourTimeAndMotion) {
  TempDir dir;
  const Recording rec = record_scene(dir);
  const int frames = rec.frames();
  ASSERT_EQ(frames, 11);
  viewer::export_gltf(rec, dir.file("out.glb"));
  tinygltf::Model m;
  tinygltf::TinyGLTF loader;
  std::string err, warn;
  ASSERT_TRUE(loader.LoadBinaryFromFile(&m, &err, &warn, dir.file("out.glb"))) << err;
  EXPECT_TRUE(err.empty()) << err;
  EXPECT_EQ(m.asset.version, "2.0");
  ASSERT_EQ(m.scenes.size(), 1u);
  EXPECT_EQ(m.scenes[0].nodes.size(), 4u);
  ASSERT_EQ(m.animations.size(), 1u);
  const tinygltf::Animation& animation = m.animations[0];

  const auto surfaces = viewer::recording_surfaces(rec);
  ASSERT_EQ(surfaces.size(), 2u);
  int time_accessor = -1;
  for (size_t b = 0; b < surfaces.size(); ++b) {
    const viewer::BodySurface& s = surfaces[b];
    const tinygltf::Node& node = node_named(m, s.name);
    const tinygltf::Primitive& p = m.meshes.at(static_cast<size_t>(node.mesh)).primitives.at(0);
    const int nv = s.num_vertices();
    const tinygltf::Accessor& position =
        m.accessors[static_cast<size_t>(p.attributes.at("POSITION"))];
    EXPECT_EQ(position.count, static_cast<size_t>(nv));
    EXPECT_EQ(m.accessors[static_cast<size_t>(p.attributes.at("NORMAL"))].count,
              static_cast<size_t>(nv));
    EXPECT_EQ(m.accessors[static_cast<size_t>(p.indices)].count, 3 * s.triangles.size());
    ASSERT_EQ(p.targets.size(), static_cast<size_t>(frames - 1));
    // Bounds of the base (frame 0) as float.
    ASSERT_EQ(position.minValues.size(), 3u);
    for (int c = 0; c < 3; ++c) {
      float lo = 1e30f, hi = -1e30f;
      for (int v = 0; v < nv; ++v) {
        const float x = static_cast<float>(s.vertex(rec.position[0], v)[c]);
        lo = std::min(lo, x);
        hi = std::max(hi, x);
      }
      EXPECT_EQ(position.minValues[c], lo);
      EXPECT_EQ(position.maxValues[c], hi);
    }
    // Frame k is the base plus target k - 1: the recorded surface to float precision.
    const float* base = floats(m, p.attributes.at("POSITION"));
    const float* normal = floats(m, p.attributes.at("NORMAL"));
    for (int v = 0; v < nv; ++v)
      EXPECT_NEAR(Eigen::Map<const Eigen::Vector3f>(normal + 3 * v).norm(), 1.0, 1e-6);
    for (int k = 0; k < frames; ++k) {
      const float* d =
          k > 0 ? floats(m, p.targets[static_cast<size_t>(k - 1)].at("POSITION")) : nullptr;
      for (int v = 0; v < nv; ++v) {
        const Vec3 expected = s.vertex(rec.position[k], v);
        for (int c = 0; c < 3; ++c) {
          const float got = base[3 * v + c] + (d != nullptr ? d[3 * v + c] : 0.0f);
          EXPECT_NEAR(got, expected[c], 4e-7 * (1 + std::abs(expected[c])))
              << s.name << " frame " << k << " vertex " << v;
        }
      }
    }
    // The material: the body's colour (the palette's for the cloth), linear.
    const Vec3 srgb = s.color ? *s.color : viewer::palette_color(static_cast<int>(b));
    if (b == 0) {
      EXPECT_EQ(srgb, Vec3(0.8, 0.2, 0.1));
    }
    const auto& factor =
        m.materials.at(static_cast<size_t>(p.material)).pbrMetallicRoughness.baseColorFactor;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(factor[c], srgb_to_linear(srgb[c]), 1e-12);
    EXPECT_EQ(factor[3], 1.0);
    // Its weights: one-hot at target k - 1 at frame k.
    int channels = 0;
    for (const tinygltf::AnimationChannel& channel : animation.channels) {
      if (channel.target_node != &node - m.nodes.data()) continue;
      ++channels;
      EXPECT_EQ(channel.target_path, "weights");
      const tinygltf::AnimationSampler& sampler =
          animation.samplers.at(static_cast<size_t>(channel.sampler));
      EXPECT_EQ(sampler.interpolation, "LINEAR");
      time_accessor = sampler.input;
      ASSERT_EQ(m.accessors[static_cast<size_t>(sampler.output)].count,
                static_cast<size_t>(frames * (frames - 1)));
      const float* w = floats(m, sampler.output);
      for (int k = 0; k < frames; ++k)
        for (int j = 0; j < frames - 1; ++j)
          EXPECT_EQ(w[k * (frames - 1) + j], j == k - 1 ? 1.0f : 0.0f);
    }
    EXPECT_EQ(channels, 1) << s.name;
  }
  // Frame times: k x output_interval (as float), with the accessor's bounds.
  ASSERT_GE(time_accessor, 0);
  const tinygltf::Accessor& times = m.accessors[static_cast<size_t>(time_accessor)];
  ASSERT_EQ(times.count, static_cast<size_t>(frames));
  const float* t = floats(m, time_accessor);
  for (int k = 0; k < frames; ++k) EXPECT_EQ(t[k], static_cast<float>(k * 0.01)) << k;
  EXPECT_EQ(times.minValues.at(0), 0.0);
  EXPECT_EQ(times.maxValues.at(0), static_cast<float>(10 * 0.01));

  // The ground stays put; the box's node moves as the recording says.
  const tinygltf::Node& ground = node_named(m, "0_plane");
  const tinygltf::Node& box = node_named(m, "1_box");
  int box_channels = 0;
  for (const tinygltf::AnimationChannel& channel : animation.channels) {
    EXPECT_NE(channel.target_node, &ground - m.nodes.data());
    if (channel.target_node != &box - m.nodes.data()) continue;
    ++box_channels;
    const tinygltf::AnimationSampler& sampler =
        animation.samplers.at(static_cast<size_t>(channel.sampler));
    EXPECT_EQ(sampler.input, time_accessor);
    const float* out = floats(m, sampler.output);
    for (int k = 0; k < frames; ++k) {
      if (channel.target_path == "translation") {
        for (int c = 0; c < 3; ++c)
          EXPECT_NEAR(out[3 * k + c], rec.terrains[1].position[k][c], 1e-6) << k;
      } else {
        ASSERT_EQ(channel.target_path, "rotation");
        // About y at 90 degrees/s: the quaternion (0, sin(a/2), 0, cos(a/2)), a = pi/2 t.
        const double a = 0.5 * 3.14159265358979323846 * rec.time[k];
        EXPECT_NEAR(out[4 * k + 1], std::sin(a / 2), 1e-6) << k;
        EXPECT_NEAR(out[4 * k + 3], std::cos(a / 2), 1e-6) << k;
      }
    }
  }
  EXPECT_EQ(box_channels, 2);
  const tinygltf::Primitive& box_mesh = m.meshes.at(static_cast<size_t>(box.mesh)).primitives.at(0);
  EXPECT_EQ(m.accessors[static_cast<size_t>(box_mesh.attributes.at("POSITION"))].count, 24u);
}

#else

TEST(ExportGltf, ReadBackEveryFrameColourTimeAndMotion) {
  GTEST_SKIP() << "jelly was built without tinygltf";
}

#endif

// The CLI: --gltf writes, refuses an existing file without --overwrite, a name not .glb and a
// missing folder (exit 2 each), as the other exports do.
TEST(ExportGltf, CliWritesAndRefuses) {
  TempDir dir;
  record_scene(dir);
  const std::string jelly = std::string("'") + JELLY_CLI + "' export '" + dir.file("r.h5") + "' ";
  if (!viewer::gltf_available()) {
    const testing::Result r = testing::run(jelly + "--gltf '" + dir.file("a.glb") + "'", dir);
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("tinygltf"), std::string::npos) << r.err;
    return;
  }
  testing::Result r = testing::run(jelly + "--gltf '" + dir.file("a.glb") + "'", dir);
  EXPECT_EQ(r.code, 0) << r.err;
  ASSERT_TRUE(std::filesystem::exists(dir.file("a.glb")));
  const auto size = std::filesystem::file_size(dir.file("a.glb"));
  {
    std::ifstream in(dir.file("a.glb"), std::ios::binary);
    char magic[4];
    in.read(magic, 4);
    EXPECT_EQ(std::string(magic, 4), "glTF");
  }
  r = testing::run(jelly + "--gltf '" + dir.file("a.glb") + "'", dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--overwrite"), std::string::npos) << r.err;
  EXPECT_EQ(std::filesystem::file_size(dir.file("a.glb")), size);
  r = testing::run(jelly + "--gltf '" + dir.file("a.glb") + "' --overwrite", dir);
  EXPECT_EQ(r.code, 0) << r.err;
  r = testing::run(jelly + "--gltf '" + dir.file("a.gltf") + "'", dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find(".glb"), std::string::npos) << r.err;
  r = testing::run(jelly + "--gltf '" + dir.file("missing/a.glb") + "'", dir);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("missing")));
  // The recording itself is never the output.
  r = testing::run(jelly + "--gltf '" + dir.file("r.h5") + "'", dir);
  EXPECT_EQ(r.code, 2);
}

// `jelly xdmf --state` writes the sidecar and the ParaView state beside the recording, refuses to
// replace them without --overwrite (exit 2, the old files as they were), and replaces both with
// it.
TEST(XdmfState, CliWritesRefusesAndOverwrites) {
  TempDir dir;
  record_scene(dir);  // without a sidecar
  const std::string xdmf = std::string("'") + JELLY_CLI + "' xdmf '" + dir.file("r.h5") + "'";
  testing::Result r = testing::run(xdmf + " --state", dir);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("r.paraview.py"), std::string::npos) << r.out;
  const std::string state = testing::read_text(dir.file("r.paraview.py"));
  EXPECT_NE(state.find("SIDECAR = \"r.xdmf\""), std::string::npos) << state;
  EXPECT_NE(state.find("SPEED_RANGE = [0, "), std::string::npos) << state;
  { std::ofstream(dir.file("r.paraview.py")) << "old"; }
  r = testing::run(xdmf + " --state", dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--overwrite"), std::string::npos) << r.err;
  EXPECT_EQ(testing::read_text(dir.file("r.paraview.py")), "old");
  std::filesystem::remove(dir.file("r.xdmf"));  // the state alone is refused too
  r = testing::run(xdmf + " --state", dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("r.paraview.py"), std::string::npos) << r.err;
  EXPECT_EQ(testing::read_text(dir.file("r.paraview.py")), "old");
  r = testing::run(xdmf + " --state --overwrite", dir);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(testing::read_text(dir.file("r.paraview.py")), state);
}

}  // namespace
}  // namespace jelly
