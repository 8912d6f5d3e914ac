#include <jelly/io/recording.hpp>

#include <filesystem>
#include <iomanip>
#include <limits>
#include <sstream>

#include <jelly/core/errors.hpp>
#include <jelly/io/detail/h5.hpp>

namespace jelly {

namespace {

std::vector<std::string> member_names(hid_t group) {
  std::vector<std::string> names;
  H5Literate(
      group, H5_INDEX_NAME, H5_ITER_INC, nullptr,
      [](hid_t, const char* name, const H5L_info_t*, void* out) -> herr_t {
        static_cast<std::vector<std::string>*>(out)->emplace_back(name);
        return 0;
      },
      &names);
  return names;
}

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

Recording read(hid_t file) {
  Recording r;
  std::vector<hsize_t> dims;
  std::vector<double> mass = h5::read_doubles(file, "/particles/jelly/mass");
  r.model.mass = Eigen::Map<const VecX>(mass.data(), static_cast<Eigen::Index>(mass.size()));
  const std::size_t n = mass.size();
  expect(n <= static_cast<std::size_t>(std::numeric_limits<int>::max() / 3),
         "/particles/jelly/mass", "too many particles");
  std::vector<double> rest = h5::read_doubles(file, "/particles/jelly/rest_position");
  expect(rest.size() == 3 * n, "/particles/jelly/rest_position",
         count_text(rest.size()) + " numbers for " + count_text(n) + " particles");
  r.model.rest_position =
      Eigen::Map<const VecX>(rest.data(), static_cast<Eigen::Index>(rest.size()));
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
  h5::Handle parameters = h5::open_group(file, "/parameters");
  r.attributes = attributes_of(parameters.get());
  r.scene_json = h5::read_string_attribute(parameters.get(), "scene_json");
  std::vector<hsize_t> gdims;
  if (h5::has_attribute(parameters.get(), "gravity")) {
    const std::string g = r.attributes["gravity"];
    std::istringstream in(g);
    in >> r.model.gravity.x() >> r.model.gravity.y() >> r.model.gravity.z();
  }

  r.time = h5::read_doubles(file, "/particles/jelly/position/time");
  r.step = h5::read_longs(file, "/particles/jelly/position/step");
  try {
    r.model.validate();
  } catch (const InputError& e) {
    throw std::runtime_error(std::string("its model is invalid: ") + e.what());
  }
  r.position = split_frames(h5::read_doubles(file, "/particles/jelly/position/value", &dims), dims,
                            n, "/particles/jelly/position/value");
  r.velocity = split_frames(h5::read_doubles(file, "/particles/jelly/velocity/value", &dims), dims,
                            n, "/particles/jelly/velocity/value");
  // A killed run may have flushed one series further than another: keep the common frames.
  const size_t frames =
      std::min({r.time.size(), r.step.size(), r.position.size(), r.velocity.size()});
  r.time.resize(frames);
  r.step.resize(frames);
  r.position.resize(frames);
  r.velocity.resize(frames);

  h5::Handle observables = h5::open_group(file, "/observables");
  for (const std::string& name : member_names(observables.get())) {
    const std::vector<double> v = h5::read_doubles(observables.get(), name + "/value", &dims);
    expect(dims.size() == 1 || (dims.size() == 2 && dims[1] == 3), "/observables/" + name,
           "not [T] or [T][3]");
    const Eigen::Index rows = static_cast<Eigen::Index>(dims[0]);
    const Eigen::Index cols = dims.size() > 1 ? static_cast<Eigen::Index>(dims[1]) : 1;
    r.observables[name] =
        Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
            v.data(), rows, cols);
  }
  h5::Handle terrain = h5::open_group(file, "/terrain");
  for (const std::string& name : member_names(terrain.get())) {
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
    h5::Handle mass = h5::open_dataset(f, "/particles/jelly/mass");
    out << "particles:     " << h5::dataset_dims(mass.get()).at(0) << '\n';
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
    const std::vector<double> time = h5::read_doubles(f, "/particles/jelly/position/time");
    h5::Handle value = h5::open_dataset(f, "/particles/jelly/position/value");
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
    for (const std::string& name : member_names(observables.get())) out << ' ' << name;
    out << '\n';
    h5::Handle terrain = h5::open_group(f, "/terrain");
    out << "terrains:     ";
    const auto names = member_names(terrain.get());
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
