#include <jelly/io/recording.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <jelly/core/errors.hpp>
#include <jelly/io/detail/h5.hpp>

namespace jelly {

namespace {

std::map<std::string, std::string> attributes_of(hid_t object) {
  std::map<std::string, std::string> map;
  for (auto& [name, value] : h5::read_attributes_as_text(object)) map[name] = value;
  return map;
}

// Throws std::runtime_error "<what>: <why>" unless ok.
void expect(bool ok, const std::string& what, const std::string& why) {
  if (!ok) throw std::runtime_error(what + ": " + why);
}

std::string count_text(std::size_t n) { return std::to_string(n); }

std::vector<VecX> split_frames(const std::vector<double>& data, const std::vector<hsize_t>& dims,
                               std::size_t particles, const std::string& what) {
  std::vector<VecX> frames;
  expect(dims.size() == 3 && dims[2] == 3 && dims[1] == particles, what,
         "not [T][" + count_text(particles) + "][3] (one row per particle of the mass dataset)");
  const Eigen::Index size = static_cast<Eigen::Index>(3 * dims[1]);
  for (hsize_t f = 0; f < dims[0]; ++f) {
    frames.emplace_back(Eigen::Map<const VecX>(data.data() + f * size, size));
  }
  return frames;
}

// A body of a recording: its group under /particles and its place among the particles.
struct BodyGroup {
  std::string name;
  long first = -1;
  std::string group() const { return "/particles/" + name; }
};

// The bodies in the order of their particles (the attribute first_particle; a recording without
// it has one body).
std::vector<BodyGroup> body_groups(hid_t file) {
  h5::Handle particles = h5::open_group(file, "/particles");
  std::vector<BodyGroup> bodies;
  for (const std::string& name : h5::member_names(particles.get())) {
    BodyGroup b{name, -1};
    h5::Handle g = h5::open_group(particles.get(), name);
    if (h5::has_attribute(g.get(), "first_particle")) {
      b.first = h5::read_long_attribute(g.get(), "first_particle");
    }
    bodies.push_back(b);
  }
  expect(!bodies.empty(), "/particles", "no body");
  std::stable_sort(bodies.begin(), bodies.end(),
                   [](const BodyGroup& a, const BodyGroup& b) { return a.first < b.first; });
  return bodies;
}

// The body's render surface from /particles/<body>/surface (global particle indices), if any.
Surface read_surface(hid_t file, const std::string& group, int first, int count) {
  Surface s;
  if (!h5::exists(file, group + "/surface/triangles")) return s;
  const std::string at = group + "/surface/";
  const std::vector<int> triangles = h5::read_ints(file, at + "triangles");
  s.offsets = h5::read_ints(file, at + "vertex_offsets");
  s.particles = h5::read_ints(file, at + "vertex_particles");
  s.weights = h5::read_doubles(file, at + "vertex_weights");
  expect(triangles.size() % 3 == 0, at + "triangles", "not [F][3]");
  for (std::size_t t = 0; t < triangles.size(); t += 3) {
    s.triangles.push_back({triangles[t], triangles[t + 1], triangles[t + 2]});
  }
  for (int& p : s.particles) {
    expect(p >= 0 && p < count, at + "vertex_particles",
           "index " + std::to_string(p) + " outside the body's " + std::to_string(count) +
               " particles");
    p += first;
  }
  return s;
}

Recording read(hid_t file) {
  Recording r;
  std::vector<hsize_t> dims;
  const std::vector<BodyGroup> groups = body_groups(file);
  std::vector<int> counts;
  std::size_t n = 0;
  for (const BodyGroup& b : groups) {
    std::vector<double> mass = h5::read_doubles(file, b.group() + "/mass");
    expect(b.first < 0 || static_cast<std::size_t>(b.first) == n, b.group(),
           "first_particle " + std::to_string(b.first) + " does not follow the bodies before it (" +
               count_text(n) + " particles)");
    expect(n + mass.size() <= static_cast<std::size_t>(std::numeric_limits<int>::max() / 3),
           b.group() + "/mass", "too many particles");
    std::vector<double> rest = h5::read_doubles(file, b.group() + "/rest_position");
    expect(rest.size() == 3 * mass.size(), b.group() + "/rest_position",
           count_text(rest.size()) + " numbers for " + count_text(mass.size()) + " particles");
    r.model.mass.conservativeResize(static_cast<Eigen::Index>(n + mass.size()));
    r.model.mass.tail(static_cast<Eigen::Index>(mass.size())) =
        Eigen::Map<const VecX>(mass.data(), static_cast<Eigen::Index>(mass.size()));
    r.model.rest_position.conservativeResize(static_cast<Eigen::Index>(3 * (n + mass.size())));
    r.model.rest_position.tail(static_cast<Eigen::Index>(rest.size())) =
        Eigen::Map<const VecX>(rest.data(), static_cast<Eigen::Index>(rest.size()));
    counts.push_back(static_cast<int>(mass.size()));
    n += mass.size();
  }
  const std::vector<int> pairs = h5::read_ints(file, "/connectivity/springs");
  const std::vector<int> type = h5::read_ints(file, "/connectivity/type");
  const std::vector<double> rest_length = h5::read_doubles(file, "/connectivity/rest_length");
  const std::vector<double> ks = h5::read_doubles(file, "/connectivity/ks");
  const std::vector<double> kd = h5::read_doubles(file, "/connectivity/kd");
  const std::size_t m = type.size();
  expect(m <= static_cast<std::size_t>(std::numeric_limits<int>::max()), "/connectivity/type",
         "too many springs");
  expect(pairs.size() == 2 * m, "/connectivity/springs",
         count_text(pairs.size()) + " indices for " + count_text(m) + " springs");
  for (const auto& [name, size] :
       {std::pair<const char*, std::size_t>{"rest_length", rest_length.size()},
        {"ks", ks.size()},
        {"kd", kd.size()}}) {
    expect(size == m, std::string("/connectivity/") + name,
           count_text(size) + " values for " + count_text(m) + " springs");
  }
  for (size_t i = 0; i < m; ++i) {
    expect(type[i] >= 0 && type[i] < kSpringTypeCount, "/connectivity/type",
           "spring " + count_text(i) + " has type " + std::to_string(type[i]) +
               " (0 structural, 1 shear, 2 bending)");
    r.model.springs.add(pairs[2 * i], pairs[2 * i + 1], rest_length[i], {ks[i], kd[i]},
                        static_cast<SpringType>(type[i]));
  }
  // The bodies: ranges of particles and of the springs (which follow each other body by body).
  {
    int first = 0, spring = 0;
    for (std::size_t bi = 0; bi < groups.size(); ++bi) {
      Body body;
      body.name = groups[bi].name;
      body.first_particle = first;
      body.num_particles = counts[bi];
      body.first_spring = spring;
      while (spring < static_cast<int>(m) && pairs[2 * spring] < first + counts[bi]) ++spring;
      body.num_springs = spring - body.first_spring;
      h5::Handle g = h5::open_group(file, groups[bi].group());
      if (h5::has_attribute(g.get(), "kind"))
        body.kind = h5::read_string_attribute(g.get(), "kind");
      if (h5::has_attribute(g.get(), "radius"))
        body.radius = h5::read_double_attribute(g.get(), "radius");
      if (h5::has_attribute(g.get(), "spacing"))
        body.spacing = h5::read_double_attribute(g.get(), "spacing");
      if (h5::has_attribute(g.get(), "thickness")) {
        body.thickness = h5::read_double_attribute(g.get(), "thickness");
        expect(std::isfinite(body.thickness) && body.thickness >= 0,
               groups[bi].group() + " attribute thickness",
               std::to_string(body.thickness) + " is not a distance >= 0 (m)");
      }
      if (h5::has_attribute(g.get(), "color")) {
        // sRGB [r, g, b] in [0, 1], written as space-separated text by the attribute reader.
        std::istringstream text(attributes_of(g.get())["color"]);
        Vec3 c = Vec3::Constant(-1);
        text >> c.x() >> c.y() >> c.z();
        expect(!text.fail() && c.allFinite() && c.minCoeff() >= 0 && c.maxCoeff() <= 1,
               groups[bi].group() + " attribute color", "not [r, g, b] in [0, 1]");
        body.color = c;
      }
      body.surface = read_surface(file, groups[bi].group(), first, counts[bi]);
      r.model.bodies.push_back(std::move(body));
      first += counts[bi];
    }
  }
  h5::Handle parameters = h5::open_group(file, "/parameters");
  r.attributes = attributes_of(parameters.get());
  r.scene_json = h5::read_string_attribute(parameters.get(), "scene_json");
  if (h5::has_attribute(parameters.get(), "gravity")) {
    const std::string g = r.attributes["gravity"];
    std::istringstream in(g);
    in >> r.model.gravity.x() >> r.model.gravity.y() >> r.model.gravity.z();
  }

  const std::string clock = groups.front().group() + "/position/";
  // A killed run's last frames may not read (h5::Frames): every frame series keeps the frames
  // that do, and the frames all of them hold are kept below. A run that finished (its status
  // written by on_finish after the last flush) stored every frame: one that does not read (a
  // corrupt compressed chunk) is damage, an error naming the dataset, not a shorter recording.
  const auto status = r.attributes.find("run_status");
  const bool finished = status != r.attributes.end() && status->second != "running";
  const h5::Frames kReadable = finished ? h5::Frames::kAll : h5::Frames::kLeadingReadable;
  r.time = h5::read_doubles(file, clock + "time", nullptr, kReadable);
  r.step = h5::read_longs(file, clock + "step", nullptr, kReadable);
  try {
    r.model.validate();
  } catch (const InputError& e) {
    throw std::runtime_error(std::string("its model is invalid: ") + e.what());
  }
  // Every frame's positions and velocities, the bodies' rows one after the other.
  for (std::size_t bi = 0; bi < groups.size(); ++bi) {
    const std::size_t count = static_cast<std::size_t>(counts[bi]);
    const Eigen::Index first = 3 * static_cast<Eigen::Index>(r.model.bodies[bi].first_particle);
    for (auto [series, frames] :
         {std::pair{"/position/value", &r.position}, std::pair{"/velocity/value", &r.velocity}}) {
      const std::string path = groups[bi].group() + series;
      const std::vector<VecX> body_frames =
          split_frames(h5::read_doubles(file, path, &dims, kReadable), dims, count, path);
      if (bi == 0) {
        frames->assign(body_frames.size(), VecX::Zero(static_cast<Eigen::Index>(3 * n)));
      }
      const std::size_t common = std::min(frames->size(), body_frames.size());
      frames->resize(common);
      for (std::size_t f = 0; f < common; ++f) {
        (*frames)[f].segment(first, static_cast<Eigen::Index>(3 * count)) = body_frames[f];
      }
    }
  }
  // A killed run may have flushed one series further than another: keep the common frames.
  const size_t frames =
      std::min({r.time.size(), r.step.size(), r.position.size(), r.velocity.size()});
  r.time.resize(frames);
  r.step.resize(frames);
  r.position.resize(frames);
  r.velocity.resize(frames);

  h5::Handle observables = h5::open_group(file, "/observables");
  for (const std::string& name : h5::member_names(observables.get())) {
    const std::vector<double> v =
        h5::read_doubles(observables.get(), name + "/value", &dims, kReadable);
    expect(dims.size() == 1 || (dims.size() == 2 && dims[1] == 3), "/observables/" + name,
           "not [T] or [T][3]");
    const Eigen::Index rows = static_cast<Eigen::Index>(dims[0]);
    const Eigen::Index cols = dims.size() > 1 ? static_cast<Eigen::Index>(dims[1]) : 1;
    r.observables[name] =
        Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
            v.data(), rows, cols);
  }
  h5::Handle terrain = h5::open_group(file, "/terrain");
  for (const std::string& name : h5::member_names(terrain.get())) {
    TerrainTrack track;
    track.name = name;
    h5::Handle g = h5::open_group(terrain.get(), name);
    track.attributes = attributes_of(g.get());
    track.kind = track.attributes["kind"];
    const std::vector<double> p = h5::read_doubles(g.get(), "position/value");
    for (size_t i = 0; i + 2 < p.size(); i += 3)
      track.position.emplace_back(p[i], p[i + 1], p[i + 2]);
    r.terrains.push_back(std::move(track));
  }
  return r;
}

}  // namespace

std::vector<Real> exact_frame_times(const std::vector<Real>& time, Real dt, Real output_interval) {
  std::vector<Real> exact(time);
  if (!(dt > 0) || !std::isfinite(dt)) return exact;
  const Real tolerance = 1e-3 * dt;
  // The nearest multiple of `every`, when within the tolerance.
  const auto snap = [&](Real t, Real every, Real& out) {
    if (!(every > 0) || !std::isfinite(every)) return false;
    const Real k = std::round(t / every);
    if (std::abs(t - k * every) > tolerance) return false;
    out = k * every;
    return true;
  };
  for (Real& t : exact)
    if (std::isfinite(t) && !snap(t, output_interval, t)) snap(t, dt, t);
  return exact;
}

std::vector<Real> exact_frame_times(const Recording& recording) {
  const auto number = [&](const char* name) {
    const auto it = recording.attributes.find(name);
    if (it == recording.attributes.end()) return 0.0;
    try {
      return std::stod(it->second);
    } catch (const std::logic_error&) {
      return 0.0;
    }
  };
  return exact_frame_times(recording.time, number("dt"), number("output_interval"));
}

Recording read_recording(const std::string& path) {
  std::lock_guard<std::recursive_mutex> lock(h5::library_mutex());
  h5::QuietErrors quiet;
  h5::Handle file = h5::open_file(path);
  try {
    return read(file.get());
  } catch (const std::exception& e) {
    throw InputError("'" + path + "' is not a readable jelly recording: " + e.what());
  }
}

std::string describe_recording(const std::string& path) {
  std::lock_guard<std::recursive_mutex> lock(h5::library_mutex());
  h5::QuietErrors quiet;
  h5::Handle file = h5::open_file(path);
  std::ostringstream out;
  try {
    const hid_t f = file.get();
    // The validation every reader of a recording makes (read_recording): a damaged file is
    // refused here too, not described as if whole.
    (void)read(f);
    h5::Handle h5md = h5::open_group(f, "/h5md");
    h5::Handle par = h5::open_group(f, "/parameters");
    auto attributes = attributes_of(par.get());
    const auto attribute = [&](const std::string& name) {
      auto it = attributes.find(name);
      return it == attributes.end() ? std::string("-") : it->second;
    };
    // Numbers with 6 significant digits for reading (the attributes keep full precision).
    const auto number = [&](const std::string& name) {
      if (!h5::has_attribute(par.get(), name)) return std::string("-");
      std::ostringstream text;
      text << h5::read_double_attribute(par.get(), name);
      return text.str();
    };
    out << "file:          " << path << " (" << std::filesystem::file_size(path) << " bytes)\n";
    out << "creator:       " << h5::read_string_attribute(h5md.get(), "creator") << ' '
        << h5::read_string_attribute(h5md.get(), "creator_version") << '\n';
    const std::vector<BodyGroup> bodies = body_groups(f);
    hsize_t particles = 0;
    std::ostringstream listing;
    for (const BodyGroup& b : bodies) {
      h5::Handle mass = h5::open_dataset(f, b.group() + "/mass");
      const hsize_t count = h5::dataset_dims(mass.get()).at(0);
      particles += count;
      h5::Handle g = h5::open_group(f, b.group());
      listing << (listing.tellp() > 0 ? ", " : "") << b.name << " (";
      if (h5::has_attribute(g.get(), "kind")) {
        listing << h5::read_string_attribute(g.get(), "kind") << ", ";
      }
      listing << count << " particles";
      if (h5::exists(f, b.group() + "/surface/triangles")) {
        h5::Handle t = h5::open_dataset(f, b.group() + "/surface/triangles");
        listing << ", surface of " << h5::dataset_dims(t.get()).at(0) << " triangles";
      }
      listing << ")";
    }
    out << "particles:     " << particles << '\n';
    out << "bodies:        " << listing.str() << '\n';
    const std::vector<int> type = h5::read_ints(f, "/connectivity/type");
    int counts[kSpringTypeCount] = {0, 0, 0};
    for (int t : type) {
      if (t >= 0 && t < kSpringTypeCount) ++counts[t];
    }
    out << "springs:       " << type.size() << " (";
    for (int t = 0; t < kSpringTypeCount; ++t) {
      out << (t ? ", " : "") << counts[t] << ' ' << spring_type_name(static_cast<SpringType>(t));
    }
    out << ")\n";
    const std::vector<double> time = h5::read_doubles(f, bodies.front().group() + "/position/time");
    h5::Handle value = h5::open_dataset(f, bodies.front().group() + "/position/value");
    const hsize_t frames = std::min<hsize_t>(time.size(), h5::dataset_dims(value.get()).at(0));
    out << "frames:        " << frames;
    if (frames > 0) out << ", t = " << time.front() << " .. " << time[frames - 1] << " s";
    out << '\n';
    out << "integrator:    " << attribute("integrator") << ", dt = " << number("dt")
        << " s, output every " << number("output_interval") << " s\n";
    out << "status:        " << attribute("run_status");
    if (attribute("run_status") != "running") {
      out << " at t = " << number("run_t") << " s, " << attribute("run_steps") << " steps, "
          << number("run_wall_seconds") << " s wall, " << attribute("run_force_evaluations")
          << " force evaluations";
      if (!attribute("run_reason").empty() && attribute("run_reason") != "-") {
        out << " (" << attribute("run_reason") << ")";
      }
    } else {
      out << " (the run did not finish: killed, crashed or still going)";
    }
    out << '\n';
    h5::Handle observables = h5::open_group(f, "/observables");
    out << "observables:  ";
    for (const std::string& name : h5::member_names(observables.get())) out << ' ' << name;
    out << '\n';
    h5::Handle terrain = h5::open_group(f, "/terrain");
    out << "terrains:     ";
    const auto names = h5::member_names(terrain.get());
    if (names.empty()) out << " none";
    for (const std::string& name : names) out << ' ' << name;
    out << '\n';
    out << "scene:         "
        << (attribute("scene_json").empty() ? "not stored" : "stored as /parameters scene_json")
        << '\n';
  } catch (const std::exception& e) {
    throw InputError("'" + path + "' is not a readable jelly recording: " + e.what());
  }
  return out.str();
}

}  // namespace jelly
