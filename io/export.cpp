#include <jelly/io/detail/export.hpp>

#include <Eigen/Geometry>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <jelly/core/detail/file_replacement.hpp>
#include <jelly/core/detail/input_file.hpp>
#include <jelly/core/errors.hpp>

namespace jelly {

namespace {

constexpr char kPc2Signature[12] = {'P', 'O', 'I', 'N', 'T', 'C', 'A', 'C', 'H', 'E', '2', '\0'};

// Little-endian int32 and float32, as the format (and every x86 and ARM machine) has them.
void put_i32(std::FILE* f, std::int32_t v) { std::fwrite(&v, 4, 1, f); }
void put_f32(std::FILE* f, float v) { std::fwrite(&v, 4, 1, f); }

}  // namespace

void vertex_normals(const std::vector<Vec3>& vertices, const std::vector<Triangle>& triangles,
                    std::vector<Vec3>& normals) {
  normals.assign(vertices.size(), Vec3::Zero());
  for (const Triangle& t : triangles) {
    const Vec3 n = (vertices[t[1]] - vertices[t[0]]).cross(vertices[t[2]] - vertices[t[0]]);
    for (int i : t) normals[i] += n;
  }
  for (Vec3& n : normals) {
    const Real length = n.norm();
    n = length > 0 ? Vec3(n / length) : Vec3::UnitY();
  }
}

ObjObject crease_normals(const std::string& name, const std::vector<Vec3>& vertices,
                         const std::vector<Triangle>& triangles, double crease_degrees) {
  const size_t nt = triangles.size();
  std::vector<Vec3> face(nt);  // twice the area times the unit normal
  std::vector<std::vector<int>> around(vertices.size());
  for (size_t f = 0; f < nt; ++f) {
    const Triangle& t = triangles[f];
    face[f] = (vertices[t[1]] - vertices[t[0]]).cross(vertices[t[2]] - vertices[t[0]]);
    for (int i : t) around[i].push_back(static_cast<int>(f));
  }
  const Real cos_crease = std::cos(crease_degrees * 3.14159265358979323846 / 180);
  ObjObject out;
  out.name = name;
  out.triangles.resize(nt);
  // Per original vertex, the copies made so far (their normals): corners whose normals agree to
  // rounding share one.
  std::vector<std::vector<int>> copies(vertices.size());
  for (size_t f = 0; f < nt; ++f) {
    const Vec3 own = face[f].normalized();
    for (int c = 0; c < 3; ++c) {
      const int v = triangles[f][c];
      Vec3 sum = Vec3::Zero();
      for (int g : around[v])
        if (face[g].normalized().dot(own) >= cos_crease) sum += face[g];
      const Vec3 n = sum.norm() > 0 ? Vec3(sum.normalized()) : Vec3::UnitY();
      int index = -1;
      for (int k : copies[v])
        if ((out.normals[k] - n).norm() < 1e-9) index = k;
      if (index < 0) {
        index = static_cast<int>(out.vertices.size());
        out.vertices.push_back(vertices[v]);
        out.normals.push_back(n);
        copies[v].push_back(index);
      }
      out.triangles[f][c] = index;
    }
  }
  return out;
}

std::string obj_text(const std::vector<ObjObject>& objects, const std::string& one_object) {
  std::string text = "# jelly render surface\n";
  if (!one_object.empty()) text += "o " + one_object + "\n";
  char line[160];
  int base = 1, normal_base = 1;
  for (const ObjObject& o : objects) {
    text += (one_object.empty() ? "o " : "g ") + o.name + "\n";
    for (const Vec3& v : o.vertices) {
      std::snprintf(line, sizeof line, "v %.9g %.9g %.9g\n", v.x(), v.y(), v.z());
      text += line;
    }
    const bool normals = !o.normals.empty();
    if (normals && o.normals.size() != o.vertices.size())
      throw std::logic_error("obj_text: object '" + o.name + "' has " +
                             std::to_string(o.normals.size()) + " normals for " +
                             std::to_string(o.vertices.size()) + " vertices");
    for (const Vec3& n : o.normals) {
      std::snprintf(line, sizeof line, "vn %.7g %.7g %.7g\n", n.x(), n.y(), n.z());
      text += line;
    }
    for (const auto& t : o.triangles) {
      if (normals) {
        const int d = normal_base - base;  // vn index = v index + d
        std::snprintf(line, sizeof line, "f %d//%d %d//%d %d//%d\n", t[0] + base, t[0] + base + d,
                      t[1] + base, t[1] + base + d, t[2] + base, t[2] + base + d);
      } else {
        std::snprintf(line, sizeof line, "f %d %d %d\n", t[0] + base, t[1] + base, t[2] + base);
      }
      text += line;
    }
    base += static_cast<int>(o.vertices.size());
    normal_base += static_cast<int>(o.normals.size());
  }
  return text;
}

void write_obj(const std::string& path, const std::vector<ObjObject>& objects,
               const std::string& one_object) {
  detail::replace_file(path, obj_text(objects, one_object));
}

std::vector<ObjObject> read_obj(const std::string& path) {
  const std::string why = detail::why_not_a_regular_file(path);
  if (!why.empty()) throw InputError("file", path, "an OBJ file that can be read (" + why + ")");
  std::ifstream in(path);
  if (!in) throw InputError("file", path, "an OBJ file that can be read");
  std::vector<ObjObject> objects;
  int base = 1;                    // index of the current object's first vertex, file-wide
  int normal_base = 1;             // and of its first normal
  int seen = 0, normals_seen = 0;  // vertices and normals so far, file-wide
  std::string line;
  const auto bad = [&] { return InputError("file", path, "an OBJ file (bad line: " + line + ")"); };
  while (std::getline(in, line)) {
    std::istringstream items(line);
    std::string key;
    items >> key;
    if (key == "o" || key == "g") {
      // A new part, unless the current one has nothing yet (an object named before its group).
      if (objects.empty() || !objects.back().vertices.empty()) objects.emplace_back();
      items >> objects.back().name;
      base = seen + 1;
      normal_base = normals_seen + 1;
    } else if (key == "v" || key == "vn" || key == "f") {
      if (objects.empty()) objects.emplace_back();
      if (key == "v" || key == "vn") {
        Vec3 v;
        items >> v.x() >> v.y() >> v.z();
        if (key == "v") {
          objects.back().vertices.push_back(v);
          ++seen;
        } else {
          objects.back().normals.push_back(v);
          ++normals_seen;
        }
      } else {
        std::array<int, 3> t{};
        for (int& i : t) {
          std::string corner;
          if (!(items >> corner)) throw bad();
          const size_t slashes = corner.find("//");
          try {
            i = std::stoi(corner.substr(0, slashes)) - base;
            if (slashes != std::string::npos &&
                std::stoi(corner.substr(slashes + 2)) - normal_base != i)
              throw bad();
          } catch (const std::logic_error&) {  // stoi: no number
            throw bad();
          }
        }
        objects.back().triangles.push_back(t);
      }
      if (!items) throw bad();
    }
  }
  return objects;
}

Pc2Writer::Pc2Writer(const std::string& path, int num_points, float start_frame, float sample_rate)
    : path_(path) {
  require(num_points >= 0, "num_points", num_points, ">= 0");  // before the buffer's size
  buffer_.resize(3 * static_cast<size_t>(num_points));
  replacement_ = std::make_unique<detail::FileReplacement>(path);
  file_ = std::fopen(replacement_->temporary().c_str(), "wb");
  if (file_ == nullptr)
    throw std::runtime_error("cannot write '" + path + "' (" + std::strerror(errno) + ")");
  std::fwrite(kPc2Signature, 1, sizeof kPc2Signature, file_);
  put_i32(file_, 1);  // file version
  put_i32(file_, num_points);
  put_f32(file_, start_frame);
  put_f32(file_, sample_rate);
  put_i32(file_, 0);  // samples: written by close()
}

Pc2Writer::~Pc2Writer() {
  // Not completed by close(): the temporary is removed, an old file stays as it was.
  if (file_ != nullptr) std::fclose(file_);
}

void Pc2Writer::write(const double* xyz) {
  for (size_t i = 0; i < buffer_.size(); ++i) buffer_[i] = static_cast<float>(xyz[i]);
  if (std::fwrite(buffer_.data(), sizeof(float), buffer_.size(), file_) != buffer_.size())
    failed_ = true;
  ++samples_;
}

void Pc2Writer::close() {
  if (file_ == nullptr) return;
  std::fseek(file_, sizeof kPc2Signature + 4 * 4, SEEK_SET);
  put_i32(file_, samples_);
  const bool ok = !failed_ && std::ferror(file_) == 0;
  const bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  if (!ok || !closed) {
    replacement_->discard();
    throw std::runtime_error("cannot write '" + path_ + "' (the write failed)");
  }
  replacement_->commit();
}

Pc2Data read_pc2(const std::string& path) {
  const std::string why = detail::why_not_a_regular_file(path);
  if (!why.empty()) throw InputError("file", path, "a PC2 file that can be read (" + why + ")");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("file", path, "a PC2 file that can be read");
  char signature[12];
  std::int32_t version = 0, points = 0, samples = 0;
  Pc2Data d;
  in.read(signature, 12);
  in.read(reinterpret_cast<char*>(&version), 4);
  in.read(reinterpret_cast<char*>(&points), 4);
  in.read(reinterpret_cast<char*>(&d.start_frame), 4);
  in.read(reinterpret_cast<char*>(&d.sample_rate), 4);
  in.read(reinterpret_cast<char*>(&samples), 4);
  if (!in || std::memcmp(signature, kPc2Signature, 12) != 0 || version != 1 || points < 0 ||
      samples < 0)
    throw InputError("file", path, "a PC2 file (POINTCACHE2 header, version 1)");
  // The counts are checked against the file's size before anything is allocated from them.
  std::error_code ec;
  const auto bytes = std::filesystem::file_size(path, ec);
  if (ec || 12.0 * points * samples > static_cast<double>(bytes)) {
    throw InputError("file", path,
                     "a complete PC2 file (its header promises " + std::to_string(samples) +
                         " samples of " + std::to_string(points) + " points, more than it holds)");
  }
  d.num_points = points;
  for (int s = 0; s < samples; ++s) {
    d.samples.emplace_back(static_cast<size_t>(3 * points));
    in.read(reinterpret_cast<char*>(d.samples.back().data()),
            static_cast<std::streamsize>(12 * static_cast<size_t>(points)));
    if (!in) throw InputError("file", path, "a complete PC2 file (it is truncated)");
  }
  return d;
}

}  // namespace jelly
