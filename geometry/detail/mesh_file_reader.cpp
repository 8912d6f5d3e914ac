#include <jelly/geometry/detail/mesh_file_reader.hpp>

namespace jelly::detail {

namespace {

MeshFileReader& registered_reader() {
  static MeshFileReader reader = nullptr;
  return reader;
}

}  // namespace

MeshFileReader mesh_file_reader() { return registered_reader(); }

void set_mesh_file_reader(MeshFileReader reader) { registered_reader() = reader; }

}  // namespace jelly::detail
