#include <jelly/core/components.hpp>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <unordered_map>
#include <vector>

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/Importer.hpp>

#include <jelly/core/errors.hpp>
#include <jelly/geometry/detail/mesh_file.hpp>
#include <jelly/geometry/detail/mesh_file_reader.hpp>

// The meshes component (assimp): the reader of .obj, .stl and .ply files behind read_mesh
// (geometry/detail/mesh_io.hpp), which does the checks before and after it.
namespace jelly {

namespace {

// Index of each distinct position, in order of first appearance; -0 and +0 are the same.
class Welder {
 public:
  int index(const Vec3& p, std::vector<Vec3>& vertices) {
    const Key key{p.x() + 0.0, p.y() + 0.0, p.z() + 0.0};
    const auto [it, inserted] = map_.try_emplace(key, static_cast<int>(vertices.size()));
    if (inserted) vertices.push_back(p);
    return it->second;
  }

 private:
  struct Key {
    double x, y, z;
    bool operator==(const Key& o) const { return x == o.x && y == o.y && z == o.z; }
  };
  struct Hash {
    std::size_t operator()(const Key& k) const {
      std::uint64_t h = 1469598103934665603ull;
      for (double d : {k.x, k.y, k.z}) {
        std::uint64_t bits;
        std::memcpy(&bits, &d, sizeof bits);
        h = (h ^ bits) * 1099511628211ull;
        h ^= h >> 29;
      }
      return static_cast<std::size_t>(h);
    }
  };
  std::unordered_map<Key, int, Hash> map_;
};

// detail::MeshFileReader with assimp.
int read_with_assimp(const std::string& path, const std::string& field, const std::string& value,
                     TriangleMesh& mesh, std::map<std::string, std::vector<int>>& groups) {
  Assimp::Importer importer;
  // ValidateDataStructure runs first and refuses a face naming a vertex the mesh does not have
  // (before Triangulate reads the vertices of polygons).
  const unsigned flags = aiProcess_ValidateDataStructure | aiProcess_Triangulate;
  const aiScene* scene = nullptr;
  if (detail::lower_extension(path) == ".obj") {
    // An OBJ file is handed over ending in a line break: assimp's OBJ reader parses a number at
    // the end of its buffer past the buffer's end when the file's last line has none
    // (jelly_mesh_fuzzer; the input is in tests/fuzz/corpus/mesh).
    std::ifstream in(path, std::ios::binary);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (text.empty() || text.back() != '\n') text += '\n';
    scene = importer.ReadFileFromMemory(text.data(), text.size(), flags, "obj");
  } else {
    scene = importer.ReadFile(path, flags);
  }
  if (scene == nullptr) {
    throw InputError(
        field, value,
        "a mesh file the reader (assimp) accepts: " + std::string(importer.GetErrorString()));
  }

  Welder welder;
  int dropped = 0;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* am = scene->mMeshes[m];
    std::vector<int> index(am->mNumVertices);
    for (unsigned v = 0; v < am->mNumVertices; ++v) {
      const aiVector3D& p = am->mVertices[v];
      const Vec3 q(p.x, p.y, p.z);
      if (!q.allFinite()) {  // (the message is built only then: this loop is hot)
        throw InputError(
            field, value,
            "a mesh with finite coordinates (a vertex is at (" + to_text(q.transpose()) + "))");
      }
      index[v] = welder.index(q, mesh.vertices);
    }
    const std::string name = am->mName.C_Str();
    std::vector<int>* group = (name.empty() || name == "defaultobject") ? nullptr : &groups[name];
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines
      for (int k = 0; k < 3; ++k) {
        if (face.mIndices[k] >= am->mNumVertices) {
          throw InputError(field, value,
                           "a mesh whose faces name its vertices (a face names vertex " +
                               std::to_string(static_cast<int>(face.mIndices[k])) + " of " +
                               std::to_string(am->mNumVertices) + ")");
        }
      }
      const Triangle t{index[face.mIndices[0]], index[face.mIndices[1]], index[face.mIndices[2]]};
      if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) {
        ++dropped;
        continue;
      }
      mesh.triangles.push_back(t);
      if (group != nullptr) group->insert(group->end(), t.begin(), t.end());
    }
  }
  return dropped;
}

}  // namespace

void register_meshes_component() {
  if (has_component("meshes")) return;
  register_component({"meshes",
                      "mesh files .obj, .stl, .ply read with assimp (voxelized and "
                      "mesh bodies, mesh obstacles, jelly mesh)"});
  detail::set_mesh_file_reader(&read_with_assimp);
}

}  // namespace jelly
