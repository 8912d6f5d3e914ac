// `jelly export --gltf`: a recording as one glTF 2.0 binary (tinygltf builds and writes it).
//
// The bodies deform, so their animation is morph targets, one per frame after the first, with
// weights animated LINEAR over the frame times (frame k = target k at weight 1, the others 0).
// glTF has no per-frame vertex buffers and no node visibility in its core (KHR_node_visibility
// is newer than Blender 3.4's importer), and per-frame meshes shown by scaling nodes to zero
// would copy the triangles once per frame and give importers one object per frame. Morph
// targets import as one object whose shape keys (Blender 3.4), morphTargetInfluences (three.js)
// or blend shapes (Godot 4) play the animation. docs/output.md says what was checked.
#include <jelly/viewer/detail/exports.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <map>
#include <sstream>

#include <jelly/core/detail/file_replacement.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/version.hpp>

#ifdef JELLY_WITH_TINYGLTF
#include <tiny_gltf.h>
#endif

namespace jelly::viewer {

#ifdef JELLY_WITH_TINYGLTF

namespace {

// glTF's material colours are linear; a body's colour is sRGB.
double gltf_linear_from_srgb(double c) {
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

// Appends data to the one buffer of a tinygltf model: a buffer view per accessor, tightly packed.
class GltfBuffers {
 public:
  explicit GltfBuffers(tinygltf::Model& model) : model_(model) { model_.buffers.emplace_back(); }

  // An accessor of `count` elements of `type` (TINYGLTF_TYPE_SCALAR, _VEC3, _VEC4) over floats,
  // with min and max when `bounds` (required for positions and animation inputs).
  int floats(const std::vector<float>& data, int type, int components, bool bounds, int target) {
    tinygltf::Accessor a;
    a.bufferView = view(data.data(), data.size() * sizeof(float), target);
    a.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
    a.type = type;
    a.count = data.size() / static_cast<size_t>(components);
    if (bounds && a.count > 0) {
      a.minValues.assign(static_cast<size_t>(components), std::numeric_limits<double>::max());
      a.maxValues.assign(static_cast<size_t>(components), std::numeric_limits<double>::lowest());
      for (size_t i = 0; i < data.size(); ++i) {
        const size_t c = i % static_cast<size_t>(components);
        a.minValues[c] = std::min<double>(a.minValues[c], data[i]);
        a.maxValues[c] = std::max<double>(a.maxValues[c], data[i]);
      }
    }
    model_.accessors.push_back(std::move(a));
    return static_cast<int>(model_.accessors.size()) - 1;
  }

  int indices(const std::vector<Triangle>& triangles) {
    std::vector<std::uint32_t> data;
    data.reserve(3 * triangles.size());
    for (const Triangle& t : triangles)
      for (int i : t) data.push_back(static_cast<std::uint32_t>(i));
    tinygltf::Accessor a;
    a.bufferView = view(data.data(), data.size() * sizeof(std::uint32_t),
                        TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    a.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    a.type = TINYGLTF_TYPE_SCALAR;
    a.count = data.size();
    model_.accessors.push_back(std::move(a));
    return static_cast<int>(model_.accessors.size()) - 1;
  }

 private:
  int view(const void* bytes, size_t size, int target) {
    std::vector<unsigned char>& buffer = model_.buffers.front().data;
    tinygltf::BufferView v;
    v.buffer = 0;
    v.byteOffset = buffer.size();  // a multiple of 4: every element is 4 bytes
    v.byteLength = size;
    v.target = target;
    const auto* b = static_cast<const unsigned char*>(bytes);
    buffer.insert(buffer.end(), b, b + size);
    model_.bufferViews.push_back(v);
    return static_cast<int>(model_.bufferViews.size()) - 1;
  }

  tinygltf::Model& model_;
};

void gltf_append(std::vector<float>& out, const Vec3& v) {
  out.insert(out.end(),
             {static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z())});
}

int gltf_material(tinygltf::Model& model, const std::string& name, const Vec3& srgb) {
  tinygltf::Material m;
  m.name = name;
  m.pbrMetallicRoughness.baseColorFactor = {gltf_linear_from_srgb(srgb.x()),
                                            gltf_linear_from_srgb(srgb.y()),
                                            gltf_linear_from_srgb(srgb.z()), 1.0};
  m.pbrMetallicRoughness.metallicFactor = 0;
  m.pbrMetallicRoughness.roughnessFactor = 0.5;
  m.doubleSided = true;  // cloth and the ground's square are seen from both sides
  model.materials.push_back(std::move(m));
  return static_cast<int>(model.materials.size()) - 1;
}

}  // namespace

bool gltf_available() { return true; }

void export_gltf(const Recording& recording, const std::string& path) {
  const std::vector<BodySurface> surfaces = recording_surfaces(recording);
  int triangles = 0;
  for (const BodySurface& s : surfaces) triangles += s.num_triangles();
  if (triangles == 0 || recording.frames() == 0)
    throw InputError("recording",
                     std::to_string(recording.model.num_particles()) + " particles, " +
                         std::to_string(recording.frames()) + " frames",
                     "frames of bodies with a render surface");
  const int frames = recording.frames();
  const std::vector<Real> times = exact_frame_times(recording);

  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = std::string("jelly ") + JELLY_VERSION_STRING;
  GltfBuffers buffers(model);
  model.scenes.emplace_back();
  model.defaultScene = 0;
  tinygltf::Animation animation;
  animation.name = "jelly";

  std::vector<float> time_data;
  for (Real t : times) time_data.push_back(static_cast<float>(t));
  const int time_accessor =
      frames > 1 ? buffers.floats(time_data, TINYGLTF_TYPE_SCALAR, 1, true, 0) : -1;
  // The weights of every body's targets at every frame (all bodies have frames - 1 targets):
  // zero at frame 0, then target k - 1 alone at frame k.
  int weights_accessor = -1;
  if (frames > 1) {
    std::vector<float> w(static_cast<size_t>(frames) * static_cast<size_t>(frames - 1), 0.0f);
    for (int k = 1; k < frames; ++k)
      w[static_cast<size_t>(k) * static_cast<size_t>(frames - 1) + static_cast<size_t>(k - 1)] = 1;
    weights_accessor = buffers.floats(w, TINYGLTF_TYPE_SCALAR, 1, false, 0);
  }
  const auto add_channel = [&](int node, const char* what, int output) {
    tinygltf::AnimationSampler sampler;
    sampler.input = time_accessor;
    sampler.output = output;
    sampler.interpolation = "LINEAR";
    animation.samplers.push_back(sampler);
    tinygltf::AnimationChannel channel;
    channel.sampler = static_cast<int>(animation.samplers.size()) - 1;
    channel.target_node = node;
    channel.target_path = what;
    animation.channels.push_back(channel);
  };
  const auto add_node = [&](tinygltf::Node node) {
    model.nodes.push_back(std::move(node));
    const int index = static_cast<int>(model.nodes.size()) - 1;
    model.scenes.front().nodes.push_back(index);
    return index;
  };

  for (size_t b = 0; b < surfaces.size(); ++b) {
    const BodySurface& s = surfaces[b];
    if (s.triangles.empty()) continue;
    const int nv = s.num_vertices();
    std::vector<Vec3> first(static_cast<size_t>(nv)), now(static_cast<size_t>(nv));
    std::vector<Vec3> first_normals, normals;
    for (int v = 0; v < nv; ++v) first[static_cast<size_t>(v)] = s.vertex(recording.position[0], v);
    vertex_normals(first, s.triangles, first_normals);
    // The base as float; a target's displacement is from that float base, so base + displacement
    // is the frame's position to float rounding.
    std::vector<float> base, base_normals;
    for (const Vec3& p : first) gltf_append(base, p);
    for (const Vec3& n : first_normals) gltf_append(base_normals, n);

    tinygltf::Primitive primitive;
    primitive.mode = TINYGLTF_MODE_TRIANGLES;
    primitive.attributes["POSITION"] =
        buffers.floats(base, TINYGLTF_TYPE_VEC3, 3, true, TINYGLTF_TARGET_ARRAY_BUFFER);
    primitive.attributes["NORMAL"] =
        buffers.floats(base_normals, TINYGLTF_TYPE_VEC3, 3, false, TINYGLTF_TARGET_ARRAY_BUFFER);
    primitive.indices = buffers.indices(s.triangles);
    primitive.material =
        gltf_material(model, s.name, s.color ? *s.color : palette_color(static_cast<int>(b)));
    tinygltf::Value::Array names;
    std::vector<float> dp(base.size()), dn(base.size());
    for (int k = 1; k < frames; ++k) {
      for (int v = 0; v < nv; ++v) now[static_cast<size_t>(v)] = s.vertex(recording.position[k], v);
      vertex_normals(now, s.triangles, normals);
      for (size_t v = 0; v < now.size(); ++v)
        for (int c = 0; c < 3; ++c) {
          dp[3 * v + c] = static_cast<float>(now[v][c] - static_cast<double>(base[3 * v + c]));
          dn[3 * v + c] =
              static_cast<float>(normals[v][c] - static_cast<double>(base_normals[3 * v + c]));
        }
      std::map<std::string, int> target;
      target["POSITION"] =
          buffers.floats(dp, TINYGLTF_TYPE_VEC3, 3, true, TINYGLTF_TARGET_ARRAY_BUFFER);
      target["NORMAL"] =
          buffers.floats(dn, TINYGLTF_TYPE_VEC3, 3, false, TINYGLTF_TARGET_ARRAY_BUFFER);
      primitive.targets.push_back(std::move(target));
      char name[32];
      std::snprintf(name, sizeof name, "frame_%04d", k);
      names.emplace_back(std::string(name));
    }
    tinygltf::Mesh mesh;
    mesh.name = s.name;
    mesh.primitives.push_back(std::move(primitive));
    if (frames > 1) {
      mesh.weights.assign(static_cast<size_t>(frames - 1), 0.0);
      // Blender names the shape keys after mesh.extras.targetNames (three.js too).
      tinygltf::Value::Object extras;
      extras["targetNames"] = tinygltf::Value(std::move(names));
      mesh.extras = tinygltf::Value(std::move(extras));
    }
    model.meshes.push_back(std::move(mesh));
    tinygltf::Node node;
    node.name = s.name;
    node.mesh = static_cast<int>(model.meshes.size()) - 1;
    const int index = add_node(std::move(node));
    if (frames > 1) add_channel(index, "weights", weights_accessor);
  }

  for (const ExportTerrain& terrain : export_terrains(recording)) {
    std::vector<float> positions, normals;
    for (const Vec3& p : terrain.mesh.vertices) gltf_append(positions, p);
    for (const Vec3& n : terrain.mesh.normals) gltf_append(normals, n);
    tinygltf::Primitive primitive;
    primitive.mode = TINYGLTF_MODE_TRIANGLES;
    primitive.attributes["POSITION"] =
        buffers.floats(positions, TINYGLTF_TYPE_VEC3, 3, true, TINYGLTF_TARGET_ARRAY_BUFFER);
    primitive.attributes["NORMAL"] =
        buffers.floats(normals, TINYGLTF_TYPE_VEC3, 3, false, TINYGLTF_TARGET_ARRAY_BUFFER);
    primitive.indices = buffers.indices(terrain.mesh.triangles);
    primitive.material = gltf_material(model, terrain.mesh.name, Vec3(0.62, 0.64, 0.68));
    tinygltf::Mesh mesh;
    mesh.name = terrain.mesh.name;
    mesh.primitives.push_back(std::move(primitive));
    model.meshes.push_back(std::move(mesh));

    // Rotations as unit quaternions (x, y, z, w), each on the side of the previous one so that
    // LINEAR (spherical) interpolation takes the short way.
    std::vector<float> translation, rotation;
    Eigen::Quaterniond previous = Eigen::Quaterniond::Identity();
    for (const Eigen::Isometry3d& pose : terrain.poses) {
      gltf_append(translation, pose.translation());
      Eigen::Quaterniond q(pose.linear());
      q.normalize();
      if (q.coeffs().dot(previous.coeffs()) < 0) q.coeffs() = -q.coeffs();
      previous = q;
      rotation.insert(rotation.end(), {static_cast<float>(q.x()), static_cast<float>(q.y()),
                                       static_cast<float>(q.z()), static_cast<float>(q.w())});
    }
    tinygltf::Node node;
    node.name = terrain.mesh.name;
    node.mesh = static_cast<int>(model.meshes.size()) - 1;
    node.translation.assign(translation.begin(), translation.begin() + 3);
    node.rotation.assign(rotation.begin(), rotation.begin() + 4);
    const int index = add_node(std::move(node));
    if (terrain.moves && frames > 1) {
      add_channel(index, "translation",
                  buffers.floats(translation, TINYGLTF_TYPE_VEC3, 3, false, 0));
      add_channel(index, "rotation", buffers.floats(rotation, TINYGLTF_TYPE_VEC4, 4, false, 0));
    }
  }
  if (!animation.channels.empty()) model.animations.push_back(std::move(animation));
  model.buffers.front().name = "jelly";

  std::ostringstream out;
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToStream(&model, out, false, true))
    throw std::runtime_error("cannot write '" + path + "' (tinygltf could not encode the scene)");
  jelly::detail::replace_file(path, out.str());
}

#else  // without tinygltf

bool gltf_available() { return false; }

void export_gltf(const Recording& /*recording*/, const std::string& path) {
  throw InputError("--gltf", path,
                   "a jelly built with tinygltf (apt-get install libtinygltf-dev, then rebuild)");
}

#endif

}  // namespace jelly::viewer
