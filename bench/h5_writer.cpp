#include <jelly/bench/h5_writer.hpp>

#include <hdf5.h>

#include <stdexcept>

namespace jelly::bench {

namespace {

// Closes an HDF5 identifier with its matching function when it leaves scope.
class Handle {
 public:
  Handle(hid_t id, herr_t (*close)(hid_t), const std::string& what) : id_(id), close_(close) {
    if (id_ < 0) throw std::runtime_error("HDF5: cannot " + what);
  }
  ~Handle() { close_(id_); }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  operator hid_t() const { return id_; }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

void check(herr_t status, const std::string& what) {
  if (status < 0) throw std::runtime_error("HDF5: cannot " + what);
}

void write_string_attribute(hid_t object, const std::string& name, const std::string& value) {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose, "copy a string type");
  check(H5Tset_size(type, H5T_VARIABLE), "size a string type");
  check(H5Tset_cset(type, H5T_CSET_UTF8), "set UTF-8");
  Handle space(H5Screate(H5S_SCALAR), H5Sclose, "create a scalar space");
  Handle attribute(H5Acreate2(object, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT),
                   H5Aclose, "create attribute " + name);
  const char* text = value.c_str();
  check(H5Awrite(attribute, type, &text), "write attribute " + name);
}

void write_column(hid_t group, const Column& c) {
  const hsize_t rows = c.is_text ? c.texts.size() : c.numbers.size();
  Handle space(H5Screate_simple(1, &rows, nullptr), H5Sclose, "create a space");
  if (c.is_text) {
    Handle type(H5Tcopy(H5T_C_S1), H5Tclose, "copy a string type");
    check(H5Tset_size(type, H5T_VARIABLE), "size a string type");
    check(H5Tset_cset(type, H5T_CSET_UTF8), "set UTF-8");
    Handle set(
        H5Dcreate2(group, c.name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
        H5Dclose, "create dataset " + c.name);
    std::vector<const char*> pointers;
    for (const std::string& s : c.texts) pointers.push_back(s.c_str());
    if (rows > 0) {
      check(H5Dwrite(set, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, pointers.data()),
            "write dataset " + c.name);
    }
  } else {
    Handle set(H5Dcreate2(group, c.name.c_str(), H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT,
                          H5P_DEFAULT),
               H5Dclose, "create dataset " + c.name);
    if (rows > 0) {
      check(H5Dwrite(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, c.numbers.data()),
            "write dataset " + c.name);
    }
  }
}

}  // namespace

void write_h5(const std::string& path, const std::string& command, const std::vector<Table>& tables,
              const Metadata& metadata) {
  Handle file(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose,
              "create " + path);
  Handle root(H5Gcreate2(file, command.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose,
              "create group " + command);
  for (const auto& [key, value] : metadata) write_string_attribute(root, key, value);
  for (const Table& t : tables) {
    Handle group(H5Gcreate2(root, t.name().c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                 H5Gclose, "create group " + t.name());
    write_string_attribute(group, "description", t.description());
    for (const Column& c : t.columns()) write_column(group, c);
  }
}

}  // namespace jelly::bench
