#include <jelly/io/checkpoint.hpp>

#include <cmath>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/io/detail/checkpoint_h5.hpp>
#include <jelly/io/detail/h5.hpp>
#include <jelly/io/detail/json_parse.hpp>
#include <jelly/solvers/contact/detail/contact_solver.hpp>

namespace jelly {

namespace h5 {

CheckpointWriter::CheckpointWriter(hid_t file, int num_particles, const std::string& integrator,
                                   Real dt) {
  group_ = create_group(file, "checkpoint");
  write_attribute(group_.get(), "integrator", integrator);
  write_attribute(group_.get(), "dt", dt);
  const hsize_t n = static_cast<hsize_t>(num_particles);
  const auto fixed = [&](const char* name) {
    Handle space(H5Screate_simple(2, std::vector<hsize_t>{n, 3}.data(), nullptr), name);
    return Handle(H5Dcreate2(group_.get(), name, H5T_IEEE_F64LE, space.get(), H5P_DEFAULT,
                             H5P_DEFAULT, H5P_DEFAULT),
                  std::string("create checkpoint/") + name);
  };
  position_ = fixed("position");
  velocity_ = fixed("velocity");
  const auto resizable = [&](const char* name, hid_t type, hsize_t width) {
    std::vector<hsize_t> dims{0}, max_dims{H5S_UNLIMITED}, chunk{256};
    if (width > 1) {
      dims.push_back(width);
      max_dims.push_back(width);
      chunk.push_back(width);
    }
    Handle space(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), max_dims.data()),
                 name);
    Handle properties(H5Pcreate(H5P_DATASET_CREATE), name);
    check(H5Pset_chunk(properties.get(), static_cast<int>(chunk.size()), chunk.data()), name);
    return Handle(H5Dcreate2(group_.get(), name, type, space.get(), H5P_DEFAULT, properties.get(),
                             H5P_DEFAULT),
                  std::string("create checkpoint/") + name);
  };
  seed_particle_ = resizable("seed_particle", H5T_STD_I32LE, 1);
  seed_normal_ = resizable("seed_normal", H5T_IEEE_F64LE, 3);
  seed_friction_ = resizable("seed_friction", H5T_IEEE_F64LE, 1);
  integrator_state_ = resizable("integrator_state", H5T_IEEE_F64LE, 1);
}

namespace {

void overwrite(hid_t dataset, hid_t memory_type, std::vector<hsize_t> dims, const void* data) {
  check(H5Dset_extent(dataset, dims.data()), "resize checkpoint dataset");
  if (dims[0] > 0) {
    check(H5Dwrite(dataset, memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data),
          "write checkpoint dataset");
  }
}

}  // namespace

constexpr const char* kModelValues = "model_values";

void write_model_values(hid_t checkpoint, const ModelValues& m) {
  if (exists(checkpoint, kModelValues))
    check(H5Ldelete(checkpoint, kModelValues, H5P_DEFAULT), "replace checkpoint/model_values");
  Handle g = create_group(checkpoint, kModelValues);
  write_dataset(g.get(), "ks", {m.ks.size()}, m.ks.data());
  write_dataset(g.get(), "kd", {m.kd.size()}, m.kd.data());
  write_dataset(g.get(), "mass", {static_cast<hsize_t>(m.mass.size())}, m.mass.data());
  write_dataset(g.get(), "gravity", {3}, m.gravity.data());
  const hsize_t p = m.pins.particles.size();
  std::vector<double> anchors;
  for (const Vec3& a : m.pins.anchors) anchors.insert(anchors.end(), a.data(), a.data() + 3);
  write_dataset(g.get(), "pin_particle", {p}, m.pins.particles.data());
  write_dataset(g.get(), "pin_anchor", {p, 3}, anchors.data());
  write_dataset(g.get(), "pin_path", {p}, m.pins.path.data());
  Json paths = Json::array();
  for (const Path& path : m.pins.paths) paths.push_back(path.to_json());
  write_attribute(g.get(), "pin_paths", paths.dump());
}

void CheckpointWriter::write(const SimulatorSnapshot& s) {
  check(
      H5Dwrite(position_.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, s.state.x.data()),
      "write checkpoint/position");
  check(
      H5Dwrite(velocity_.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, s.state.v.data()),
      "write checkpoint/velocity");
  const hsize_t k = s.seed_contacts.size();
  particles_.clear();
  normals_.clear();
  frictions_.clear();
  for (const ContactSolver::SeedContact& c : s.seed_contacts) {
    particles_.push_back(c.particle);
    normals_.insert(normals_.end(), c.normal.data(), c.normal.data() + 3);
    frictions_.push_back(c.friction);
  }
  overwrite(seed_particle_.get(), H5T_NATIVE_INT, {k}, particles_.data());
  overwrite(seed_normal_.get(), H5T_NATIVE_DOUBLE, {k, 3}, normals_.data());
  overwrite(seed_friction_.get(), H5T_NATIVE_DOUBLE, {k}, frictions_.data());
  overwrite(integrator_state_.get(), H5T_NATIVE_DOUBLE, {s.integrator_state.size()},
            s.integrator_state.data());
  if (s.model_values) write_model_values(group_.get(), *s.model_values);
  write_attribute(group_.get(), "t", s.state.t);
  write_attribute(group_.get(), "total_steps", s.total_steps);
  write_attribute(group_.get(), "next_output", s.next_output);
  write_attribute(group_.get(), "contact_count", static_cast<long>(s.contact_count));
}

void CheckpointWriter::set_integrator(const std::string& integrator, Real dt) {
  write_attribute(group_.get(), "integrator", integrator);
  write_attribute(group_.get(), "dt", dt);
}

}  // namespace h5

SimulatorSnapshot Checkpoint::snapshot() const {
  return {state,       seed_contacts,    contact_count, total_steps,
          next_output, integrator_state, model_values};
}

namespace {
// The edited model values of a checkpoint's model_values group (validated when restored).
ModelValues read_model_values(hid_t checkpoint) {
  h5::Handle g = h5::open_group(checkpoint, "model_values");
  ModelValues m;
  m.ks = h5::read_doubles(g.get(), "ks");
  m.kd = h5::read_doubles(g.get(), "kd");
  const std::vector<double> mass = h5::read_doubles(g.get(), "mass");
  m.mass = Eigen::Map<const VecX>(mass.data(), static_cast<Eigen::Index>(mass.size()));
  const std::vector<double> gravity = h5::read_doubles(g.get(), "gravity");
  if (gravity.size() != 3) throw std::runtime_error("model_values/gravity is not [3]");
  m.gravity = Vec3(gravity[0], gravity[1], gravity[2]);
  m.pins.particles = h5::read_ints(g.get(), "pin_particle");
  m.pins.path = h5::read_ints(g.get(), "pin_path");
  const std::vector<double> anchors = h5::read_doubles(g.get(), "pin_anchor");
  if (anchors.size() != 3 * m.pins.particles.size() ||
      m.pins.path.size() != m.pins.particles.size())
    throw std::runtime_error("model_values: pin_particle, pin_anchor and pin_path differ in size");
  for (std::size_t k = 0; k < m.pins.particles.size(); ++k)
    m.pins.anchors.emplace_back(anchors[3 * k], anchors[3 * k + 1], anchors[3 * k + 2]);
  const Json paths = detail::parse_json(h5::read_string_attribute(g.get(), "pin_paths"),
                                        "checkpoint/model_values pin_paths");
  if (!paths.is_array()) throw std::runtime_error("model_values pin_paths is not a list");
  for (std::size_t k = 0; k < paths.size(); ++k)
    m.pins.paths.push_back(Path::read(paths[k], "checkpoint pin_paths[" + std::to_string(k) + "]"));
  for (int path : m.pins.path)
    if (path < 0 || path >= static_cast<int>(m.pins.paths.size()))
      throw std::runtime_error("model_values pin_path " + std::to_string(path) + " names no path");
  return m;
}
}  // namespace

Checkpoint read_checkpoint(const std::string& path) {
  std::lock_guard<std::recursive_mutex> lock(h5::library_mutex());
  h5::QuietErrors quiet;
  h5::Handle file = h5::open_file(path);
  if (!h5::exists(file.get(), "checkpoint")) {
    throw InputError("'" + path + "' holds no /checkpoint group (not a jelly recording?)");
  }
  Checkpoint cp;
  try {
    h5::Handle g = h5::open_group(file.get(), "checkpoint");
    if (!h5::has_attribute(g.get(), "t")) {
      throw InputError("'" + path + "' has an empty /checkpoint: its run wrote no flush");
    }
    std::vector<hsize_t> dims;
    std::vector<double> x = h5::read_doubles(g.get(), "position", &dims);
    const auto fail = [](const std::string& why) { throw std::runtime_error(why); };
    if (dims.size() != 2 || dims[1] != 3) fail("position is not [N][3]");
    std::vector<double> v = h5::read_doubles(g.get(), "velocity", &dims);
    if (v.size() != x.size() || dims.size() != 2) fail("velocity is not the shape of position");
    cp.state.t = h5::read_double_attribute(g.get(), "t");
    cp.state.x = Eigen::Map<const VecX>(x.data(), static_cast<Eigen::Index>(x.size()));
    cp.state.v = Eigen::Map<const VecX>(v.data(), static_cast<Eigen::Index>(v.size()));
    // A value that is not finite is damage to the file, or the last state of a run that
    // diverged: nothing a run can continue from either way (checked below, with the status).
    std::string not_finite;
    for (const auto& [name, values] :
         {std::pair{"position", &cp.state.x}, std::pair{"velocity", &cp.state.v}}) {
      for (Eigen::Index i = 0; i < values->size() && not_finite.empty(); ++i) {
        if (!std::isfinite((*values)[i])) {
          not_finite = std::string("/checkpoint/") + name + " of particle " +
                       std::to_string(i / 3) + " is " + to_text((*values)[i]);
        }
      }
    }
    if (not_finite.empty() && !std::isfinite(cp.state.t)) {
      not_finite = "/checkpoint attribute t is " + to_text(cp.state.t);
    }
    cp.total_steps = h5::read_long_attribute(g.get(), "total_steps");
    cp.next_output = h5::read_double_attribute(g.get(), "next_output");
    cp.contact_count = static_cast<int>(h5::read_long_attribute(g.get(), "contact_count"));
    const std::vector<int> particles = h5::read_ints(g.get(), "seed_particle");
    const std::vector<double> normals = h5::read_doubles(g.get(), "seed_normal");
    const std::vector<double> frictions = h5::read_doubles(g.get(), "seed_friction");
    if (normals.size() != 3 * particles.size() || frictions.size() != particles.size()) {
      fail("seed_particle, seed_normal and seed_friction hold " + std::to_string(particles.size()) +
           ", " + std::to_string(normals.size()) + " and " + std::to_string(frictions.size()) +
           " numbers, not K, 3K and K");
    }
    for (size_t i = 0; i < particles.size(); ++i) {
      cp.seed_contacts.push_back({particles[i],
                                  Vec3(normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]),
                                  frictions[i]});
    }
    if (h5::exists(g.get(), "integrator_state"))
      cp.integrator_state = h5::read_doubles(g.get(), "integrator_state");
    if (h5::exists(g.get(), "model_values")) cp.model_values = read_model_values(g.get());
    cp.integrator = h5::read_string_attribute(g.get(), "integrator");
    cp.dt = h5::read_double_attribute(g.get(), "dt");
    if (h5::exists(file.get(), "parameters")) {
      h5::Handle parameters = h5::open_group(file.get(), "parameters");
      if (h5::has_attribute(parameters.get(), "scene_json")) {
        cp.scene_json = h5::read_string_attribute(parameters.get(), "scene_json");
      }
      if (h5::has_attribute(parameters.get(), "output_interval")) {
        cp.output_interval = h5::read_double_attribute(parameters.get(), "output_interval");
      }
    }
    if (!not_finite.empty()) {
      std::string status;
      if (h5::exists(file.get(), "parameters")) {
        h5::Handle parameters = h5::open_group(file.get(), "parameters");
        if (h5::has_attribute(parameters.get(), "run_status")) {
          status = h5::read_string_attribute(parameters.get(), "run_status");
        }
      }
      throw InputError("'" + path + "' has an invalid /checkpoint: " + not_finite +
                       (status == "diverged"
                            ? " (its run diverged: there is no finite state to continue from)"
                            : " (not finite: the file is damaged)"));
    }
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError("'" + path + "' has an invalid /checkpoint: " + e.what());
  }
  return cp;
}

void restore(Simulator& sim, const Checkpoint& cp) {
  require(cp.state.x.size() == sim.model().num_dofs(), "checkpoint particles",
          cp.state.x.size() / 3,
          "the simulator's particle count (" + std::to_string(sim.model().num_particles()) + ")");
  require(cp.integrator == sim.integrator().name(), "checkpoint integrator", cp.integrator,
          "the simulator's integrator '" + std::string(sim.integrator().name()) + "'");
  require(cp.dt == sim.options().dt, "checkpoint dt", cp.dt,
          "the simulator's time step (" + to_text(sim.options().dt) + ")");
  // A run's checkpoint is taken at a frame (next_output is that frame's time, about t) or at its
  // end (the next frame's time, at most one interval later). Far from t, the first frames would
  // be emitted one interval at a time across the gap: a hang for an absurd value.
  const Real t = cp.state.t;
  require(std::isfinite(t), "checkpoint t", t, "a finite time");
  const Real interval = cp.output_interval > 0 ? cp.output_interval : 0;
  const Real slack = 2 * (interval + cp.dt) + 1e-9 * std::abs(t);
  require(std::isfinite(cp.next_output) && std::abs(cp.next_output - t) <= slack,
          "checkpoint next_output", cp.next_output,
          "a time within an output interval of the checkpoint's t = " + to_text(t) + " s");
  sim.restore(cp.snapshot());
}

namespace {

// The first JSON path at which a and b differ, or "" when they are equal.
std::string first_difference(const Json& a, const Json& b, const std::string& path) {
  if (a.is_object() && b.is_object()) {
    for (auto it = a.begin(); it != a.end(); ++it) {
      const std::string child = json_child(path, it.key());
      const auto other = b.find(it.key());
      if (other == b.end()) return child;
      std::string d = first_difference(it.value(), *other, child);
      if (!d.empty()) return d;
    }
    for (auto it = b.begin(); it != b.end(); ++it) {
      if (a.find(it.key()) == a.end()) return json_child(path, it.key());
    }
    return "";
  }
  if (a.is_array() && b.is_array() && a.size() == b.size()) {
    for (std::size_t i = 0; i < a.size(); ++i) {
      std::string d = first_difference(a[i], b[i], json_element(path, i));
      if (!d.empty()) return d;
    }
    return "";
  }
  return a == b ? "" : (path.empty() ? std::string("scene") : path);
}

const Json* at_path(const Json& j, const std::string& path) {
  const Json* current = &j;
  std::string part;
  for (std::size_t i = 0; i <= path.size(); ++i) {
    const char c = i < path.size() ? path[i] : '.';
    if (c != '.' && c != '[' && c != ']') {
      part += c;
      continue;
    }
    if (part.empty()) continue;
    if (current->is_array()) {
      const std::size_t index = std::stoul(part);
      if (index >= current->size()) return nullptr;
      current = &(*current)[index];
    } else {
      const auto it = current->find(part);
      if (it == current->end()) return nullptr;
      current = &*it;
    }
    part.clear();
  }
  return current;
}

// The parts of a scene that decide its trajectory, as JSON.
Json run_defining_json(const Scene& scene) {
  Json j = detail::parse_json(scene_to_json(scene), "scene");
  for (const char* key : {"description", "duration", "output_interval", "divergence", "crush"})
    j.erase(key);
  return j;
}

}  // namespace

void check_same_scene(const Checkpoint& cp, const Scene& scene, const std::string& source) {
  if (cp.scene_json.empty()) {
    throw InputError("--restart " + source +
                     ": the file stores no scene (not written by `jelly run`), so it cannot be "
                     "checked to be a run of this scene");
  }
  Scene recorded;
  try {
    recorded = parse_scene(cp.scene_json, {}, source + " /parameters scene_json");
  } catch (const InputError& e) {
    throw InputError("--restart " + source + ": its stored scene cannot be read: " + e.what());
  }
  const Json was = run_defining_json(recorded);
  const Json now = run_defining_json(scene);
  const std::string path = first_difference(was, now, "");
  if (path.empty()) return;
  const auto text = [&](const Json& j) {
    const Json* v = at_path(j, path);
    return v == nullptr ? std::string("nothing") : json_text(*v);
  };
  throw InputError("--restart " + source + ": its run had " + path + " = " + text(was) +
                   ", this scene has " + text(now) +
                   ": a restart continues the same run (only duration, output_interval, "
                   "divergence, crush and description may change)");
}

}  // namespace jelly
