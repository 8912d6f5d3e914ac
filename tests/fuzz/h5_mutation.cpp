#include "fuzz/h5_mutation.hpp"

#include <hdf5.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/io/h5_recorder.hpp>

namespace jelly::fuzz {

namespace {

const char* const kScenes[kPristineCount] = {
    R"({"cube": {"n": 2, "edge_length": 1, "origin": [-0.5, 0.3, -0.5]},
        "terrains": [{"kind": "slope", "contact": {"model": "seed"}}],
        "integrator": {"name": "rk4", "dt": 0.001}, "duration": 0.2, "output_interval": 0.02})",
    R"({"cube": {"n": 2, "edge_length": 1, "origin": [-0.5, 0.02, -0.5]},
        "terrains": [{"kind": "plane"}],
        "integrator": {"name": "implicit_euler", "dt": 0.01}, "duration": 0.2,
        "output_interval": 0.02})",
    // Two cubes, the upper one landing on the lower within 0.1 s: the checkpoint holds
    // implicit_euler's contact pairs between bodies.
    R"({"bodies": [{"kind": "cube", "name": "low", "n": 2, "edge_length": 0.5,
                    "origin": [-0.25, 0.01, -0.25]},
                   {"kind": "cube", "name": "high", "n": 2, "edge_length": 0.5,
                    "origin": [-0.25, 1.03, -0.25]}],
        "terrains": [{"kind": "plane"}],
        "integrator": {"name": "implicit_euler", "dt": 0.01}, "duration": 0.2,
        "output_interval": 0.02})"};

struct Pristine {
  Scene scene;
  std::string bytes;                  // the file
  std::vector<std::string> datasets;  // every dataset path
  std::vector<std::string> objects;   // every group and dataset path
  std::vector<std::string> attribute_names;
};

std::string scratch_dir() {
  // Never destroyed: the atexit handler that removes the folder runs after the destructors of
  // statics constructed after its registration, this one among them (a use after free that
  // AddressSanitizer reported at the fuzzer's exit).
  static const std::string& dir = *new std::string([] {
    const std::string base = std::filesystem::exists("/dev/shm") ? "/dev/shm" : "/tmp";
    std::string pattern = base + "/jelly-fuzz-XXXXXX";
    if (mkdtemp(pattern.data()) == nullptr) std::abort();
    std::atexit([] { std::filesystem::remove_all(scratch_dir()); });
    return pattern;
  }());
  return dir;
}

herr_t visit(hid_t, const char* name, const H5O_info_t* info, void* data) {
  auto& p = *static_cast<Pristine*>(data);
  const std::string path = std::string("/") + name;
  if (path == "/.") return 0;
  p.objects.push_back(path);
  if (info->type == H5O_TYPE_DATASET) p.datasets.push_back(path);
  return 0;
}

herr_t collect_attribute(hid_t, const char* name, const H5A_info_t*, void* data) {
  auto& names = *static_cast<std::vector<std::string>*>(data);
  if (std::find(names.begin(), names.end(), name) == names.end()) names.emplace_back(name);
  return 0;
}

Pristine make_pristine(int which) {
  Pristine p;
  p.scene = parse_scene(kScenes[which]);
  const std::string path = scratch_dir() + "/pristine" + std::to_string(which) + ".h5";
  std::filesystem::remove(path);
  {
    Simulator sim = make_simulator(p.scene);
    RecorderOptions options;
    options.scene_json = scene_to_json(p.scene);
    options.flush_every_frames = 2;
    options.write_xdmf = false;
    options.background_writer = false;
    H5Recorder recorder(path, sim, options);
    sim.add_observer(recorder);
    sim.run_until(p.scene.duration);
  }
  std::ifstream in(path, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  p.bytes = bytes.str();
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  H5Ovisit2(file, H5_INDEX_NAME, H5_ITER_INC, visit, &p, H5O_INFO_BASIC);
  for (const std::string& object : p.objects) {
    const hid_t o = H5Oopen(file, object.c_str(), H5P_DEFAULT);
    H5Aiterate2(o, H5_INDEX_NAME, H5_ITER_INC, nullptr, collect_attribute, &p.attribute_names);
    H5Oclose(o);
  }
  H5Fclose(file);
  std::filesystem::remove(path);
  return p;
}

const Pristine& pristine(int which) {
  static const std::vector<Pristine> all = [] {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // the edits fail often; quietly
    std::vector<Pristine> v;
    for (int i = 0; i < kPristineCount; ++i) v.push_back(make_pristine(i));
    return v;
  }();
  return all[which];
}

bool focused(const std::string& path) {
  return path.rfind("/checkpoint", 0) == 0 || path.rfind("/parameters", 0) == 0;
}

const std::string& pick_from(FuzzInput& in, const std::vector<std::string>& all,
                             bool checkpoint_focus) {
  static std::vector<std::string> chosen;
  chosen.clear();
  for (const std::string& s : all) {
    if (!checkpoint_focus || focused(s)) chosen.push_back(s);
  }
  if (chosen.empty()) chosen.push_back("/checkpoint");
  return chosen[in.pick(chosen.size())];
}

hsize_t pick_extent(FuzzInput& in) {
  static constexpr hsize_t kExtents[] = {0, 1, 2, 3, 4, 5, 8, 11, 28, 29, 64, 1 << 20};
  return kExtents[in.pick(sizeof kExtents / sizeof kExtents[0])];
}

// Writes `values` (count elements, as doubles converted by HDF5) into a new dataset.
void create_dataset(hid_t file, const std::string& path, const std::vector<hsize_t>& dims,
                    hid_t file_type, FuzzInput& in) {
  hsize_t count = 1;
  for (hsize_t d : dims) count *= d;
  const hid_t space = dims.empty()
                          ? H5Screate(H5S_SCALAR)
                          : H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr);
  const hid_t properties = H5Pcreate(H5P_DATASET_CREATE);
  if (!dims.empty() && count > 4096) {  // claimed, not stored: chunked and left unwritten
    std::vector<hsize_t> chunk(dims.size(), 1);
    H5Pset_chunk(properties, static_cast<int>(chunk.size()), chunk.data());
  }
  const hid_t dataset =
      H5Dcreate2(file, path.c_str(), file_type, space, H5P_DEFAULT, properties, H5P_DEFAULT);
  if (dataset >= 0 && count <= 4096 && count > 0) {
    if (H5Tget_class(file_type) == H5T_INTEGER) {
      std::vector<long> values(count);
      for (long& v : values) v = in.flag() ? static_cast<long>(in.byte()) - 2 : in.integer();
      H5Dwrite(dataset, H5T_NATIVE_LONG, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data());
    } else {
      std::vector<double> values(count);
      for (double& v : values) v = in.number();
      H5Dwrite(dataset, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data());
    }
  }
  if (dataset >= 0) H5Dclose(dataset);
  H5Pclose(properties);
  H5Sclose(space);
}

std::vector<hsize_t> dims_of(hid_t file, const std::string& path) {
  std::vector<hsize_t> dims;
  const hid_t dataset = H5Dopen2(file, path.c_str(), H5P_DEFAULT);
  if (dataset < 0) return dims;
  const hid_t space = H5Dget_space(dataset);
  const int rank = H5Sget_simple_extent_ndims(space);
  if (rank > 0) {
    dims.resize(static_cast<size_t>(rank));
    H5Sget_simple_extent_dims(space, dims.data(), nullptr);
  }
  H5Sclose(space);
  H5Dclose(dataset);
  return dims;
}

void replace_dataset(hid_t file, const std::string& path, FuzzInput& in) {
  std::vector<hsize_t> dims;
  const std::size_t rank = in.pick(4);
  for (std::size_t i = 0; i < rank; ++i) dims.push_back(pick_extent(in));
  static const hid_t kTypes[] = {H5T_IEEE_F64LE, H5T_STD_I32LE, H5T_STD_I64LE, H5T_IEEE_F32LE};
  const hid_t type = kTypes[in.pick(4)];
  H5Ldelete(file, path.c_str(), H5P_DEFAULT);
  create_dataset(file, path, dims, type, in);
}

// The same dataset with a first extent a little different (the lengths of parallel arrays then
// disagree), filled with fresh values.
void resize_dataset(hid_t file, const std::string& path, FuzzInput& in) {
  std::vector<hsize_t> dims = dims_of(file, path);
  if (dims.empty()) dims.push_back(1);
  static constexpr long kDelta[] = {-1, 1, -3, 3, -1000000, 2};
  const long delta = kDelta[in.pick(6)];
  const long first = static_cast<long>(dims[0]);
  dims[0] = static_cast<hsize_t>(
      std::max(0L, delta == 2 ? 2 * first : (delta == -1000000 ? 0 : first + delta)));
  const hid_t dataset = H5Dopen2(file, path.c_str(), H5P_DEFAULT);
  hid_t type = H5T_IEEE_F64LE;
  if (dataset >= 0) {
    const hid_t t = H5Dget_type(dataset);
    if (H5Tget_class(t) == H5T_INTEGER) type = H5T_STD_I32LE;
    H5Tclose(t);
    H5Dclose(dataset);
  }
  H5Ldelete(file, path.c_str(), H5P_DEFAULT);
  create_dataset(file, path, dims, type, in);
}

void poke_value(hid_t file, const std::string& path, FuzzInput& in) {
  const hid_t dataset = H5Dopen2(file, path.c_str(), H5P_DEFAULT);
  if (dataset < 0) return;
  const hid_t space = H5Dget_space(dataset);
  const hssize_t points = H5Sget_simple_extent_npoints(space);
  if (points > 0 && points <= 1 << 20) {
    const hsize_t element = in.pick(static_cast<std::size_t>(points));
    const int rank = H5Sget_simple_extent_ndims(space);
    std::vector<hsize_t> dims(static_cast<size_t>(std::max(rank, 1)), 1), at(dims.size(), 0);
    if (rank > 0) H5Sget_simple_extent_dims(space, dims.data(), nullptr);
    hsize_t rest = element;
    for (int i = rank - 1; i >= 0; --i) {
      at[static_cast<size_t>(i)] = rest % dims[static_cast<size_t>(i)];
      rest /= dims[static_cast<size_t>(i)];
    }
    if (rank > 0) H5Sselect_elements(space, H5S_SELECT_SET, 1, at.data());
    const hsize_t one = 1;
    const hid_t memory = H5Screate_simple(1, &one, nullptr);
    const hid_t t = H5Dget_type(dataset);
    if (H5Tget_class(t) == H5T_INTEGER) {
      const long v = in.flag() ? static_cast<long>(in.byte()) - 2 : in.integer();
      H5Dwrite(dataset, H5T_NATIVE_LONG, memory, space, H5P_DEFAULT, &v);
    } else if (H5Tget_class(t) == H5T_FLOAT) {
      const double v = in.number();
      H5Dwrite(dataset, H5T_NATIVE_DOUBLE, memory, space, H5P_DEFAULT, &v);
    }
    H5Tclose(t);
    H5Sclose(memory);
  }
  H5Sclose(space);
  H5Dclose(dataset);
}

void set_attribute(hid_t file, const std::string& object, const std::string& name, FuzzInput& in,
                   const std::string& scene_json) {
  const hid_t o = H5Oopen(file, object.c_str(), H5P_DEFAULT);
  if (o < 0) return;
  H5Adelete(o, name.c_str());
  const std::size_t kind = in.pick(5);
  if (kind <= 1) {  // a number, or several where one belongs
    const hsize_t n = kind == 0 ? 1 : in.pick(6);
    const hid_t space = kind == 0 ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &n, nullptr);
    std::vector<double> values(std::max<hsize_t>(n, 1));
    for (double& v : values) v = in.number();
    const hid_t a = H5Acreate2(o, name.c_str(), H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT);
    if (a >= 0) {
      H5Awrite(a, H5T_NATIVE_DOUBLE, values.data());
      H5Aclose(a);
    }
    H5Sclose(space);
  } else if (kind == 2) {
    const long v = in.integer();
    const hid_t space = H5Screate(H5S_SCALAR);
    const hid_t a = H5Acreate2(o, name.c_str(), H5T_STD_I64LE, space, H5P_DEFAULT, H5P_DEFAULT);
    if (a >= 0) {
      H5Awrite(a, H5T_NATIVE_LONG, &v);
      H5Aclose(a);
    }
    H5Sclose(space);
  } else {  // text: from the input, or the stored scene with one --set edit
    std::string text = in.text(200);
    if (kind == 4) {
      try {
        text = apply_override(scene_json, text);
      } catch (const InputError&) {
      }
    }
    const hid_t type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, in.flag() ? H5T_VARIABLE : std::max<std::size_t>(text.size(), 1));
    const hid_t space = H5Screate(H5S_SCALAR);
    const hid_t a = H5Acreate2(o, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT);
    if (a >= 0) {
      if (H5Tis_variable_str(type) > 0) {
        const char* p = text.c_str();
        H5Awrite(a, type, &p);
      } else {
        text.resize(std::max<std::size_t>(text.size(), 1));
        H5Awrite(a, type, text.data());
      }
      H5Aclose(a);
    }
    H5Sclose(space);
    H5Tclose(type);
  }
  H5Oclose(o);
}

}  // namespace

const Scene& pristine_scene(int which) { return pristine(which).scene; }

void prepare_pristine() { (void)pristine(0); }

Mutated mutated_recording(FuzzInput& in, bool checkpoint_focus) {
  Mutated m;
  m.which = static_cast<int>(in.pick(kPristineCount));
  const Pristine& p = pristine(m.which);
  m.path = scratch_dir() + "/mutated.h5";
  {
    std::ofstream out(m.path, std::ios::binary | std::ios::trunc);
    out.write(p.bytes.data(), static_cast<std::streamsize>(p.bytes.size()));
  }
  const hid_t file = H5Fopen(m.path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  if (file < 0) std::abort();
  const std::string scene_json = scene_to_json(p.scene);
  for (int op = 0; op < 6 && !in.empty(); ++op) {
    switch (in.pick(8)) {
      case 0:
        replace_dataset(file, pick_from(in, p.datasets, checkpoint_focus), in);
        break;
      case 1:
      case 2:
        resize_dataset(file, pick_from(in, p.datasets, checkpoint_focus), in);
        break;
      case 3:
        H5Ldelete(file, pick_from(in, p.objects, checkpoint_focus).c_str(), H5P_DEFAULT);
        break;
      case 4:
      case 5: {
        const std::string& object = pick_from(in, p.objects, checkpoint_focus);
        const std::string name =
            in.flag() ? p.attribute_names[in.pick(p.attribute_names.size())] : in.text(12);
        set_attribute(file, in.flag() ? std::string("/parameters") : object, name, in, scene_json);
        break;
      }
      case 6:
        poke_value(file, pick_from(in, p.datasets, checkpoint_focus), in);
        break;
      case 7: {  // two datasets swap places
        const std::string a = pick_from(in, p.datasets, checkpoint_focus);
        const std::string b = pick_from(in, p.datasets, checkpoint_focus);
        if (a != b) {
          H5Lmove(file, a.c_str(), file, "/swap", H5P_DEFAULT, H5P_DEFAULT);
          H5Lmove(file, b.c_str(), file, a.c_str(), H5P_DEFAULT, H5P_DEFAULT);
          H5Lmove(file, "/swap", file, b.c_str(), H5P_DEFAULT, H5P_DEFAULT);
        }
        break;
      }
    }
  }
  H5Fclose(file);
  return m;
}

}  // namespace jelly::fuzz
