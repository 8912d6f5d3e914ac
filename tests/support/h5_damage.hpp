#pragma once
// Damage done to an HDF5 file the way a bad disk or a bad copy does it, for the tests of readers
// that must refuse it: a compressed chunk overwritten with garbage, a string attribute replaced.
#include <hdf5.h>

#include <cstdio>
#include <string>
#include <vector>

namespace jelly::testing {

// Overwrites chunk `index` (in storage order; -1: the last) of dataset `name` with bytes 0xA5, so
// that it no longer inflates. Returns the first frame the chunk held, or -1 when it could not.
inline long corrupt_chunk(const std::string& path, const std::string& name, long index) {
  haddr_t address = 0;
  hsize_t size = 0, offset[3] = {0, 0, 0};
  {
    const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    if (file < 0) return -1;
    const hid_t dataset = H5Dopen2(file, name.c_str(), H5P_DEFAULT);
    const hid_t space = H5Dget_space(dataset);
    hsize_t chunks = 0;
    unsigned mask = 0;
    const bool found =
        H5Dget_num_chunks(dataset, space, &chunks) >= 0 && chunks > 0 &&
        H5Dget_chunk_info(dataset, space, index < 0 ? chunks - 1 : static_cast<hsize_t>(index),
                          offset, &mask, &address, &size) >= 0;
    H5Sclose(space);
    H5Dclose(dataset);
    H5Fclose(file);
    if (!found) return -1;
  }
  std::FILE* f = std::fopen(path.c_str(), "r+b");
  if (f == nullptr) return -1;
  const std::vector<unsigned char> garbage(size, 0xA5);
  const bool written = std::fseek(f, static_cast<long>(address), SEEK_SET) == 0 &&
                       std::fwrite(garbage.data(), 1, size, f) == size;
  std::fclose(f);
  return written ? static_cast<long>(offset[0]) : -1;
}

// Replaces string attribute `name` of `object` (e.g. /parameters run_status).
inline void set_string_attribute(const std::string& path, const std::string& object,
                                 const std::string& name, const std::string& value) {
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  const hid_t group = H5Oopen(file, object.c_str(), H5P_DEFAULT);
  H5Adelete(group, name.c_str());
  const hid_t type = H5Tcopy(H5T_C_S1);
  H5Tset_size(type, H5T_VARIABLE);
  const hid_t space = H5Screate(H5S_SCALAR);
  const hid_t attribute = H5Acreate2(group, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT);
  const char* text = value.c_str();
  H5Awrite(attribute, type, &text);
  H5Aclose(attribute);
  H5Sclose(space);
  H5Tclose(type);
  H5Oclose(group);
  H5Fclose(file);
}

}  // namespace jelly::testing
