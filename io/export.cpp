#include <jelly/io/export.hpp>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

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

std::string obj_text(const std::vector<ObjObject>& objects, const std::string& one_object) {
  std::string text = "# jelly render surface\n";
  if (!one_object.empty()) text += "o " + one_object + "\n";
  char line[128];
  int base = 1;
  for (const ObjObject& o : objects) {
    text += (one_object.empty() ? "o " : "g ") + o.name + "\n";
    for (const Vec3& v : o.vertices) {
      std::snprintf(line, sizeof line, "v %.9g %.9g %.9g\n", v.x(), v.y(), v.z());
      text += line;
    }
    for (const auto& t : o.triangles) {
      std::snprintf(line, sizeof line, "f %d %d %d\n", t[0] + base, t[1] + base, t[2] + base);
      text += line;
    }
    base += static_cast<int>(o.vertices.size());
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
  int base = 1;  // index of the current object's first vertex, file-wide
  int seen = 0;  // vertices so far, file-wide
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream items(line);
    std::string key;
    items >> key;
    if (key == "o" || key == "g") {
      // A new part, unless the current one has nothing yet (an object named before its group).
      if (objects.empty() || !objects.back().vertices.empty()) objects.emplace_back();
      items >> objects.back().name;
      base = seen + 1;
    } else if (key == "v" || key == "f") {
      if (objects.empty()) {
        objects.emplace_back();
        base = 1;
      }
      if (key == "v") {
        Vec3 v;
        items >> v.x() >> v.y() >> v.z();
        objects.back().vertices.push_back(v);
        ++seen;
      } else {
        std::array<int, 3> t{};
        items >> t[0] >> t[1] >> t[2];
        for (int& i : t) i -= base;
        objects.back().triangles.push_back(t);
      }
      if (!items) throw InputError("file", path, "an OBJ file (bad line: " + line + ")");
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
