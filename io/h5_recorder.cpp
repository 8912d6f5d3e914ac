#include <jelly/io/h5_recorder.hpp>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cerrno>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <deque>
#include <exception>
#include <functional>
#include <optional>
#include <thread>

#include <jelly/core/detail/file_replacement.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/core/measures.hpp>
#include <jelly/io/detail/checkpoint_h5.hpp>
#include <jelly/io/detail/h5.hpp>
#include <jelly/io/detail/xdmf_h5.hpp>
#include <jelly/version.hpp>

namespace jelly {

void RecorderOptions::validate() const {
  require(flush_every_frames >= 1, "flush_every_frames", flush_every_frames, "an integer >= 1");
  require(compression_level >= 0 && compression_level <= 9, "compression_level", compression_level,
          "an integer in 0..9 (0 = off)");
  xdmf.validate();
}

std::string xdmf_path_for(const std::string& h5_path) {
  const size_t slash = h5_path.find_last_of('/');
  const size_t dot = h5_path.find_last_of('.');
  if (dot != std::string::npos && (slash == std::string::npos || dot > slash)) {
    return h5_path.substr(0, dot) + ".xdmf";
  }
  return h5_path + ".xdmf";
}

namespace {

// The observables of docs/output.md, computed from a frame's positions and velocities.
struct ObservableSpec {
  const char* name;
  int width;  // 1 (scalar) or 3 (vector)
  std::function<void(const Model&, const VecX& x, const VecX& v, double* out)> compute;
};

const std::vector<ObservableSpec>& observable_specs() {
  static const std::vector<ObservableSpec> specs{
      {"kinetic_energy", 1,
       [](const Model& m, const VecX&, const VecX& v, double* o) { *o = kinetic_energy(m, v); }},
      {"elastic_energy", 1,
       [](const Model& m, const VecX& x, const VecX&, double* o) { *o = elastic_energy(m, x); }},
      {"gravitational_energy", 1,
       [](const Model& m, const VecX& x, const VecX&, double* o) {
         *o = gravitational_energy(m, x);
       }},
      {"total_energy", 1,
       [](const Model& m, const VecX& x, const VecX& v, double* o) {
         *o = kinetic_energy(m, v) + elastic_energy(m, x) + gravitational_energy(m, x);
       }},
      {"center_of_mass", 3,
       [](const Model& m, const VecX& x, const VecX&, double* o) {
         Eigen::Map<Vec3>{o} = center_of_mass(m, x);
       }},
      {"linear_momentum", 3,
       [](const Model& m, const VecX&, const VecX& v, double* o) {
         Eigen::Map<Vec3>{o} = linear_momentum(m, v);
       }},
      {"angular_momentum", 3,
       [](const Model& m, const VecX& x, const VecX& v, double* o) {
         Eigen::Map<Vec3>{o} = angular_momentum(m, x, v);
       }},
  };
  return specs;
}

// Frames waiting to be written: each array holds `frames` frames back to back.
struct Batch {
  hsize_t frames = 0;
  std::vector<long> step;
  std::vector<double> time, position, velocity;
  std::vector<std::vector<double>> terrain;   // per terrain, 3 per frame
  std::vector<std::vector<double>> rotation;  // per terrain, 9 per frame (row-major)
  bool has_checkpoint = false;
  SimulatorSnapshot checkpoint;

  void clear() {
    frames = 0;
    step.clear();
    time.clear();
    position.clear();
    velocity.clear();
    for (auto& t : terrain) t.clear();
    for (auto& r : rotation) r.clear();
    has_checkpoint = false;
  }
};

// Frames per chunk of the particle series (a frame holds `values` numbers): the flush block, or
// the largest divisor of it whose chunk fits in HDF5's 1 MiB chunk cache. A chunk then never
// spans two flushes, so a flush writes whole new chunks and never rewrites (and moves) a
// compressed chunk that the file on disk already points to: a killed run leaves intact chunks.
// The frames of a block held in memory (each block waits in one of up to four batches: being
// filled, two queued, one being written) are limited to this many bytes of particle data: a large
// body is flushed in blocks of fewer frames than flush_every_frames.
constexpr size_t kMaxBlockBytes = size_t{8} << 20;

// Frames per block: flush_every_frames, or when frames of `frame_bytes` bytes would exceed
// kMaxBlockBytes, the largest power of two that fits (a power of two divides into chunks of any
// smaller power of two; chunk_frames), at least 1.
int block_frames(int flush_every, size_t frame_bytes) {
  const size_t fit = kMaxBlockBytes / std::max<size_t>(frame_bytes, 1);
  if (static_cast<size_t>(flush_every) <= fit) return flush_every;
  size_t block = 1;
  while (2 * block <= fit) block *= 2;
  return static_cast<int>(block);
}

hsize_t chunk_frames(size_t values, int flush_every) {
  const size_t bytes = 8 * std::max<size_t>(values, 1);
  for (int d = flush_every; d > 1; --d) {
    if (flush_every % d == 0 && bytes * d <= (size_t{1} << 20)) return static_cast<hsize_t>(d);
  }
  return 1;
}

// The small series (clock, observables, terrain: 1, 3 or 9 numbers a frame) are stored
// uncompressed in chunks of this many frames: a chunk is allocated once and then filled in place,
// flush after flush, instead of a new tiny compressed chunk per flush.
constexpr hsize_t kSmallSeriesChunk = 256;

std::string terrain_group_name(size_t index, const Terrain& terrain) {
  return std::to_string(index) + "_" + std::string(terrain.kind());
}

// Whether `path` exists; throws InputError when it exists and could not be replaced by a file
// (a directory, a device), or exists and `overwrite` is false.
bool check_target(const std::string& path, bool overwrite, const std::string& what) {
  struct stat info {};
  if (stat(path.c_str(), &info) != 0) return false;
  if (!S_ISREG(info.st_mode)) {
    throw InputError("cannot write " + what + " '" + path + "': it exists and is not a file");
  }
  if (!overwrite) {
    throw InputError("cannot write " + what + " '" + path +
                     "': the file exists (a recorder replaces it only when told to: "
                     "RecorderOptions::overwrite, jelly run --overwrite)");
  }
  if (access(path.c_str(), W_OK) != 0) {
    throw InputError("cannot write " + what + " '" + path + "': " + std::strerror(errno));
  }
  return true;
}

// Throws InputError unless a file can be created at `path` (which does not exist): it is created
// and removed again, so that a run learns before it starts that its sidecar could not be written.
void probe_creatable(const std::string& path, const std::string& what) {
  const int fd = open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0644);
  if (fd < 0) throw InputError("cannot write " + what + " '" + path + "': " + std::strerror(errno));
  close(fd);
  std::remove(path.c_str());
}

}  // namespace

struct H5Recorder::Impl {
  std::string path;          // where the recording ends up
  std::string write_path;    // where it is written: path, or the replacement's temporary
  std::string sidecar_path;  // the XDMF sidecar, when written
  // With overwrite and an existing file: the temporary moved onto path at the first on_finish
  // (removed, the old file kept, when the recorder ends before). Declared before the HDF5
  // handles, so that they are closed before it is removed.
  std::optional<detail::FileReplacement> replacement;
  // Without a replacement, the file is written in place: locked, so that a second recorder told
  // to overwrite it is refused while this one writes (the replacement locks the file it replaces).
  detail::WriteLock write_lock;
  RecorderOptions options;
  Model model;
  int n = 0;
  h5::Handle file, parameters;
  h5::Series step, time;
  // One /particles/<name> group per body (a model without bodies is one body "jelly").
  struct BodySeries {
    std::string name;
    int first = 0, count = 0;
    const Surface* surface = nullptr;  // in `model`, or null
    h5::Series position, velocity, surface_position;
    std::vector<double> position_work, velocity_work, surface_work;
  };
  std::vector<BodySeries> bodies;
  std::vector<h5::Series> observables, terrains, terrain_rotations;
  std::unique_ptr<h5::CheckpointWriter> checkpoint;
  // Set by set_scene(): the scene JSON and integrator name to store at on_finish.
  std::optional<std::pair<std::string, std::string>> changed_scene;
  long frames_received = 0;
  int block = 1;  // frames per flush block (block_frames)

  // Writer-thread side: the HDF5 work and the observables happen there, under the library mutex.
  VecX x_work, v_work;
  std::vector<std::vector<double>> observable_work;

  // Hand-off between on_frame (producer) and the writer thread (consumer).
  std::unique_ptr<Batch> current;
  std::mutex mutex;
  std::condition_variable changed;
  std::deque<std::unique_ptr<Batch>> queue, spare;
  bool writing = false, stopping = false;
  std::exception_ptr error;
  std::thread writer;

  Impl(const std::string& p, const Simulator& sim, RecorderOptions o);
  void write_static(const Simulator& sim);
  void write_batch(Batch& batch);
  void writer_loop();
  void submit();
  void drain();
  void stop();
  std::unique_ptr<Batch> take_spare();
};

H5Recorder::Impl::Impl(const std::string& p, const Simulator& sim, RecorderOptions o)
    : path(p), options(std::move(o)), model(sim.model()), n(sim.model().num_particles()) {
  options.validate();
  if (options.integrator_name.empty()) options.integrator_name = sim.integrator().name();
  require(!path.empty(), "recording path", "\"\"", "a file name");
  const bool replacing = check_target(path, options.overwrite, "the recording");
  if (options.write_xdmf) {
    sidecar_path = xdmf_path_for(path);
    if (sidecar_path == path) {
      throw InputError("cannot write the recording '" + path +
                       "': its XDMF sidecar would have the same name (name the recording .h5)");
    }
  }
  const bool sidecar_exists =
      options.write_xdmf && check_target(sidecar_path, options.overwrite, "the XDMF sidecar");
  if (replacing) replacement.emplace(path);
  write_path = replacing ? replacement->temporary() : path;
  {
    std::lock_guard<std::recursive_mutex> lock(h5::library_mutex());
    h5::QuietErrors quiet;
    // The temporary was created empty by the replacement; a new file is created exclusively.
    file = h5::create_file(write_path, /*exclusive=*/!replacing);
    try {
      if (!replacing) write_lock = detail::WriteLock(write_path);
      if (options.write_xdmf && !sidecar_exists) probe_creatable(sidecar_path, "the XDMF sidecar");
      write_static(sim);
      h5::check(H5Fflush(file.get(), H5F_SCOPE_GLOBAL), "flush " + write_path);
    } catch (...) {
      // A file this recorder created and could not complete (a full disk): not left behind.
      parameters.reset();
      for (h5::Series* series : {&step, &time}) *series = h5::Series();
      bodies.clear();
      observables.clear();
      terrains.clear();
      terrain_rotations.clear();
      checkpoint.reset();
      file.reset();
      write_lock.release();
      if (replacement) {
        replacement->discard();
      } else {
        std::remove(write_path.c_str());
      }
      throw;
    }
  }
  current = take_spare();
  current->terrain.resize(terrains.size());
  current->rotation.resize(terrains.size());
  if (options.background_writer) writer = std::thread([this] { writer_loop(); });
}

void H5Recorder::Impl::write_static(const Simulator& sim) {
  const hid_t f = file.get();
  {
    h5::Handle h5md = h5::create_group(f, "h5md");
    h5::write_attribute(h5md.get(), "version", std::vector<int>{1, 1});
    h5::write_attribute(h5md.get(), "creator", std::string("jelly"));
    h5::write_attribute(h5md.get(), "creator_version", std::string(JELLY_VERSION_STRING));
  }
  parameters = h5::create_group(f, "parameters");
  const hid_t par = parameters.get();
  h5::write_attribute(par, "scene_json", options.scene_json);
  h5::write_attribute(par, "integrator", options.integrator_name);
  h5::write_attribute(par, "dt", sim.options().dt);
  h5::write_attribute(par, "output_interval", sim.options().output_interval);
  h5::write_attribute(par, "library_version", std::string(JELLY_VERSION_STRING));
  h5::write_attribute(par, "gravity",
                      std::vector<double>(model.gravity.data(), model.gravity.data() + 3));
  h5::write_attribute(par, "num_particles", static_cast<long>(n));
  h5::write_attribute(par, "num_springs", static_cast<long>(model.springs.size()));
  h5::write_attribute(par, "run_status", std::string("running"));

  const int level = options.compression_level;
  // Per frame: positions and velocities of every particle, and the surfaces' vertices.
  size_t frame_bytes = 48 * static_cast<size_t>(n);
  for (const Body& b : model.bodies) {
    if (!b.surface.empty()) frame_bytes += 24 * static_cast<size_t>(b.surface.num_vertices());
  }
  block = block_frames(options.flush_every_frames, frame_bytes);
  h5::create_group(f, "particles");
  if (model.bodies.empty()) {
    bodies.push_back({"jelly", 0, n, nullptr, {}, {}, {}, {}, {}, {}});
  } else {
    for (const Body& b : model.bodies) {
      bodies.push_back({b.name,
                        b.first_particle,
                        b.num_particles,
                        b.surface.empty() ? nullptr : &b.surface,
                        {},
                        {},
                        {},
                        {},
                        {},
                        {}});
    }
  }
  // H5MD lets time-dependent groups sampled at the same frames share step and time by hard
  // links: the first body's position group holds them.
  const std::string clock = "/particles/" + bodies.front().name + "/position/";
  const auto link_clock = [&](hid_t group) {
    h5::hard_link(f, clock + "step", group, "step");
    h5::hard_link(f, clock + "time", group, "time");
  };
  for (std::size_t bi = 0; bi < bodies.size(); ++bi) {
    BodySeries& body = bodies[bi];
    const hsize_t N = static_cast<hsize_t>(body.count);
    h5::Handle g = h5::create_group(f, "particles/" + body.name);
    h5::write_attribute(g.get(), "first_particle", static_cast<long>(body.first));
    if (!model.bodies.empty()) {
      const Body& b = model.bodies[bi];
      h5::write_attribute(g.get(), "kind", b.kind);
      h5::write_attribute(g.get(), "first_spring", static_cast<long>(b.first_spring));
      h5::write_attribute(g.get(), "num_springs", static_cast<long>(b.num_springs));
      h5::write_attribute(g.get(), "radius", b.radius);
      h5::write_attribute(g.get(), "spacing", b.spacing);
      h5::write_attribute(g.get(), "thickness", b.thickness);
      if (b.color)
        h5::write_attribute(g.get(), "color",
                            std::vector<double>{b.color->x(), b.color->y(), b.color->z()});
    }
    h5::write_dataset(g.get(), "mass", {N}, model.mass.data() + body.first);
    h5::write_dataset(g.get(), "rest_position", {N, 3},
                      model.rest_position.data() + 3 * body.first);
    const hsize_t frame_chunk = chunk_frames(3 * N, block);
    {
      h5::Handle p = h5::create_group(g.get(), "position");
      if (bi == 0) {
        step =
            h5::Series(p.get(), "step", H5T_STD_I64LE, H5T_NATIVE_LONG, {}, kSmallSeriesChunk, 0);
        time = h5::Series(p.get(), "time", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {}, kSmallSeriesChunk,
                          0);
      } else {
        link_clock(p.get());
      }
      body.position = h5::Series(p.get(), "value", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {N, 3},
                                 frame_chunk, level);
    }
    {
      h5::Handle v = h5::create_group(g.get(), "velocity");
      link_clock(v.get());
      body.velocity = h5::Series(v.get(), "value", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {N, 3},
                                 frame_chunk, level);
    }
    if (body.surface != nullptr) {
      // The render surface: triangles over vertices that are weighted sums of the body's
      // particles (body-local indices), and the vertices' positions at every frame.
      const Surface& s = *body.surface;
      h5::Handle sg = h5::create_group(g.get(), "surface");
      const hsize_t F = static_cast<hsize_t>(s.num_triangles());
      const hsize_t V = static_cast<hsize_t>(s.num_vertices());
      const hsize_t K = static_cast<hsize_t>(s.particles.size());
      std::vector<int> triangles(3 * F), particles(K);
      for (hsize_t t = 0; t < F; ++t)
        for (int c = 0; c < 3; ++c) triangles[3 * t + c] = s.triangles[t][c];
      for (hsize_t k = 0; k < K; ++k) particles[k] = s.particles[k] - body.first;
      h5::write_dataset(sg.get(), "triangles", {F, 3}, triangles.data());
      h5::write_dataset(sg.get(), "vertex_offsets", {V + 1}, s.offsets.data());
      h5::write_dataset(sg.get(), "vertex_particles", {K}, particles.data());
      h5::write_dataset(sg.get(), "vertex_weights", {K}, s.weights.data());
      h5::Handle p = h5::create_group(sg.get(), "position");
      link_clock(p.get());
      body.surface_position = h5::Series(p.get(), "value", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE,
                                         {V, 3}, chunk_frames(3 * V, block), level);
    }
  }

  const Springs& s = model.springs;
  const hsize_t M = static_cast<hsize_t>(s.size());
  {
    h5::Handle g = h5::create_group(f, "connectivity");
    std::vector<int> pairs(2 * M), type(M);
    for (hsize_t i = 0; i < M; ++i) {
      pairs[2 * i] = s.a[i];
      pairs[2 * i + 1] = s.b[i];
      type[i] = static_cast<int>(s.type[i]);
    }
    h5::write_dataset(g.get(), "springs", {M, 2}, pairs.data());
    h5::write_dataset(g.get(), "type", {M}, type.data());
    h5::write_dataset(g.get(), "rest_length", {M}, s.rest_length.data());
    h5::write_dataset(g.get(), "ks", {M}, s.ks.data());
    h5::write_dataset(g.get(), "kd", {M}, s.kd.data());
    h5::write_attribute(g.get(), "type_names", std::string("0 structural, 1 shear, 2 bending"));
  }

  {
    h5::Handle g = h5::create_group(f, "observables");
    for (const ObservableSpec& spec : observable_specs()) {
      h5::Handle o = h5::create_group(g.get(), spec.name);
      link_clock(o.get());
      std::vector<hsize_t> shape;
      if (spec.width > 1) shape.push_back(static_cast<hsize_t>(spec.width));
      observables.emplace_back(o.get(), "value", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, shape,
                               kSmallSeriesChunk, 0);
      observable_work.emplace_back();
    }
  }

  {
    h5::Handle g = h5::create_group(f, "terrain");
    for (size_t i = 0; i < sim.terrains().size(); ++i) {
      const Terrain& terrain = *sim.terrains()[i];
      h5::Handle t = h5::create_group(g.get(), terrain_group_name(i, terrain));
      const Real t0 = sim.state().t;
      const Vec3 p = terrain.position(t0), normal = terrain.normal(p, t0);
      h5::write_attribute(t.get(), "kind", std::string(terrain.kind()));
      h5::write_attribute(t.get(), "normal", std::vector<double>(normal.data(), normal.data() + 3));
      h5::write_attribute(t.get(), "contact_model",
                          std::string(contact_model_name(terrain.contact().model)));
      h5::write_attribute(t.get(), "restitution", terrain.contact().restitution);
      h5::write_attribute(t.get(), "friction", terrain.contact().friction);
      for (const auto& [name, value] : terrain.attributes()) {
        h5::write_attribute(t.get(), name, value);
      }
      {
        // Its shape for drawing, in its own frame, placed at each frame by the recorded rotation
        // and position (Terrain::pose(t)): a vertex v is at rotation * v + position.
        const TriangleMesh mesh = terrain.render_mesh();
        h5::Handle mg = h5::create_group(t.get(), "mesh");
        const hsize_t V = static_cast<hsize_t>(mesh.num_vertices());
        const hsize_t F = static_cast<hsize_t>(mesh.num_triangles());
        std::vector<double> vertices(3 * V);
        std::vector<int> triangles(3 * F);
        for (hsize_t v = 0; v < V; ++v)
          for (int c = 0; c < 3; ++c) vertices[3 * v + c] = mesh.vertices[v][c];
        for (hsize_t k = 0; k < F; ++k)
          for (int c = 0; c < 3; ++c) triangles[3 * k + c] = mesh.triangles[k][c];
        h5::write_dataset(mg.get(), "vertices", {V, 3}, vertices.data());
        h5::write_dataset(mg.get(), "triangles", {F, 3}, triangles.data());
      }
      h5::Handle pos = h5::create_group(t.get(), "position");
      link_clock(pos.get());
      terrains.emplace_back(pos.get(), "value", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE,
                            std::vector<hsize_t>{3}, kSmallSeriesChunk, 0);
      h5::Handle rot = h5::create_group(t.get(), "rotation");
      link_clock(rot.get());
      terrain_rotations.emplace_back(rot.get(), "value", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE,
                                     std::vector<hsize_t>{3, 3}, kSmallSeriesChunk, 0);
    }
  }

  checkpoint = std::make_unique<h5::CheckpointWriter>(f, n, std::string(sim.integrator().name()),
                                                      sim.options().dt);
}

// Runs on the writer thread (or the caller's, without one), holding the library mutex.
void H5Recorder::Impl::write_batch(Batch& batch) {
  const hsize_t frames = batch.frames;
  if (frames > 0) {
    const Eigen::Index dofs = 3 * static_cast<Eigen::Index>(n);
    const auto& specs = observable_specs();
    for (size_t k = 0; k < specs.size(); ++k) observable_work[k].resize(frames * specs[k].width);
    ensure_size(x_work, dofs);
    ensure_size(v_work, dofs);
    const bool whole = bodies.size() == 1 && bodies[0].count == n;
    for (BodySeries& body : bodies) {
      if (!whole) {
        body.position_work.resize(frames * 3 * body.count);
        body.velocity_work.resize(frames * 3 * body.count);
      }
      if (body.surface) body.surface_work.resize(frames * 3 * body.surface->num_vertices());
    }
    for (hsize_t f = 0; f < frames; ++f) {
      std::memcpy(x_work.data(), batch.position.data() + f * dofs, sizeof(double) * dofs);
      std::memcpy(v_work.data(), batch.velocity.data() + f * dofs, sizeof(double) * dofs);
      for (size_t k = 0; k < specs.size(); ++k) {
        specs[k].compute(model, x_work, v_work, observable_work[k].data() + f * specs[k].width);
      }
      for (BodySeries& body : bodies) {
        const std::size_t values = 3 * static_cast<std::size_t>(body.count);
        if (!whole) {
          std::memcpy(body.position_work.data() + f * values, x_work.data() + 3 * body.first,
                      sizeof(double) * values);
          std::memcpy(body.velocity_work.data() + f * values, v_work.data() + 3 * body.first,
                      sizeof(double) * values);
        }
        if (body.surface) {
          const int nv = body.surface->num_vertices();
          for (int v = 0; v < nv; ++v) {
            Eigen::Map<Vec3>(body.surface_work.data() + (f * nv + v) * 3) =
                body.surface->vertex(x_work, v);
          }
        }
      }
    }
    step.append(batch.step.data(), frames);
    time.append(batch.time.data(), frames);
    for (BodySeries& body : bodies) {
      body.position.append(whole ? batch.position.data() : body.position_work.data(), frames);
      body.velocity.append(whole ? batch.velocity.data() : body.velocity_work.data(), frames);
      if (body.surface) body.surface_position.append(body.surface_work.data(), frames);
    }
    for (size_t k = 0; k < specs.size(); ++k)
      observables[k].append(observable_work[k].data(), frames);
    for (size_t i = 0; i < terrains.size(); ++i) {
      terrains[i].append(batch.terrain[i].data(), frames);
      terrain_rotations[i].append(batch.rotation[i].data(), frames);
    }
  }
  if (batch.has_checkpoint) checkpoint->write(batch.checkpoint);
  h5::check(H5Fflush(file.get(), H5F_SCOPE_GLOBAL), "flush " + path);
}

void H5Recorder::Impl::writer_loop() {
  std::unique_lock<std::mutex> lock(mutex);
  for (;;) {
    changed.wait(lock, [this] { return stopping || !queue.empty(); });
    if (queue.empty()) return;  // stopping, nothing left
    std::unique_ptr<Batch> batch = std::move(queue.front());
    queue.pop_front();
    writing = true;
    lock.unlock();
    std::exception_ptr failure;
    if (!error) {
      try {
        std::lock_guard<std::recursive_mutex> library(h5::library_mutex());
        h5::QuietErrors quiet;
        write_batch(*batch);
      } catch (...) {
        failure = std::current_exception();
      }
    }
    batch->clear();
    lock.lock();
    if (failure && !error) error = failure;
    spare.push_back(std::move(batch));
    writing = false;
    changed.notify_all();
  }
}

std::unique_ptr<Batch> H5Recorder::Impl::take_spare() {
  std::lock_guard<std::mutex> lock(mutex);
  if (spare.empty()) {
    auto batch = std::make_unique<Batch>();
    batch->terrain.resize(terrains.size());
    batch->rotation.resize(terrains.size());
    return batch;
  }
  std::unique_ptr<Batch> batch = std::move(spare.front());
  spare.pop_front();
  return batch;
}

// Hands the current batch to the writer (or writes it here) and starts a new one.
void H5Recorder::Impl::submit() {
  if (!options.background_writer) {
    std::lock_guard<std::recursive_mutex> library(h5::library_mutex());
    h5::QuietErrors quiet;
    write_batch(*current);
    current->clear();
    return;
  }
  {
    std::unique_lock<std::mutex> lock(mutex);
    // At most two blocks wait: a writer slower than the run holds the run back, not memory.
    changed.wait(lock, [this] { return queue.size() < 2 || error; });
    if (error) std::rethrow_exception(error);
    queue.push_back(std::move(current));
    changed.notify_all();
  }
  current = take_spare();
}

// Waits until the writer has written everything submitted; rethrows its failure.
void H5Recorder::Impl::drain() {
  if (!options.background_writer) return;
  std::unique_lock<std::mutex> lock(mutex);
  changed.wait(lock, [this] { return queue.empty() && !writing; });
  if (error) std::rethrow_exception(error);
}

void H5Recorder::Impl::stop() {
  if (!writer.joinable()) return;
  {
    std::lock_guard<std::mutex> lock(mutex);
    stopping = true;
    changed.notify_all();
  }
  writer.join();
}

H5Recorder::H5Recorder(const std::string& path, const Simulator& sim, RecorderOptions options)
    : impl_(std::make_unique<Impl>(path, sim, std::move(options))) {}

H5Recorder::~H5Recorder() {
  try {
    if (impl_->current->frames > 0) impl_->submit();
    impl_->drain();
  } catch (...) {
    // A destructor cannot report; on_finish does.
  }
  impl_->stop();
  std::lock_guard<std::recursive_mutex> library(h5::library_mutex());
  h5::QuietErrors quiet;
  // Closes every handle, then the file; a replacement that on_finish did not complete is
  // dropped: the old file stays.
  impl_.reset();
}

namespace {

// "27000 particles, 1 body (jelly), 287820 springs".
std::string model_text(const Model& model) {
  std::string bodies;
  for (const Body& b : model.bodies) bodies += (bodies.empty() ? "" : ", ") + b.name;
  const std::size_t count = std::max<std::size_t>(model.bodies.size(), 1);
  return std::to_string(model.num_particles()) + " particles, " + std::to_string(count) +
         (count == 1 ? " body" : " bodies") + (bodies.empty() ? "" : " (" + bodies + ")") + ", " +
         std::to_string(model.springs.size()) + " springs";
}

bool same_bodies(const Model& a, const Model& b) {
  if (a.num_particles() != b.num_particles() || a.springs.size() != b.springs.size() ||
      a.bodies.size() != b.bodies.size())
    return false;
  for (std::size_t i = 0; i < a.bodies.size(); ++i) {
    const Body &p = a.bodies[i], &q = b.bodies[i];
    if (p.name != q.name || p.first_particle != q.first_particle ||
        p.num_particles != q.num_particles || p.first_spring != q.first_spring ||
        p.num_springs != q.num_springs)
      return false;
  }
  return true;
}

}  // namespace

void H5Recorder::check_simulator(const Simulator& sim) const {
  const Impl& m = *impl_;
  if (!same_bodies(m.model, sim.model())) {
    throw InputError("simulator", model_text(sim.model()),
                     "the simulator the recorder of '" + m.path + "' was made for (" +
                         model_text(m.model) + "): make a recorder for each simulator");
  }
  require(sim.terrains().size() >= m.terrains.size(), "simulator",
          std::to_string(sim.terrains().size()) + " terrains",
          "at least the " + std::to_string(m.terrains.size()) + " terrains the recorder of '" +
              m.path + "' was made with");
}

void H5Recorder::on_frame(const Simulator& sim) {
  Impl& m = *impl_;
  // add_observer checked the simulator (check_simulator); a frame never reads past its arrays.
  if (sim.state().x.size() != 3 * m.n || sim.terrains().size() < m.terrains.size()) {
    check_simulator(sim);
    throw InputError(
        "simulator", std::to_string(sim.state().x.size() / 3) + " particles",
        "the " + std::to_string(m.n) + " particles of the recorder of '" + m.path + "'");
  }
  Batch& b = *m.current;
  const State& s = sim.state();
  b.step.push_back(sim.total_steps());
  b.time.push_back(s.t);
  b.position.insert(b.position.end(), s.x.data(), s.x.data() + s.x.size());
  b.velocity.insert(b.velocity.end(), s.v.data(), s.v.data() + s.v.size());
  for (size_t i = 0; i < m.terrains.size(); ++i) {
    const Terrain& terrain = *sim.terrains()[i];
    const Vec3 p = terrain.position(s.t);
    b.terrain[i].insert(b.terrain[i].end(), p.data(), p.data() + 3);
    const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> r = terrain.pose(s.t).linear();
    b.rotation[i].insert(b.rotation[i].end(), r.data(), r.data() + 9);
  }
  ++b.frames;
  ++m.frames_received;
  if (static_cast<int>(b.frames) >= m.block) {
    b.checkpoint = sim.snapshot();
    b.has_checkpoint = true;
    m.submit();
  }
}

void H5Recorder::on_finish(const Simulator& sim, const RunReport& report) {
  Impl& m = *impl_;
  m.current->checkpoint = sim.snapshot();
  m.current->has_checkpoint = true;
  m.submit();
  m.drain();
  {
    std::lock_guard<std::recursive_mutex> library(h5::library_mutex());
    h5::QuietErrors quiet;
    const hid_t par = m.parameters.get();
    h5::write_attribute(par, "run_status", std::string(run_status_name(report.status)));
    h5::write_attribute(par, "run_reason", report.reason);
    h5::write_attribute(par, "run_t", report.t);
    h5::write_attribute(par, "run_steps", report.steps);
    h5::write_attribute(par, "run_wall_seconds", report.wall_seconds);
    h5::write_attribute(par, "run_force_evaluations", report.force_evaluations);
    h5::write_attribute(par, "total_steps", sim.total_steps());
    if (m.changed_scene) {
      h5::write_attribute(par, "scene_json", m.changed_scene->first);
      h5::write_attribute(par, "integrator", m.changed_scene->second);
    }
    if (m.checkpoint)
      m.checkpoint->set_integrator(std::string(sim.integrator().name()), sim.options().dt);
    for (const auto& [name, value] : report.statistics) {
      h5::write_attribute(par, "statistics." + name, value);
    }
    h5::check(H5Fflush(m.file.get(), H5F_SCOPE_GLOBAL), "flush " + m.path);
  }
  // The sidecar under a temporary name first, so that a failure leaves no half-written one; the
  // recording is moved onto its path only when everything else has been written.
  std::optional<detail::FileReplacement> sidecar;
  if (m.options.write_xdmf) {
    std::string text;
    {
      std::lock_guard<std::recursive_mutex> library(h5::library_mutex());
      h5::QuietErrors quiet;
      text = update_xdmf(m.file.get(), m.path, m.options.xdmf);
      h5::check(H5Fflush(m.file.get(), H5F_SCOPE_GLOBAL), "flush " + m.path);
    }
    sidecar.emplace(m.sidecar_path);
    sidecar->write(text);
  }
  if (m.replacement) {
    m.replacement->commit();
    m.replacement.reset();
    m.write_path = m.path;
    // Later run_until() calls write on in place: locked as a file written in place is.
    m.write_lock = detail::WriteLock(m.path);
  }
  if (sidecar) sidecar->commit();
}

void disable_hdf5_exit_cleanup() {
  std::lock_guard<std::recursive_mutex> lock(h5::library_mutex());
  H5dont_atexit();
}

void H5Recorder::set_scene(const std::string& scene_json, const std::string& integrator_name) {
  impl_->changed_scene.emplace(scene_json, integrator_name);
}

const std::string& H5Recorder::path() const { return impl_->path; }
long H5Recorder::frames() const { return impl_->frames_received; }

}  // namespace jelly
