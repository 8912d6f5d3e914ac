#include <jelly/io/h5_recorder.hpp>

#include <unistd.h>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <mutex>
#include <sstream>
#include <vector>

#include <jelly/core/detail/file_replacement.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/core/types.hpp>
#include <jelly/io/detail/h5.hpp>
#include <jelly/io/detail/xdmf_h5.hpp>
#include <jelly/io/recording.hpp>

namespace jelly {

void XdmfOptions::validate() const {
  require(compression_level >= 0 && compression_level <= 9, "xdmf.compression_level",
          compression_level, "an integer in 0..9 (0 = off)");
}

namespace {

using h5::check;
using h5::Handle;
using h5::member_names;

constexpr long kLayoutVersion = 2;    // of /xdmf; a group of another version is rebuilt
constexpr hsize_t kBlockFrames = 32;  // frames read and derived at a time, at most
// ... and at most this many bytes of them: a large body's blocks hold fewer frames, so that the
// derived arrays never dominate a recorded run's peak memory.
constexpr hsize_t kBlockBytes = hsize_t{16} << 20;

// Frames per pass for frames of `frame_bytes` bytes: kBlockFrames, fewer for large frames, >= 1.
hsize_t frames_per_pass(hsize_t frame_bytes) {
  return std::max<hsize_t>(1,
                           std::min(kBlockFrames, kBlockBytes / std::max<hsize_t>(frame_bytes, 1)));
}
// Strain is stored to 5 decimals (HDF5 scale-offset, lossy: |error| < 1e-5, invisible in a
// colour map), which halves its size; speed is stored as computed (float32).
constexpr int kStrainDigits = 5;

// ---------------------------------------------------------------------------------------------
// HDF5 helpers

bool is_group(hid_t parent, const std::string& name) {
  if (H5Lexists(parent, name.c_str(), H5P_DEFAULT) <= 0) return false;
  Handle object(H5Oopen(parent, name.c_str(), H5P_DEFAULT));
  return object.valid() && H5Iget_type(object.get()) == H5I_GROUP;
}

Handle open_or_create_group(hid_t parent, const std::string& name) {
  if (H5Lexists(parent, name.c_str(), H5P_DEFAULT) > 0) return h5::open_group(parent, name);
  return h5::create_group(parent, name);
}

void remove_link(hid_t parent, const std::string& name) {
  if (H5Lexists(parent, name.c_str(), H5P_DEFAULT) > 0) {
    check(H5Ldelete(parent, name.c_str(), H5P_DEFAULT), "delete " + name);
  }
}

// The XDMF NumberType and Precision of a dataset's type.
struct NumberType {
  std::string name = "Float";
  int precision = 8;
};

NumberType number_type(hid_t dataset) {
  Handle type(H5Dget_type(dataset), "dataset type");
  NumberType result;
  result.precision = static_cast<int>(H5Tget_size(type.get()));
  if (H5Tget_class(type.get()) == H5T_INTEGER) {
    result.name = H5Tget_sign(type.get()) == H5T_SGN_NONE ? "UInt" : "Int";
  }
  return result;
}

// Rows [first, first + count) of a dataset [T][...], converted to `memory_type`.
template <typename T>
std::vector<T> read_rows(hid_t dataset, hsize_t first, hsize_t count, hid_t memory_type) {
  std::vector<hsize_t> dims = h5::dataset_dims(dataset), start(dims.size(), 0);
  start[0] = first;
  dims[0] = count;
  hsize_t size = 1;
  for (hsize_t d : dims) size *= d;
  std::vector<T> values(size);
  if (size == 0) return values;
  Handle file_space(H5Dget_space(dataset), "dataset space");
  check(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start.data(), nullptr, dims.data(),
                            nullptr),
        "select rows");
  Handle memory_space(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr),
                      "memory space");
  check(H5Dread(dataset, memory_type, memory_space.get(), file_space.get(), H5P_DEFAULT,
                values.data()),
        "read rows");
  return values;
}

// An extendible dataset [T][shape...] of `file_type`, opened when it exists, else created
// (chunked by about 64 KB of frames, shuffled and deflated at `level` > 0; with `digits` > 0
// rounded to that many decimals by HDF5's scale-offset filter instead of shuffled).
Handle series(hid_t parent, const std::string& name, hid_t file_type,
              const std::vector<hsize_t>& shape, int level, int digits = 0) {
  if (H5Lexists(parent, name.c_str(), H5P_DEFAULT) > 0) return h5::open_dataset(parent, name);
  std::vector<hsize_t> dims{0}, max_dims{H5S_UNLIMITED}, chunk{1};
  size_t row_bytes = H5Tget_size(file_type);
  for (hsize_t d : shape) {
    dims.push_back(d);
    max_dims.push_back(d);
    chunk.push_back(std::max<hsize_t>(d, 1));
    row_bytes *= std::max<hsize_t>(d, 1);
  }
  chunk[0] = std::max<hsize_t>(1, (hsize_t{1} << 16) / row_bytes);
  Handle space(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), max_dims.data()),
               "dataspace for " + name);
  Handle properties(H5Pcreate(H5P_DATASET_CREATE), "dataset properties");
  check(H5Pset_chunk(properties.get(), static_cast<int>(chunk.size()), chunk.data()),
        "chunk " + name);
  if (digits > 0) {
    check(H5Pset_scaleoffset(properties.get(), H5Z_SO_FLOAT_DSCALE, digits), "round " + name);
  } else if (level > 0) {
    check(H5Pset_shuffle(properties.get()), "shuffle " + name);
  }
  if (level > 0) {
    check(H5Pset_deflate(properties.get(), static_cast<unsigned>(level)), "deflate " + name);
  }
  return Handle(H5Dcreate2(parent, name.c_str(), file_type, space.get(), H5P_DEFAULT,
                           properties.get(), H5P_DEFAULT),
                "create dataset " + name);
}

// Writes rows [first, first + count) of a series, extending it to hold them.
void write_rows(hid_t dataset, hsize_t first, hsize_t count, hid_t memory_type, const void* data) {
  if (count == 0) return;
  std::vector<hsize_t> dims = h5::dataset_dims(dataset), start(dims.size(), 0);
  if (dims[0] < first + count) {
    dims[0] = first + count;
    check(H5Dset_extent(dataset, dims.data()), "extend dataset");
  }
  start[0] = first;
  dims[0] = count;
  Handle file_space(H5Dget_space(dataset), "dataset space");
  check(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start.data(), nullptr, dims.data(),
                            nullptr),
        "select rows");
  Handle memory_space(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr),
                      "memory space");
  check(H5Dwrite(dataset, memory_type, memory_space.get(), file_space.get(), H5P_DEFAULT, data),
        "write rows");
}

// A fixed-size dataset, written over when it exists with these dimensions, else (re)created.
void put_dataset(hid_t parent, const std::string& name, hid_t file_type, hid_t memory_type,
                 const std::vector<hsize_t>& dims, const void* data) {
  if (H5Lexists(parent, name.c_str(), H5P_DEFAULT) > 0) {
    Handle dataset = h5::open_dataset(parent, name);
    if (h5::dataset_dims(dataset.get()) == dims) {
      check(H5Dwrite(dataset.get(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data),
            "write " + name);
      return;
    }
    dataset.reset();
    remove_link(parent, name);
  }
  h5::write_dataset(parent, name, file_type, memory_type, dims, data);
}

// `name` in `group`: a virtual dataset viewing row `frame` of the dataset [T][...] at
// `source_path` in the same file (HDF5 resolves the source file "." to the file that holds the
// view, wherever it was moved).
void create_view(hid_t group, const std::string& name, hid_t source, const std::string& source_path,
                 hsize_t frame) {
  if (H5Lexists(group, name.c_str(), H5P_DEFAULT) > 0) return;
  const std::vector<hsize_t> source_dims = h5::dataset_dims(source);
  const std::vector<hsize_t> view_dims(source_dims.begin() + 1, source_dims.end());
  std::vector<hsize_t> start(source_dims.size(), 0), count = source_dims;
  start[0] = frame;
  count[0] = 1;
  Handle source_space(
      H5Screate_simple(static_cast<int>(source_dims.size()), source_dims.data(), nullptr),
      "source space");
  check(H5Sselect_hyperslab(source_space.get(), H5S_SELECT_SET, start.data(), nullptr, count.data(),
                            nullptr),
        "select frame");
  Handle view_space(H5Screate_simple(static_cast<int>(view_dims.size()), view_dims.data(), nullptr),
                    "view space");
  Handle properties(H5Pcreate(H5P_DATASET_CREATE), "view properties");
  check(H5Pset_virtual(properties.get(), view_space.get(), ".", source_path.c_str(),
                       source_space.get()),
        "map view " + name);
  Handle type(H5Dget_type(source), "source type");
  Handle view(H5Dcreate2(group, name.c_str(), type.get(), view_space.get(), H5P_DEFAULT,
                         properties.get(), H5P_DEFAULT),
              "create view " + name);
}

// ---------------------------------------------------------------------------------------------
// What the recording holds

struct RecordedBody {
  std::string name;              // group /particles/<name>
  hsize_t first = 0, count = 0;  // its particles' global indices
  std::vector<hsize_t> springs;  // global indices of its springs (both ends are its particles)
  bool all_springs = false;      // first == 0 and it has every spring: /connectivity serves as is
  // Its render surface (/particles/<name>/surface), when the recording holds one: vertex v is
  // sum over k in [offsets[v], offsets[v+1]) of weights[k] * x[particles[k]] (body-local).
  bool surface = false;
  hsize_t surface_vertices = 0;
  std::vector<int> offsets, particles;
  std::vector<double> weights;
  // Its colour (the group's attribute color: sRGB r g b in [0, 1]), when the scene gave one.
  std::vector<double> color;
  std::string group() const { return "/particles/" + name; }
};

struct TerrainInfo {
  std::string name, kind;      // group /terrain/<name>, attribute kind
  std::vector<Vec3> position;  // Terrain::position(t) of every frame
  // Terrain::pose(t).linear() of every frame (identity in recordings made before it was
  // recorded): a vertex v of the mesh is at rotation * v + position.
  std::vector<Eigen::Matrix3d> rotation;
  Vec3 normal = Vec3::UnitY();
  double size_x = 0, size_z = 0, thickness = 0;
  // Its drawing in its own frame (/terrain/<name>/mesh: Terrain::render_mesh()), placed at the
  // recorded position; absent from recordings made before it was recorded.
  std::vector<Vec3> mesh_vertices;
  std::vector<std::array<int, 3>> mesh_triangles;
  bool moving = false;
};

struct Observable {
  std::string name;
  hsize_t width = 1;           // 1 (scalar) or 3 (vector)
  std::vector<double> values;  // frames x width
};

struct RecordingLayout {
  std::string h5_name;  // the file name as the sidecar names it (it sits beside the file)
  hsize_t frames = 0;
  std::vector<double> time;
  std::vector<RecordedBody> bodies;
  hsize_t num_springs = 0;
  std::vector<TerrainInfo> terrains;
  std::vector<Observable> observables;
};

[[noreturn]] void not_a_recording(const std::string& path, const std::string& why) {
  throw InputError("'" + path + "' is not a jelly recording: " + why);
}

hsize_t frames_of(hid_t file, const std::string& path) {
  Handle dataset = h5::open_dataset(file, path);
  return h5::dataset_dims(dataset.get()).at(0);
}

// The body's render surface, checked (a triangle naming a vertex that is not there would crash
// ParaView's readers); none when the recording holds none (recordings made before surfaces).
void read_surface(hid_t file, const std::string& h5_path, RecordedBody& body) {
  const std::string g = body.group() + "/surface";
  if (!h5::exists(file, g + "/triangles") || !h5::exists(file, g + "/position/value")) return;
  const auto bad = [&](const std::string& why) { not_a_recording(h5_path, g + ": " + why); };
  std::vector<hsize_t> triangle_dims, position_dims;
  const std::vector<int> triangles = h5::read_ints(file, g + "/triangles", &triangle_dims);
  {
    Handle position = h5::open_dataset(file, g + "/position/value");
    position_dims = h5::dataset_dims(position.get());
  }
  if (triangle_dims.size() != 2 || triangle_dims[1] != 3) bad("triangles is not [F][3]");
  if (position_dims.size() != 3 || position_dims[2] != 3) bad("position/value is not [T][V][3]");
  const hsize_t v = position_dims[1];
  if (triangle_dims[0] == 0 || v == 0) return;  // nothing to draw
  for (const int t : triangles) {
    if (t < 0 || static_cast<hsize_t>(t) >= v) {
      bad("triangles names vertex " + std::to_string(t) + " of " + std::to_string(v));
    }
  }
  body.offsets = h5::read_ints(file, g + "/vertex_offsets");
  body.particles = h5::read_ints(file, g + "/vertex_particles");
  body.weights = h5::read_doubles(file, g + "/vertex_weights");
  if (body.offsets.size() != v + 1 || body.offsets.front() != 0 ||
      body.offsets.back() != static_cast<int>(body.particles.size()) ||
      body.weights.size() != body.particles.size()) {
    bad("vertex_offsets, vertex_particles and vertex_weights do not describe " + std::to_string(v) +
        " vertices");
  }
  for (size_t k = 0; k + 1 < body.offsets.size(); ++k) {
    if (body.offsets[k] > body.offsets[k + 1]) bad("vertex_offsets decrease");
  }
  for (const int p : body.particles) {
    if (p < 0 || static_cast<hsize_t>(p) >= body.count) {
      bad("vertex_particles names particle " + std::to_string(p) + " of " +
          std::to_string(body.count));
    }
  }
  body.surface = true;
  body.surface_vertices = v;
}

RecordingLayout inspect(hid_t file, const std::string& h5_path) {
  RecordingLayout r;
  const size_t slash = h5_path.find_last_of('/');
  r.h5_name = slash == std::string::npos ? h5_path : h5_path.substr(slash + 1);
  if (!is_group(file, "particles")) not_a_recording(h5_path, "no /particles group");

  // Bodies: the groups under /particles, in the order of their particles. The attribute
  // first_particle gives that order; without it the bodies follow one another in name order.
  {
    Handle particles = h5::open_group(file, "particles");
    hsize_t next = 0;
    for (const std::string& name : member_names(particles.get())) {
      if (!is_group(particles.get(), name)) continue;
      RecordedBody body;
      body.name = name;
      if (!h5::exists(file, body.group() + "/position/value") ||
          !h5::exists(file, body.group() + "/velocity/value") ||
          !h5::exists(file, body.group() + "/mass")) {
        not_a_recording(h5_path, body.group() + " has no mass, position or velocity");
      }
      Handle mass = h5::open_dataset(file, body.group() + "/mass");
      body.count = h5::dataset_dims(mass.get()).at(0);
      Handle group = h5::open_group(file, body.group());
      body.first =
          h5::has_attribute(group.get(), "first_particle")
              ? static_cast<hsize_t>(h5::read_long_attribute(group.get(), "first_particle"))
              : next;
      next = body.first + body.count;
      for (const auto& [key, text] : h5::read_attributes_as_text(group.get())) {
        if (key != "color") continue;
        std::istringstream in(text);
        double c = 0;
        while (in >> c) body.color.push_back(c);
        if (body.color.size() != 3) body.color.clear();  // not an [r, g, b]: left out
      }
      read_surface(file, h5_path, body);
      r.bodies.push_back(std::move(body));
    }
  }
  if (r.bodies.empty()) not_a_recording(h5_path, "no body under /particles");
  std::sort(r.bodies.begin(), r.bodies.end(),
            [](const RecordedBody& a, const RecordedBody& b) { return a.first < b.first; });

  // The clock and the frames every series holds (a killed run may have flushed one series
  // further than another).
  r.time = h5::read_doubles(file, r.bodies.front().group() + "/position/time");
  r.frames = r.time.size();
  for (const RecordedBody& body : r.bodies) {
    r.frames = std::min({r.frames, frames_of(file, body.group() + "/position/value"),
                         frames_of(file, body.group() + "/velocity/value")});
    if (body.surface) {
      r.frames = std::min(r.frames, frames_of(file, body.group() + "/surface/position/value"));
    }
  }

  // Springs: each belongs to the body that holds its first particle.
  std::vector<hsize_t> spring_dims;
  const std::vector<int> ends = h5::read_ints(file, "/connectivity/springs", &spring_dims);
  r.num_springs = spring_dims.empty() ? 0 : spring_dims[0];
  for (hsize_t s = 0; s < r.num_springs; ++s) {
    const hsize_t a = static_cast<hsize_t>(ends[2 * s]), b = static_cast<hsize_t>(ends[2 * s + 1]);
    auto owner = std::find_if(r.bodies.begin(), r.bodies.end(), [&](const RecordedBody& body) {
      return a >= body.first && a < body.first + body.count;
    });
    if (owner == r.bodies.end() || b < owner->first || b >= owner->first + owner->count) {
      not_a_recording(h5_path, "spring " + std::to_string(s) + " joins particles " +
                                   std::to_string(a) + " and " + std::to_string(b) +
                                   " that are not both in one body");
    }
    owner->springs.push_back(s);
  }
  for (RecordedBody& body : r.bodies) {
    body.all_springs = body.first == 0 && body.springs.size() == r.num_springs;
  }

  if (is_group(file, "observables")) {
    Handle group = h5::open_group(file, "observables");
    for (const std::string& name : member_names(group.get())) {
      if (!h5::exists(group.get(), name + "/value")) continue;
      Observable o;
      o.name = name;
      std::vector<hsize_t> dims;
      o.values = h5::read_doubles(group.get(), name + "/value", &dims);
      o.width = dims.size() > 1 ? dims[1] : 1;
      r.frames = std::min(r.frames, dims.at(0));
      r.observables.push_back(std::move(o));
    }
  }

  if (is_group(file, "terrain")) {
    Handle group = h5::open_group(file, "terrain");
    for (const std::string& name : member_names(group.get())) {
      if (!h5::exists(group.get(), name + "/position/value")) continue;
      Handle t = h5::open_group(group.get(), name);
      TerrainInfo info;
      info.name = name;
      info.kind = h5::has_attribute(t.get(), "kind") ? h5::read_string_attribute(t.get(), "kind")
                                                     : std::string();
      std::vector<hsize_t> dims;
      const std::vector<double> p = h5::read_doubles(group.get(), name + "/position/value", &dims);
      r.frames = std::min(r.frames, dims.at(0));
      for (hsize_t f = 0; f < dims[0]; ++f)
        info.position.emplace_back(p[3 * f], p[3 * f + 1], p[3 * f + 2]);
      if (h5::exists(group.get(), name + "/rotation/value")) {
        std::vector<hsize_t> rotation_dims;
        const std::vector<double> m =
            h5::read_doubles(group.get(), name + "/rotation/value", &rotation_dims);
        if (rotation_dims.size() != 3 || rotation_dims[1] != 3 || rotation_dims[2] != 3) {
          not_a_recording(h5_path, "/terrain/" + name + "/rotation/value is not [T][3][3]");
        }
        r.frames = std::min(r.frames, rotation_dims[0]);
        for (hsize_t f = 0; f < rotation_dims[0]; ++f) {
          info.rotation.emplace_back(
              Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(m.data() + 9 * f));
        }
      }
      for (const auto& [key, value] : h5::read_attributes_as_text(t.get())) {
        std::istringstream in(value);
        if (key == "normal") in >> info.normal.x() >> info.normal.y() >> info.normal.z();
        if (key == "size_x") in >> info.size_x;
        if (key == "size_z") in >> info.size_z;
        if (key == "thickness") in >> info.thickness;
      }
      if (h5::exists(group.get(), name + "/mesh/vertices") &&
          h5::exists(group.get(), name + "/mesh/triangles")) {
        std::vector<hsize_t> vertex_dims, triangle_dims;
        const std::vector<double> v =
            h5::read_doubles(group.get(), name + "/mesh/vertices", &vertex_dims);
        const std::vector<int> f =
            h5::read_ints(group.get(), name + "/mesh/triangles", &triangle_dims);
        if (vertex_dims.size() != 2 || vertex_dims[1] != 3 || triangle_dims.size() != 2 ||
            triangle_dims[1] != 3) {
          not_a_recording(h5_path, "/terrain/" + name + "/mesh is not [V][3] and [F][3]");
        }
        for (size_t k = 0; k + 2 < v.size(); k += 3)
          info.mesh_vertices.emplace_back(v[k], v[k + 1], v[k + 2]);
        for (size_t k = 0; k + 2 < f.size(); k += 3) {
          for (int c = 0; c < 3; ++c) {
            if (f[k + c] < 0 || static_cast<size_t>(f[k + c]) >= info.mesh_vertices.size()) {
              not_a_recording(h5_path, "/terrain/" + name + "/mesh/triangles names vertex " +
                                           std::to_string(f[k + c]) + " of " +
                                           std::to_string(info.mesh_vertices.size()));
            }
          }
          info.mesh_triangles.push_back({f[k], f[k + 1], f[k + 2]});
        }
      }
      r.terrains.push_back(std::move(info));
    }
    // "<index>_<kind>" names in index order (name order would put 10_ before 2_).
    std::stable_sort(r.terrains.begin(), r.terrains.end(),
                     [](const TerrainInfo& a, const TerrainInfo& b) {
                       return std::atol(a.name.c_str()) < std::atol(b.name.c_str());
                     });
  }

  r.time.resize(r.frames);
  // The frames' exact times (k x output_interval, not the sum of the steps): the sidecar's
  // <Time> values, and what ParaView shows as the time.
  if (is_group(file, "parameters")) {
    Handle par = h5::open_group(file, "parameters");
    const auto number = [&](const char* name) {
      return h5::has_attribute(par.get(), name) ? h5::read_double_attribute(par.get(), name) : 0.0;
    };
    r.time = exact_frame_times(r.time, number("dt"), number("output_interval"));
  }
  for (TerrainInfo& t : r.terrains) {
    t.position.resize(r.frames);
    t.rotation.resize(r.frames, Eigen::Matrix3d::Identity());
    for (hsize_t f = 0; f < r.frames; ++f) {
      t.moving =
          t.moving || t.position[f] != t.position.front() || t.rotation[f] != t.rotation.front();
    }
  }
  return r;
}

// ---------------------------------------------------------------------------------------------
// /xdmf: views and derived arrays

std::string body_path(const RecordedBody& body) { return "/xdmf/particles/" + body.name; }
// The block of a body's surface beside the block of its particles and springs.
std::string surface_grid_name(const RecordedBody& body) { return body.name + " surface"; }
std::string terrain_path(const TerrainInfo& t) { return "/xdmf/terrain/" + t.name; }
std::string surface_path(const RecordedBody& body) { return body_path(body) + "/surface"; }

struct Bounds {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = Vec3::Constant(-std::numeric_limits<double>::infinity());
  bool empty() const { return !(lo.x() <= hi.x()); }
  void add(const Vec3& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
};

// The body's springs as the sidecar reads them: /connectivity itself, or (for one body of
// several) its own copies with particle indices counted from its first particle.
void write_body_springs(hid_t file, const RecordedBody& body, hid_t group) {
  if (body.all_springs) return;
  const std::vector<int> ends = h5::read_ints(file, "/connectivity/springs");
  const hsize_t m = body.springs.size();
  std::vector<int> local(2 * m), type(m);
  std::vector<double> rest(m), ks(m), kd(m);
  const std::vector<int> all_type = h5::read_ints(file, "/connectivity/type");
  const std::vector<double> all_rest = h5::read_doubles(file, "/connectivity/rest_length");
  const std::vector<double> all_ks = h5::read_doubles(file, "/connectivity/ks");
  const std::vector<double> all_kd = h5::read_doubles(file, "/connectivity/kd");
  for (hsize_t i = 0; i < m; ++i) {
    const hsize_t s = body.springs[i];
    local[2 * i] = ends[2 * s] - static_cast<int>(body.first);
    local[2 * i + 1] = ends[2 * s + 1] - static_cast<int>(body.first);
    type[i] = all_type[s];
    rest[i] = all_rest[s];
    ks[i] = all_ks[s];
    kd[i] = all_kd[s];
  }
  put_dataset(group, "springs", H5T_STD_I32LE, H5T_NATIVE_INT, {m, 2}, local.data());
  put_dataset(group, "type", H5T_STD_I32LE, H5T_NATIVE_INT, {m}, type.data());
  put_dataset(group, "rest_length", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {m}, rest.data());
  put_dataset(group, "ks", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {m}, ks.data());
  put_dataset(group, "kd", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {m}, kd.data());
}

// Speed and strain of the frames not derived yet, the views of every new frame, and the
// bounding box of the positions read.
void update_body(hid_t file, const RecordingLayout& r, const RecordedBody& body,
                 hsize_t first_new_view, const XdmfOptions& options, Bounds& bounds) {
  Handle group = open_or_create_group(file, body_path(body));
  write_body_springs(file, body, group.get());
  const hsize_t n = body.count, m = body.springs.size();
  const std::string position_path = body.group() + "/position/value";
  const std::string velocity_path = body.group() + "/velocity/value";
  Handle position = h5::open_dataset(file, position_path);
  Handle velocity = h5::open_dataset(file, velocity_path);
  Handle speed = series(group.get(), "speed", H5T_IEEE_F32LE, {n}, options.compression_level);
  Handle strain;
  if (options.strain) {
    strain = series(group.get(), "strain", H5T_IEEE_F32LE, {m}, options.compression_level,
                    kStrainDigits);
  }
  const hsize_t speed_done = std::min(r.frames, h5::dataset_dims(speed.get())[0]);
  const hsize_t strain_done =
      options.strain ? std::min(r.frames, h5::dataset_dims(strain.get())[0]) : r.frames;

  // Springs in body-local indices, with their rest lengths.
  std::vector<int> ends;
  std::vector<double> rest;
  if (options.strain && strain_done < r.frames) {
    const std::string springs_path = body.all_springs ? "/connectivity" : body_path(body);
    ends = h5::read_ints(file, springs_path + "/springs");
    rest = h5::read_doubles(file, springs_path + "/rest_length");
  }

  // Positions are read for the bounding box of every new frame (terrain meshes are sized by it).
  const hsize_t from = std::min({speed_done, strain_done, first_new_view});
  std::vector<float> speed_rows, strain_rows;
  // Per frame: positions and velocities read (doubles), speeds and strains derived (floats).
  const hsize_t pass = frames_per_pass(48 * n + 4 * n + (options.strain ? 4 * m : 0));
  for (hsize_t f0 = from; f0 < r.frames; f0 += pass) {
    const hsize_t count = std::min(pass, r.frames - f0);
    const std::vector<double> x = read_rows<double>(position.get(), f0, count, H5T_NATIVE_DOUBLE);
    for (hsize_t k = 0; k < count * n; ++k) bounds.add(Vec3(x[3 * k], x[3 * k + 1], x[3 * k + 2]));
    if (f0 + count > speed_done) {
      const hsize_t start = std::max(f0, speed_done);
      const std::vector<double> v =
          read_rows<double>(velocity.get(), start, f0 + count - start, H5T_NATIVE_DOUBLE);
      speed_rows.resize(v.size() / 3);
      for (size_t k = 0; k < speed_rows.size(); ++k) {
        speed_rows[k] = static_cast<float>(std::sqrt(
            v[3 * k] * v[3 * k] + v[3 * k + 1] * v[3 * k + 1] + v[3 * k + 2] * v[3 * k + 2]));
      }
      write_rows(speed.get(), start, f0 + count - start, H5T_NATIVE_FLOAT, speed_rows.data());
    }
    if (options.strain && f0 + count > strain_done) {
      const hsize_t start = std::max(f0, strain_done);
      strain_rows.resize((f0 + count - start) * m);
      for (hsize_t f = start; f < f0 + count; ++f) {
        const double* xf = x.data() + 3 * n * (f - f0);
        for (hsize_t s = 0; s < m; ++s) {
          const double* a = xf + 3 * ends[2 * s];
          const double* b = xf + 3 * ends[2 * s + 1];
          const double length =
              std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                        (a[2] - b[2]) * (a[2] - b[2]));
          strain_rows[(f - start) * m + s] = rest[s] > 0 ? static_cast<float>(length / rest[s] - 1)
                                                         : std::numeric_limits<float>::quiet_NaN();
        }
      }
      write_rows(strain.get(), start, f0 + count - start, H5T_NATIVE_FLOAT, strain_rows.data());
    }
  }

  Handle frame = open_or_create_group(group.get(), "frame");
  Handle position_views = open_or_create_group(frame.get(), "position");
  Handle velocity_views = open_or_create_group(frame.get(), "velocity");
  Handle speed_views = open_or_create_group(frame.get(), "speed");
  Handle strain_views;
  if (options.strain) strain_views = open_or_create_group(frame.get(), "strain");
  const std::string own = body_path(body);
  for (hsize_t f = first_new_view; f < r.frames; ++f) {
    const std::string name = std::to_string(f);
    create_view(position_views.get(), name, position.get(), position_path, f);
    create_view(velocity_views.get(), name, velocity.get(), velocity_path, f);
    create_view(speed_views.get(), name, speed.get(), own + "/speed", f);
    if (options.strain) create_view(strain_views.get(), name, strain.get(), own + "/strain", f);
  }
}

// The speed of every surface vertex for the frames not derived yet (|sum of weights times the
// velocities of its particles|), and the views of every new frame.
void update_surface(hid_t file, const RecordingLayout& r, const RecordedBody& body,
                    hsize_t first_new_view, const XdmfOptions& options) {
  if (!body.surface) return;
  Handle group = open_or_create_group(file, surface_path(body));
  const hsize_t n = body.count, vertices = body.surface_vertices;
  const std::string position_path = body.group() + "/surface/position/value";
  Handle position = h5::open_dataset(file, position_path);
  Handle velocity = h5::open_dataset(file, body.group() + "/velocity/value");
  Handle speed =
      series(group.get(), "speed", H5T_IEEE_F32LE, {vertices}, options.compression_level);
  const hsize_t done = std::min(r.frames, h5::dataset_dims(speed.get())[0]);
  std::vector<float> rows;
  const hsize_t pass = frames_per_pass(24 * n + 4 * vertices);
  for (hsize_t f0 = done; f0 < r.frames; f0 += pass) {
    const hsize_t count = std::min(pass, r.frames - f0);
    const std::vector<double> v = read_rows<double>(velocity.get(), f0, count, H5T_NATIVE_DOUBLE);
    rows.assign(count * vertices, 0.0f);
    for (hsize_t f = 0; f < count; ++f) {
      const double* vf = v.data() + 3 * n * f;
      for (hsize_t i = 0; i < vertices; ++i) {
        Vec3 u = Vec3::Zero();
        for (int k = body.offsets[i]; k < body.offsets[i + 1]; ++k) {
          const double* p = vf + 3 * body.particles[k];
          u += body.weights[k] * Vec3(p[0], p[1], p[2]);
        }
        rows[f * vertices + i] = static_cast<float>(u.norm());
      }
    }
    write_rows(speed.get(), f0, count, H5T_NATIVE_FLOAT, rows.data());
  }
  Handle frame = open_or_create_group(group.get(), "frame");
  Handle position_views = open_or_create_group(frame.get(), "position");
  Handle speed_views = open_or_create_group(frame.get(), "speed");
  for (hsize_t f = first_new_view; f < r.frames; ++f) {
    const std::string name = std::to_string(f);
    create_view(position_views.get(), name, position.get(), position_path, f);
    create_view(speed_views.get(), name, speed.get(), surface_path(body) + "/speed", f);
  }
}

// The corners of a unit square, counter-clockwise.
constexpr double kCorners[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};

struct Mesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;  // counter-clockwise seen from outside
};

// A square in the plane through `point` with normal `normal`, centred below the middle of
// `bounds` and reaching well past them (or 10 m across without bounds).
Mesh plane_mesh(const Vec3& point, const Vec3& normal, const Bounds& bounds) {
  const Vec3 n = normal.normalized();
  Vec3 middle = point;
  double half = 5;
  if (!bounds.empty()) {
    middle = 0.5 * (bounds.lo + bounds.hi);
    half = std::max(half, 0.75 * (bounds.hi - bounds.lo).norm());
  }
  const Vec3 centre = middle - n.dot(middle - point) * n;
  Eigen::Index least = 0;
  n.cwiseAbs().minCoeff(&least);
  const Vec3 u = n.cross(Vec3::Unit(least)).normalized(), v = n.cross(u);  // u x v = n
  Mesh mesh;
  for (const auto& corner : kCorners) {
    mesh.vertices.push_back(centre + half * (corner[0] * u + corner[1] * v));
  }
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  return mesh;
}

// A box whose top face is the platform: `top` its centre, size_x by size_z, `thickness` deep.
Mesh box_mesh(const Vec3& top, double size_x, double size_z, double thickness) {
  Mesh mesh;
  for (const double dy : {-thickness, 0.0}) {
    for (const auto& corner : kCorners) {
      mesh.vertices.push_back(top + Vec3(0.5 * corner[0] * size_x, dy, 0.5 * corner[1] * size_z));
    }
  }
  // Bottom 0-3, top 4-7 (x then z); outward normals.
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}, {4, 6, 5}, {4, 7, 6}, {0, 5, 1}, {0, 4, 5},
                    {1, 6, 2}, {1, 5, 6}, {2, 7, 3}, {2, 6, 7}, {3, 4, 0}, {3, 7, 4}};
  return mesh;
}

// The surface a terrain shows, where it is at frame 0; empty when the file has none for it.
Mesh terrain_mesh(const TerrainInfo& t, const Bounds& bounds) {
  if (t.position.empty()) return {};
  // A plane is infinite: drawn under wherever the bodies went, not as its recorded square.
  if (t.kind == "plane") return plane_mesh(t.position.front(), t.normal, bounds);
  if (!t.mesh_vertices.empty()) {
    Mesh mesh;
    for (const Vec3& v : t.mesh_vertices) {
      mesh.vertices.push_back(t.rotation.front() * v + t.position.front());
    }
    mesh.triangles = t.mesh_triangles;
    return mesh;
  }
  // Recordings made before the meshes were recorded.
  if (t.kind == "elevator" && t.size_x > 0 && t.size_z > 0) {
    const double thickness = t.thickness > 0 ? t.thickness : 0.1 * std::min(t.size_x, t.size_z);
    return box_mesh(t.position.front(), t.size_x, t.size_z, thickness);
  }
  return {};
}

// Where the point `at` of the terrain at frame 0 is at frame f (its rigid motion).
Vec3 placed(const TerrainInfo& t, hsize_t f, const Vec3& at) {
  return t.rotation[f] * (t.rotation.front().transpose() * (at - t.position.front())) +
         t.position[f];
}

// The terrain's mesh (and, when it moves, its vertices and speed at every frame with views).
// Returns false for a terrain the sidecar cannot draw.
bool update_terrain(hid_t file, const RecordingLayout& r, const TerrainInfo& t,
                    const Bounds& bounds) {
  const Mesh mesh = terrain_mesh(t, bounds);
  if (mesh.vertices.empty()) return false;
  Handle terrains = open_or_create_group(file, "/xdmf/terrain");
  Handle group = open_or_create_group(terrains.get(), t.name);
  if (h5::has_attribute(group.get(), "moving") &&
      (h5::read_long_attribute(group.get(), "moving") != 0) != t.moving) {
    group.reset();
    remove_link(terrains.get(), t.name);
    group = h5::create_group(terrains.get(), t.name);
  }
  h5::write_attribute(group.get(), "moving", static_cast<long>(t.moving));
  const hsize_t v = mesh.vertices.size(), faces = mesh.triangles.size();
  put_dataset(group.get(), "triangles", H5T_STD_I32LE, H5T_NATIVE_INT, {faces, 3},
              mesh.triangles.data());
  if (!t.moving) {
    put_dataset(group.get(), "vertices", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {v, 3},
                mesh.vertices.data());
    const std::vector<float> zero(v, 0.0f);
    put_dataset(group.get(), "speed", H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, {v}, zero.data());
    return true;
  }
  // Moving: the frame-0 mesh carried along by the recorded rotation and position; the speed of
  // every vertex from its positions at the frames before and after (backward difference,
  // forward at frame 0).
  Handle position = series(group.get(), "position", H5T_IEEE_F64LE, {v, 3}, 0);
  Handle speed = series(group.get(), "speed", H5T_IEEE_F32LE, {v}, 0);
  const hsize_t done =
      std::min(h5::dataset_dims(position.get())[0], h5::dataset_dims(speed.get())[0]);
  std::vector<double> xs;
  std::vector<float> speeds;
  for (hsize_t f = done; f < r.frames; ++f) {
    const hsize_t a = f > 0 ? f - 1 : 0, b = f > 0 ? f : std::min<hsize_t>(1, r.frames - 1);
    const double dt = b > a ? r.time[b] - r.time[a] : 0;
    for (const Vec3& p : mesh.vertices) {
      const Vec3 q = placed(t, f, p);
      xs.insert(xs.end(), q.data(), q.data() + 3);
      const double s = dt > 0 ? (placed(t, b, p) - placed(t, a, p)).norm() / dt : 0;
      speeds.push_back(static_cast<float>(s));
    }
  }
  write_rows(position.get(), done, r.frames - done, H5T_NATIVE_DOUBLE, xs.data());
  write_rows(speed.get(), done, r.frames - done, H5T_NATIVE_FLOAT, speeds.data());
  Handle frame = open_or_create_group(group.get(), "frame");
  Handle position_views = open_or_create_group(frame.get(), "position");
  Handle speed_views = open_or_create_group(frame.get(), "speed");
  const std::string own = terrain_path(t);
  for (hsize_t f = 0; f < r.frames; ++f) {
    create_view(position_views.get(), std::to_string(f), position.get(), own + "/position", f);
    create_view(speed_views.get(), std::to_string(f), speed.get(), own + "/speed", f);
  }
  return true;
}

// ---------------------------------------------------------------------------------------------
// The sidecar text

std::string xml_escape(const std::string& text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// A DataItem naming one whole dataset of the recording.
struct Item {
  std::string dims;  // "N 3"
  NumberType type;
  std::string path;  // in the recording
};

Item item_of(hid_t file, const std::string& path) {
  Handle dataset = h5::open_dataset(file, path);
  Item item;
  item.type = number_type(dataset.get());
  item.path = path;
  for (hsize_t d : h5::dataset_dims(dataset.get())) {
    item.dims += (item.dims.empty() ? "" : " ") + std::to_string(d);
  }
  return item;
}

// One float32 value per particle or spring (the derived arrays; the path is set per frame).
Item float32_item(hsize_t count) {
  Item item;
  item.dims = std::to_string(count);
  item.type.precision = 4;
  return item;
}

// The item viewing one frame of a series described by `series` (its dims without the first).
Item frame_item(const Item& series, const std::string& views, hsize_t frame) {
  Item item = series;
  item.path = views + "/" + std::to_string(frame);
  return item;
}

class Writer {
 public:
  explicit Writer(std::string h5_name) : h5_name_(xml_escape(std::move(h5_name))) {
    out_.precision(17);
  }

  void data_item(const Item& item, int indent) {
    out_ << std::string(indent, ' ') << "<DataItem Dimensions=\"" << item.dims << "\" NumberType=\""
         << item.type.name << "\" Precision=\"" << item.type.precision << "\" Format=\"HDF\">"
         << h5_name_ << ':' << xml_escape(item.path) << "</DataItem>\n";
  }
  void attribute(const std::string& name, const char* type, const char* center, const Item& item) {
    out_ << "        <Attribute Name=\"" << xml_escape(name) << "\" AttributeType=\"" << type
         << "\" Center=\"" << center << "\">\n";
    data_item(item, 10);
    out_ << "        </Attribute>\n";
  }
  // Field data: the values written into the sidecar.
  void field(const std::string& name, const double* values, hsize_t width) {
    out_ << "        <Attribute Name=\"" << xml_escape(name) << "\" AttributeType=\""
         << (width == 3 ? "Vector" : "Scalar") << "\" Center=\"Grid\">\n"
         << "          <DataItem Dimensions=\"" << (width == 1 ? "1" : "1 " + std::to_string(width))
         << "\" NumberType=\"Float\" Precision=\"8\" Format=\"XML\">";
    for (hsize_t k = 0; k < width; ++k) out_ << (k ? " " : "") << values[k];
    out_ << "</DataItem>\n        </Attribute>\n";
  }
  std::ostringstream& out() { return out_; }

 private:
  std::string h5_name_;
  std::ostringstream out_;
};

void body_grids(Writer& w, hid_t file, const RecordingLayout& r, const RecordedBody& body,
                bool observables, const XdmfOptions& options) {
  const std::string own = body_path(body);
  const std::string springs = body.all_springs ? "/connectivity" : own;
  const Item ends = item_of(file, springs + "/springs");
  const Item rest = item_of(file, springs + "/rest_length");
  const Item ks = item_of(file, springs + "/ks");
  const Item kd = item_of(file, springs + "/kd");
  const Item type = item_of(file, springs + "/type");
  const Item mass = item_of(file, body.group() + "/mass");
  Item xyz = item_of(file, body.group() + "/position/value");
  xyz.dims = std::to_string(body.count) + " 3";
  Item velocity = item_of(file, body.group() + "/velocity/value");
  velocity.dims = xyz.dims;
  const Item speed = float32_item(body.count);
  const Item strain = float32_item(body.springs.size());
  const std::string name = xml_escape(body.name);
  auto& out = w.out();
  out << "    <Grid Name=\"" << name << "\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (hsize_t f = 0; f < r.frames; ++f) {
    out << "      <Grid Name=\"" << name << "\" GridType=\"Uniform\">\n"
        << "        <Time Value=\"" << r.time[f] << "\"/>\n"
        << "        <Topology TopologyType=\"Polyline\" NodesPerElement=\"2\" NumberOfElements=\""
        << body.springs.size() << "\">\n";
    w.data_item(ends, 10);
    out << "        </Topology>\n        <Geometry GeometryType=\"XYZ\">\n";
    w.data_item(frame_item(xyz, own + "/frame/position", f), 10);
    out << "        </Geometry>\n";
    // speed first: the readers make the first scalar the active one, which ParaView colours by.
    w.attribute("speed", "Scalar", "Node", frame_item(speed, own + "/frame/speed", f));
    w.attribute("velocity", "Vector", "Node", frame_item(velocity, own + "/frame/velocity", f));
    w.attribute("mass", "Scalar", "Node", mass);
    if (options.strain) {
      w.attribute("strain", "Scalar", "Cell", frame_item(strain, own + "/frame/strain", f));
    }
    w.attribute("rest_length", "Scalar", "Cell", rest);
    w.attribute("ks", "Scalar", "Cell", ks);
    w.attribute("kd", "Scalar", "Cell", kd);
    w.attribute("spring_type (0 structural, 1 shear, 2 bending)", "Scalar", "Cell", type);
    if (observables) {
      for (const Observable& o : r.observables) w.field(o.name, &o.values[f * o.width], o.width);
    }
    if (!body.color.empty()) w.field("color", body.color.data(), 3);
    out << "      </Grid>\n";
  }
  out << "    </Grid>\n";
}

// The body's render surface: its triangles over the recorded vertex positions, frame by frame.
void surface_grids(Writer& w, hid_t file, const RecordingLayout& r, const RecordedBody& body) {
  const std::string own = surface_path(body);
  const Item triangles = item_of(file, body.group() + "/surface/triangles");
  const std::string faces = triangles.dims.substr(0, triangles.dims.find(' '));
  Item xyz = item_of(file, body.group() + "/surface/position/value");
  xyz.dims = std::to_string(body.surface_vertices) + " 3";
  const Item speed = float32_item(body.surface_vertices);
  const std::string name = xml_escape(surface_grid_name(body));
  auto& out = w.out();
  out << "    <Grid Name=\"" << name << "\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (hsize_t f = 0; f < r.frames; ++f) {
    out << "      <Grid Name=\"" << name << "\" GridType=\"Uniform\">\n"
        << "        <Time Value=\"" << r.time[f] << "\"/>\n"
        << "        <Topology TopologyType=\"Triangle\" NumberOfElements=\"" << faces << "\">\n";
    w.data_item(triangles, 10);
    out << "        </Topology>\n        <Geometry GeometryType=\"XYZ\">\n";
    w.data_item(frame_item(xyz, own + "/frame/position", f), 10);
    out << "        </Geometry>\n";
    w.attribute("speed", "Scalar", "Node", frame_item(speed, own + "/frame/speed", f));
    if (!body.color.empty()) w.field("color", body.color.data(), 3);
    out << "      </Grid>\n";
  }
  out << "    </Grid>\n";
}

void terrain_grids(Writer& w, hid_t file, const RecordingLayout& r, const TerrainInfo& t) {
  const std::string own = terrain_path(t);
  const Item triangles = item_of(file, own + "/triangles");
  const std::string faces = triangles.dims.substr(0, triangles.dims.find(' '));
  Item vertices, speed;
  if (t.moving) {
    vertices = item_of(file, own + "/position");
    vertices.dims = vertices.dims.substr(vertices.dims.find(' ') + 1);
    speed = item_of(file, own + "/speed");
    speed.dims = speed.dims.substr(speed.dims.find(' ') + 1);
  } else {
    vertices = item_of(file, own + "/vertices");
    speed = item_of(file, own + "/speed");
  }
  const std::string name = xml_escape(t.name);
  auto& out = w.out();
  out << "    <Grid Name=\"" << name << "\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (hsize_t f = 0; f < r.frames; ++f) {
    out << "      <Grid Name=\"" << name << "\" GridType=\"Uniform\">\n"
        << "        <Time Value=\"" << r.time[f] << "\"/>\n"
        << "        <Topology TopologyType=\"Triangle\" NumberOfElements=\"" << faces << "\">\n";
    w.data_item(triangles, 10);
    out << "        </Topology>\n        <Geometry GeometryType=\"XYZ\">\n";
    w.data_item(t.moving ? frame_item(vertices, own + "/frame/position", f) : vertices, 10);
    out << "        </Geometry>\n";
    w.attribute("speed", "Scalar", "Node",
                t.moving ? frame_item(speed, own + "/frame/speed", f) : speed);
    out << "      </Grid>\n";
  }
  out << "    </Grid>\n";
}

// The least and the largest speed of a set.
struct SpeedRange {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  bool empty() const { return !(lo <= hi); }
};

// The speeds of every particle and surface vertex over every frame (the derived /xdmf arrays,
// read a block at a time): the colour range that fits the whole run, where ParaView's default
// takes frame 0's (all zero for a run that starts at rest).
SpeedRange speed_range(hid_t file, const RecordingLayout& r) {
  SpeedRange range;
  const auto add = [&](const std::string& path) {
    if (!h5::exists(file, path)) return;
    Handle speed = h5::open_dataset(file, path);
    const std::vector<hsize_t> dims = h5::dataset_dims(speed.get());
    const hsize_t frames = std::min<hsize_t>(r.frames, dims.at(0));
    const hsize_t width = dims.size() > 1 ? dims[1] : 1;
    const hsize_t pass = frames_per_pass(4 * width);
    for (hsize_t f0 = 0; f0 < frames; f0 += pass) {
      const std::vector<float> rows =
          read_rows<float>(speed.get(), f0, std::min(pass, frames - f0), H5T_NATIVE_FLOAT);
      for (const float v : rows) {
        range.lo = std::min<double>(range.lo, v);
        range.hi = std::max<double>(range.hi, v);
      }
    }
  };
  for (const RecordedBody& body : r.bodies) {
    add(body_path(body) + "/speed");
    if (body.surface) add(surface_path(body) + "/speed");
  }
  return range;
}

}  // namespace

std::string update_xdmf(hid_t file, const std::string& h5_path, const XdmfOptions& options) {
  options.validate();
  const RecordingLayout r = inspect(file, h5_path);

  Handle root = open_or_create_group(file, "xdmf");
  if (!h5::has_attribute(root.get(), "version") ||
      h5::read_long_attribute(root.get(), "version") != kLayoutVersion) {
    root.reset();
    remove_link(file, "xdmf");
    root = h5::create_group(file, "xdmf");
    h5::write_attribute(root.get(), "version", kLayoutVersion);
    h5::write_attribute(root.get(), "description",
                        std::string("What the XDMF sidecar reads (docs/output.md): per-frame views "
                                    "(virtual datasets) and derived arrays; rebuilt by "
                                    "write_xdmf_for_recording"));
  }
  // Frames whose views were all written by an earlier call (a failed call may have left some).
  const hsize_t viewed =
      h5::has_attribute(root.get(), "frames")
          ? std::min<hsize_t>(r.frames, h5::read_long_attribute(root.get(), "frames"))
          : 0;
  Bounds bounds;
  if (h5::has_attribute(root.get(), "bounds")) {
    for (const auto& [key, value] : h5::read_attributes_as_text(root.get())) {
      if (key != "bounds") continue;
      std::istringstream text(value);
      text >> bounds.lo.x() >> bounds.lo.y() >> bounds.lo.z() >> bounds.hi.x() >> bounds.hi.y() >>
          bounds.hi.z();
    }
  }
  open_or_create_group(root.get(), "particles");
  for (const RecordedBody& body : r.bodies) {
    update_body(file, r, body, viewed, options, bounds);
    update_surface(file, r, body, viewed, options);
  }
  if (!bounds.empty()) {
    h5::write_attribute(root.get(), "bounds",
                        std::vector<double>{bounds.lo.x(), bounds.lo.y(), bounds.lo.z(),
                                            bounds.hi.x(), bounds.hi.y(), bounds.hi.z()});
  }
  std::vector<const TerrainInfo*> drawn;
  for (const TerrainInfo& t : r.terrains) {
    if (update_terrain(file, r, t, bounds)) drawn.push_back(&t);
  }
  h5::write_attribute(root.get(), "frames", static_cast<long>(r.frames));
  const SpeedRange speeds = speed_range(file, r);
  if (!speeds.empty())
    h5::write_attribute(root.get(), "speed_range", std::vector<double>{speeds.lo, speeds.hi});

  Writer w(r.h5_name);
  w.out() << "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n  <Domain>\n";
  for (size_t b = 0; b < r.bodies.size(); ++b) {
    body_grids(w, file, r, r.bodies[b], b == 0, options);
    if (r.bodies[b].surface) surface_grids(w, file, r, r.bodies[b]);
  }
  for (const TerrainInfo* t : drawn) terrain_grids(w, file, r, *t);
  w.out() << "  </Domain>\n</Xdmf>\n";

  return w.out().str();
}

std::string write_xdmf_for_recording(const std::string& h5_path, const XdmfOptions& options) {
  options.validate();
  std::lock_guard<std::recursive_mutex> lock(h5::library_mutex());
  h5::QuietErrors quiet;
  // The validation every reader of a recording makes: a damaged file (wrong shapes, masses that
  // are not finite, a dataset claiming more than it stores, a corrupt chunk) is an InputError
  // naming it and the dataset, before a sidecar describes it.
  (void)read_recording(h5_path);
  // The views go into a copy of the recording beside it, renamed onto it once written, flushed
  // and closed: HDF5 writes in place, and a write that failed half way (a full disk) left a
  // recording no reader could open (issue 44). The copy costs a read and a write of the file.
  detail::FileReplacement copy(h5_path);
  std::string text;
  try {
    std::filesystem::copy_file(h5_path, copy.temporary(),
                               std::filesystem::copy_options::overwrite_existing);
    h5::Handle file = h5::open_file(copy.temporary(), true);
    text = update_xdmf(file.get(), h5_path, options);
    check(H5Fflush(file.get(), H5F_SCOPE_GLOBAL), "flush " + h5_path);
    file.reset();
    copy.commit();
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    // A failed write (a full disk), not bad input; the recording is as it was.
    throw std::runtime_error("cannot write the XDMF views into '" + h5_path + "': " + e.what());
  }
  // Under a temporary name first: a failure leaves the old sidecar (or none), never half of one.
  const std::string xdmf_path = xdmf_path_for(h5_path);
  detail::replace_file(xdmf_path, text);
  return xdmf_path;
}

std::string paraview_state_path_for(const std::string& h5_path) {
  const std::string xdmf = xdmf_path_for(h5_path);
  return xdmf.substr(0, xdmf.size() - 5) + ".paraview.py";
}

namespace {

// A Python string literal of `text` (UTF-8 passes through; quotes, backslashes and control
// characters are escaped).
std::string python_string(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\x%02x", static_cast<unsigned char>(c));
      out += escaped;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

std::string python_numbers(const std::vector<double>& values) {
  std::string out = "[";
  char number[40];
  for (size_t k = 0; k < values.size(); ++k) {
    std::snprintf(number, sizeof number, "%.17g", values[k]);
    out += (k ? ", " : "") + std::string(number);
  }
  return out + "]";
}

}  // namespace

std::string write_paraview_state(const std::string& h5_path) {
  std::vector<double> bounds, speeds;
  {
    std::lock_guard<std::recursive_mutex> lock(h5::library_mutex());
    h5::QuietErrors quiet;
    h5::Handle file = h5::open_file(h5_path, false);
    if (!is_group(file.get(), "xdmf"))
      throw InputError("'" + h5_path + "' has no sidecar data (/xdmf): run `jelly xdmf " + h5_path +
                       "` first");
    Handle root = h5::open_group(file.get(), "xdmf");
    for (const auto& [key, value] : h5::read_attributes_as_text(root.get())) {
      std::istringstream text(value);
      std::vector<double>* into = key == "bounds"        ? &bounds
                                  : key == "speed_range" ? &speeds
                                                         : nullptr;
      for (double v; into != nullptr && text >> v;) into->push_back(v);
    }
  }
  const std::string xdmf = xdmf_path_for(h5_path);
  const std::string state = paraview_state_path_for(h5_path);
  const std::string name = xdmf.substr(xdmf.rfind('/') + 1);
  std::error_code error;
  const std::string absolute = std::filesystem::absolute(xdmf, error).lexically_normal().string();

  std::ostringstream py;
  py << "# ParaView state of " << name.substr(0, name.size() - 5)
     << ".h5, written by `jelly xdmf --state` (jelly writes\n"
     << "# this file and never runs it). Load it with File > Load State (a Python state file), "
        "with\n"
     << "# `paraview --state=" << state.substr(state.rfind('/') + 1)
     << "`, or run it with pvpython. It opens the XDMF sidecar beside\n"
     << "# it with ParaView's default reader, colours every block by speed over the range of all\n"
     << "# frames (not frame 0's), and points the camera at the bodies' bounding box over the "
        "run.\n"
     << "import os\n\nfrom paraview import simple\n\n"
     << "SIDECAR = " << python_string(name) << "  # beside this file\n"
     << "WRITTEN_AT = " << python_string(absolute) << "  # where it was when this was written\n";
  // A constant speed (a run at rest) still gets a range ParaView can draw.
  if (speeds.size() == 2 && !(speeds[1] > speeds[0])) speeds[1] = speeds[0] + 1;
  py << "SPEED_RANGE = " << (speeds.size() == 2 ? python_numbers(speeds) : "None")
     << "  # m/s, every particle and surface vertex over every frame\n"
     << "BOUNDS = " << (bounds.size() == 6 ? python_numbers(bounds) : "None")
     << "  # m: lo x, y, z, hi x, y, z of the bodies over the run\n\n"
     << "try:\n"
     << "    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), SIDECAR)\n"
     << "except NameError:  # run where __file__ is not set\n"
     << "    path = WRITTEN_AT\n"
     << "if not os.path.exists(path):\n"
     << "    path = WRITTEN_AT\n"
     << "reader = simple.OpenDataFile(path)\n"
     << "view = simple.GetActiveViewOrCreate(\"RenderView\")\n"
     << "display = simple.Show(reader, view)\n"
     << "simple.ColorBy(display, (\"POINTS\", \"speed\"))\n"
     << "lut = simple.GetColorTransferFunction(\"speed\")\n"
     << "if SPEED_RANGE is not None:\n"
     << "    lut.AutomaticRescaleRangeMode = \"Never\"\n"
     << "    lut.RescaleTransferFunction(SPEED_RANGE[0], SPEED_RANGE[1])\n"
     << "    simple.GetOpacityTransferFunction(\"speed\").RescaleTransferFunction(SPEED_RANGE[0], "
        "SPEED_RANGE[1])\n"
     << "display.SetScalarBarVisibility(view, True)\n"
     << "simple.GetScalarBar(lut, view).Title = \"speed (m/s)\"\n"
     << "simple.GetAnimationScene().UpdateAnimationUsingDataTimeSteps()\n"
     << "simple.Render(view)  # the first render resets the camera: it is set after\n"
     << "if BOUNDS is not None:\n"
     << "    # The box's centre, seen from the front, right and above, at the distance where its\n"
     << "    # bounding sphere fills the 30-degree view angle.\n"
     << "    centre = [0.5 * (BOUNDS[i] + BOUNDS[i + 3]) for i in range(3)]\n"
     << "    radius = max(0.05, 0.5 * sum((BOUNDS[i + 3] - BOUNDS[i]) ** 2 for i in range(3)) ** "
        "0.5)\n"
     << "    distance = 1.05 * radius / 0.25881904510252074  # sin(15 degrees)\n"
     << "    direction = [0.5, 0.4, 1.0]\n"
     << "    norm = sum(d * d for d in direction) ** 0.5\n"
     << "    view.CameraFocalPoint = centre\n"
     << "    view.CameraPosition = [c + distance * d / norm for c, d in zip(centre, direction)]\n"
     << "    view.CameraViewUp = [0.0, 1.0, 0.0]\n"
     << "    view.CameraViewAngle = 30.0\n"
     << "    view.CenterOfRotation = centre\n"
     << "    simple.Render(view)\n";
  detail::replace_file(state, py.str());
  return state;
}

}  // namespace jelly
