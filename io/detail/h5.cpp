#include <jelly/io/detail/h5.hpp>

#include <algorithm>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include <jelly/core/detail/input_file.hpp>
#include <jelly/core/errors.hpp>

namespace jelly::h5 {

std::recursive_mutex& library_mutex() {
  static std::recursive_mutex mutex;
  return mutex;
}

QuietErrors::QuietErrors() {
  H5Eget_auto2(H5E_DEFAULT, &func_, &data_);
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
}

QuietErrors::~QuietErrors() { H5Eset_auto2(H5E_DEFAULT, func_, data_); }

namespace {

herr_t collect_error(unsigned /*n*/, const H5E_error2_t* error, void* out) {
  auto& messages = *static_cast<std::vector<std::string>*>(out);
  if (error->desc == nullptr || error->desc[0] == '\0') return 0;
  // The file driver's long report ("... errno = 28, error message = 'No space left on device',
  // buf = ...") is reduced to the operating system's message.
  std::string text = error->desc;
  const std::string key = "error message = '";
  const size_t start = text.find(key);
  if (start != std::string::npos) {
    const size_t end = text.find('\'', start + key.size());
    text =
        text.substr(start + key.size(), end == std::string::npos ? end : end - start - key.size());
  }
  messages.push_back(std::move(text));
  return 0;
}

hid_t string_type() {
  const hid_t type = H5Tcopy(H5T_C_S1);
  H5Tset_size(type, H5T_VARIABLE);
  H5Tset_cset(type, H5T_CSET_UTF8);
  return type;
}

void remove_attribute(hid_t object, const std::string& name) {
  if (H5Aexists(object, name.c_str()) > 0) check(H5Adelete(object, name.c_str()), "delete " + name);
}

void write_attribute_raw(hid_t object, const std::string& name, hid_t file_type, hid_t memory_type,
                         const std::vector<hsize_t>& dims, const void* data) {
  remove_attribute(object, name);
  Handle space(dims.empty() ? H5Screate(H5S_SCALAR)
                            : H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr),
               "dataspace for attribute " + name);
  Handle attribute(
      H5Acreate2(object, name.c_str(), file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT),
      "create attribute " + name);
  check(H5Awrite(attribute.get(), memory_type, data), "write attribute " + name);
}

// The leading frames of a time series that read, one frame at a time, up to the first that
// does not (a run killed mid-write can leave chunks the file's index names but never stored).
// `dims` is shortened to the frames kept.
template <typename T>
void read_leading_frames(hid_t dataset, const std::string& name, hid_t memory_type,
                         std::vector<hsize_t>& dims, std::vector<T>& data) {
  const hsize_t frame_values = dims[0] == 0 ? 0 : data.size() / dims[0];
  Handle file_space(H5Dget_space(dataset), "dataspace");
  std::vector<hsize_t> start(dims.size(), 0), count = dims;
  count[0] = 1;
  Handle memory_space(H5Screate_simple(static_cast<int>(count.size()), count.data(), nullptr),
                      "frame dataspace");
  const auto read_frame = [&](hsize_t frame) {
    start[0] = frame;
    return H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start.data(), nullptr,
                               count.data(), nullptr) >= 0 &&
           H5Dread(dataset, memory_type, memory_space.get(), file_space.get(), H5P_DEFAULT,
                   data.data() + frame * frame_values) >= 0;
  };
  hsize_t frames = 0;
  while (frames < dims[0] && read_frame(frames)) ++frames;
  // A killed run loses its last frames, never one before frames that read: an unreadable frame
  // followed by a readable last frame is damage (a corrupt chunk), not a shorter run.
  if (frames + 1 < dims[0] && read_frame(dims[0] - 1)) {
    throw std::runtime_error("HDF5: frame " + std::to_string(frames) + " of " + name + " of " +
                             std::to_string(dims[0]) +
                             " does not read (a corrupt chunk) while later frames do");
  }
  H5Eclear2(H5E_DEFAULT);
  dims[0] = frames;
  data.resize(frames * frame_values);
}

template <typename T>
std::vector<T> read_all(hid_t parent, const std::string& name, hid_t memory_type,
                        std::vector<hsize_t>* dims_out, Frames frames = Frames::kAll) {
  Handle dataset = open_dataset(parent, name);
  std::vector<hsize_t> dims = dataset_dims(dataset.get());
  // A file can claim any shape (its chunks need not exist): refuse before allocating more than
  // kMaxReadBytes, or more than its stored bytes could hold (deflate expands at most about
  // 1032 times; jelly's files store every chunk they claim).
  const hsize_t stored = H5Dget_storage_size(dataset.get());
  const hsize_t limit =
      std::min<hsize_t>(kMaxReadBytes, std::max<hsize_t>(1 << 20, 1100 * stored)) / sizeof(T);
  hsize_t count = 1;
  for (hsize_t d : dims) {
    if (d != 0 && count > limit / d) {
      throw std::runtime_error("HDF5: dataset " + name + " claims more values than it stores (" +
                               std::to_string(stored) + " bytes) or than " +
                               std::to_string(kMaxReadBytes >> 30) + " GiB");
    }
    count *= d;
  }
  std::vector<T> data(count);
  if (count > 0 &&
      H5Dread(dataset.get(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()) < 0) {
    if (frames != Frames::kLeadingReadable || dims.empty()) check(-1, "read " + name);
    read_leading_frames(dataset.get(), name, memory_type, dims, data);
  }
  if (dims_out != nullptr) *dims_out = dims;
  return data;
}

}  // namespace

std::string error_text() {
  std::vector<std::string> messages;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_DOWNWARD, collect_error, &messages);
  if (messages.empty()) return "unknown HDF5 error";
  // The deepest two entries carry the cause (e.g. the operating system's message).
  std::string text;
  const size_t first = messages.size() > 2 ? messages.size() - 2 : 0;
  for (size_t i = first; i < messages.size(); ++i) {
    if (!text.empty()) text += "; ";
    text += messages[i];
  }
  return text;
}

hid_t check(hid_t id, const std::string& what) {
  if (id < 0) throw std::runtime_error("HDF5: " + what + ": " + error_text());
  return id;
}

Handle& Handle::operator=(Handle&& other) noexcept {
  if (this != &other) {
    reset();
    id_ = std::exchange(other.id_, -1);
  }
  return *this;
}

void Handle::reset() {
  if (id_ < 0) return;
  switch (H5Iget_type(id_)) {
    case H5I_FILE:
      H5Fclose(id_);
      break;
    case H5I_GROUP:
      H5Gclose(id_);
      break;
    case H5I_DATASET:
      H5Dclose(id_);
      break;
    case H5I_DATASPACE:
      H5Sclose(id_);
      break;
    case H5I_DATATYPE:
      H5Tclose(id_);
      break;
    case H5I_ATTR:
      H5Aclose(id_);
      break;
    case H5I_GENPROP_LST:
      H5Pclose(id_);
      break;
    default:
      break;
  }
  id_ = -1;
}

namespace {

// The operating system's reason ("No such file or directory": the deepest message, which
// collect_error reduced to it), or the whole HDF5 text when there is none.
std::string file_error_reason() {
  std::vector<std::string> messages;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_DOWNWARD, collect_error, &messages);
  return messages.empty() ? error_text() : messages.back();
}

}  // namespace

Handle create_file(const std::string& path, bool exclusive) {
  const hid_t id =
      H5Fcreate(path.c_str(), exclusive ? H5F_ACC_EXCL : H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (id < 0) throw InputError("cannot create HDF5 file '" + path + "': " + file_error_reason());
  return Handle(id);
}

Handle open_file(const std::string& path, bool writable) {
  // A pipe or a device would block HDF5's first read for ever.
  if (const std::string why = detail::why_not_a_regular_file(path); !why.empty()) {
    throw InputError("cannot open '" + path + "': " + why);
  }
  if (H5Fis_hdf5(path.c_str()) <= 0) {
    FILE* f = std::fopen(path.c_str(), "rb");
    if (f == nullptr) throw InputError("cannot open '" + path + "': no such readable file");
    std::fclose(f);
    throw InputError("cannot open '" + path + "': not an HDF5 file");
  }
  const hid_t id = H5Fopen(path.c_str(), writable ? H5F_ACC_RDWR : H5F_ACC_RDONLY, H5P_DEFAULT);
  if (id < 0) throw InputError("cannot open HDF5 file '" + path + "': " + file_error_reason());
  return Handle(id);
}

Handle create_group(hid_t parent, const std::string& name) {
  return Handle(H5Gcreate2(parent, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                "create group " + name);
}

Handle open_group(hid_t parent, const std::string& name) {
  return Handle(H5Gopen2(parent, name.c_str(), H5P_DEFAULT), "open group " + name);
}

Handle open_dataset(hid_t parent, const std::string& name) {
  return Handle(H5Dopen2(parent, name.c_str(), H5P_DEFAULT), "open dataset " + name);
}

std::vector<std::string> member_names(hid_t group) {
  std::vector<std::string> names;
  check(H5Literate(
            group, H5_INDEX_NAME, H5_ITER_INC, nullptr,
            [](hid_t, const char* name, const H5L_info_t*, void* out) -> herr_t {
              static_cast<std::vector<std::string>*>(out)->emplace_back(name);
              return 0;
            },
            &names),
        "list group members");
  return names;
}

bool exists(hid_t parent, const std::string& path) {
  std::string prefix;
  std::istringstream parts(path);
  std::string part;
  while (std::getline(parts, part, '/')) {
    if (part.empty()) continue;
    prefix += (prefix.empty() ? "" : "/") + part;
    if (H5Lexists(parent, prefix.c_str(), H5P_DEFAULT) <= 0) return false;
  }
  return true;
}

void hard_link(hid_t target_parent, const std::string& target, hid_t link_parent,
               const std::string& link) {
  check(H5Lcreate_hard(target_parent, target.c_str(), link_parent, link.c_str(), H5P_DEFAULT,
                       H5P_DEFAULT),
        "link " + link + " to " + target);
}

void write_attribute(hid_t object, const std::string& name, const std::string& value) {
  Handle type(string_type());
  const char* text = value.c_str();
  write_attribute_raw(object, name, type.get(), type.get(), {}, &text);
}

void write_attribute(hid_t object, const std::string& name, double value) {
  write_attribute_raw(object, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {}, &value);
}

void write_attribute(hid_t object, const std::string& name, long value) {
  write_attribute_raw(object, name, H5T_STD_I64LE, H5T_NATIVE_LONG, {}, &value);
}

void write_attribute(hid_t object, const std::string& name, const std::vector<double>& value) {
  write_attribute_raw(object, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {value.size()},
                      value.data());
}

void write_attribute(hid_t object, const std::string& name, const std::vector<int>& value) {
  write_attribute_raw(object, name, H5T_STD_I32LE, H5T_NATIVE_INT, {value.size()}, value.data());
}

bool has_attribute(hid_t object, const std::string& name) {
  return H5Aexists(object, name.c_str()) > 0;
}

namespace {

// Elements of an attribute's dataspace (1 for a scalar).
hssize_t attribute_points(hid_t attribute) {
  Handle space(H5Aget_space(attribute), "attribute space");
  return H5Sget_simple_extent_npoints(space.get());
}

// Reading a single value of an attribute that holds several would overrun the buffer.
void require_single(hid_t attribute, const std::string& name) {
  const hssize_t points = attribute_points(attribute);
  if (points != 1) {
    throw std::runtime_error("HDF5: attribute " + name + " holds " + std::to_string(points) +
                             " values, not one");
  }
}

std::string read_string(hid_t attribute, hid_t file_type) {
  require_single(attribute, "string");
  if (H5Tis_variable_str(file_type) > 0) {
    Handle type(string_type());
    char* text = nullptr;
    check(H5Aread(attribute, type.get(), &text), "read string attribute");
    std::string value = text != nullptr ? text : "";
    H5free_memory(text);
    return value;
  }
  const size_t size = H5Tget_size(file_type);
  std::string value(size, '\0');
  Handle type(H5Tcopy(H5T_C_S1));
  H5Tset_size(type.get(), size);
  check(H5Aread(attribute, type.get(), value.data()), "read string attribute");
  value.resize(std::min(value.size(), value.find('\0')));
  return value;
}

std::string attribute_as_text(hid_t attribute) {
  Handle type(H5Aget_type(attribute), "attribute type");
  const hssize_t count = attribute_points(attribute);
  if (H5Tget_class(type.get()) == H5T_STRING) {
    return count == 1 ? read_string(attribute, type.get()) : "<array of strings>";
  }
  if (count < 0 || static_cast<hsize_t>(count) > kMaxReadBytes / sizeof(double)) {
    return "<unsupported size>";
  }
  std::vector<double> values(static_cast<size_t>(std::max<hssize_t>(count, 0)));
  const H5T_class_t type_class = H5Tget_class(type.get());
  if (type_class != H5T_INTEGER && type_class != H5T_FLOAT) return "<unsupported type>";
  std::string text;
  if (type_class == H5T_INTEGER) {
    std::vector<long> longs(values.size());
    check(H5Aread(attribute, H5T_NATIVE_LONG, longs.data()), "read attribute");
    for (long v : longs) text += (text.empty() ? "" : " ") + std::to_string(v);
  } else {
    check(H5Aread(attribute, H5T_NATIVE_DOUBLE, values.data()), "read attribute");
    for (double v : values) text += (text.empty() ? "" : " ") + to_text(v);
  }
  return text;
}

herr_t collect_attribute(hid_t object, const char* name, const H5A_info_t* /*info*/, void* out) {
  auto& list = *static_cast<std::vector<std::pair<std::string, std::string>>*>(out);
  const hid_t attribute = H5Aopen(object, name, H5P_DEFAULT);
  if (attribute < 0) return -1;
  Handle owned(attribute);
  list.emplace_back(name, attribute_as_text(attribute));
  return 0;
}

}  // namespace

std::string read_string_attribute(hid_t object, const std::string& name) {
  Handle attribute(H5Aopen(object, name.c_str(), H5P_DEFAULT), "open attribute " + name);
  Handle type(H5Aget_type(attribute.get()), "attribute type");
  if (H5Tget_class(type.get()) != H5T_STRING) {
    throw std::runtime_error("HDF5: attribute " + name + " is not a string");
  }
  require_single(attribute.get(), name);
  return read_string(attribute.get(), type.get());
}

double read_double_attribute(hid_t object, const std::string& name) {
  Handle attribute(H5Aopen(object, name.c_str(), H5P_DEFAULT), "open attribute " + name);
  require_single(attribute.get(), name);
  double value = 0;
  check(H5Aread(attribute.get(), H5T_NATIVE_DOUBLE, &value), "read attribute " + name);
  return value;
}

long read_long_attribute(hid_t object, const std::string& name) {
  Handle attribute(H5Aopen(object, name.c_str(), H5P_DEFAULT), "open attribute " + name);
  require_single(attribute.get(), name);
  long value = 0;
  check(H5Aread(attribute.get(), H5T_NATIVE_LONG, &value), "read attribute " + name);
  return value;
}

std::vector<std::pair<std::string, std::string>> read_attributes_as_text(hid_t object) {
  std::vector<std::pair<std::string, std::string>> list;
  check(H5Aiterate2(object, H5_INDEX_NAME, H5_ITER_INC, nullptr, collect_attribute, &list),
        "read attributes");
  return list;
}

void write_dataset(hid_t parent, const std::string& name, hid_t file_type, hid_t memory_type,
                   const std::vector<hsize_t>& dims, const void* data) {
  Handle space(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr),
               "dataspace for " + name);
  Handle dataset(H5Dcreate2(parent, name.c_str(), file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT,
                            H5P_DEFAULT),
                 "create dataset " + name);
  hsize_t count = 1;
  for (hsize_t d : dims) count *= d;
  if (count > 0) {
    check(H5Dwrite(dataset.get(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data),
          "write dataset " + name);
  }
}

std::vector<hsize_t> dataset_dims(hid_t dataset) {
  Handle space(H5Dget_space(dataset), "dataset space");
  const int rank = H5Sget_simple_extent_ndims(space.get());
  std::vector<hsize_t> dims(static_cast<size_t>(std::max(rank, 0)));
  if (rank > 0) H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr);
  return dims;
}

std::vector<double> read_doubles(hid_t parent, const std::string& name, std::vector<hsize_t>* dims,
                                 Frames frames) {
  return read_all<double>(parent, name, H5T_NATIVE_DOUBLE, dims, frames);
}

std::vector<int> read_ints(hid_t parent, const std::string& name, std::vector<hsize_t>* dims) {
  return read_all<int>(parent, name, H5T_NATIVE_INT, dims);
}

std::vector<long> read_longs(hid_t parent, const std::string& name, std::vector<hsize_t>* dims,
                             Frames frames) {
  return read_all<long>(parent, name, H5T_NATIVE_LONG, dims, frames);
}

Series::Series(hid_t parent, const std::string& name, hid_t file_type, hid_t memory_type,
               std::vector<hsize_t> frame_shape, hsize_t chunk_frames, int compression_level)
    : memory_type_(memory_type), frame_shape_(std::move(frame_shape)) {
  std::vector<hsize_t> dims{0}, max_dims{H5S_UNLIMITED}, chunk{std::max<hsize_t>(chunk_frames, 1)};
  for (hsize_t d : frame_shape_) {
    dims.push_back(d);
    max_dims.push_back(d);
    chunk.push_back(std::max<hsize_t>(d, 1));
  }
  Handle space(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), max_dims.data()),
               "dataspace for " + name);
  Handle properties(H5Pcreate(H5P_DATASET_CREATE), "dataset properties");
  check(H5Pset_chunk(properties.get(), static_cast<int>(chunk.size()), chunk.data()),
        "chunk " + name);
  if (compression_level > 0) {
    check(H5Pset_shuffle(properties.get()), "shuffle " + name);
    check(H5Pset_deflate(properties.get(), static_cast<unsigned>(compression_level)),
          "deflate " + name);
  }
  dataset_ = Handle(H5Dcreate2(parent, name.c_str(), file_type, space.get(), H5P_DEFAULT,
                               properties.get(), H5P_DEFAULT),
                    "create dataset " + name);
}

void Series::append(const void* data, hsize_t frames) {
  if (frames == 0) return;
  std::vector<hsize_t> dims{frames_ + frames}, start{frames_}, count{frames};
  for (hsize_t d : frame_shape_) {
    dims.push_back(d);
    start.push_back(0);
    count.push_back(d);
  }
  check(H5Dset_extent(dataset_.get(), dims.data()), "extend dataset");
  Handle file_space(H5Dget_space(dataset_.get()), "dataset space");
  check(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start.data(), nullptr, count.data(),
                            nullptr),
        "select frames");
  Handle memory_space(H5Screate_simple(static_cast<int>(count.size()), count.data(), nullptr),
                      "memory space");
  check(H5Dwrite(dataset_.get(), memory_type_, memory_space.get(), file_space.get(), H5P_DEFAULT,
                 data),
        "write frames");
  frames_ += frames;
}

}  // namespace jelly::h5
