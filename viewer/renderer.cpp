#include <jelly/viewer/renderer.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <jelly/viewer/detail/gl.hpp>
#include <jelly/viewer/detail/gl_program.hpp>

namespace jelly::viewer {

namespace {

// ---------------------------------------------------------------------------------------------
// Shaders (GLSL 3.30 core). Colours are given in sRGB, lit in linear space and written as sRGB.

constexpr const char* kMeshVertex = R"(#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
uniform mat4 u_model;
uniform mat4 u_view_proj;
uniform mat4 u_light_vp;
invariant gl_Position;
out vec3 v_world;
out vec3 v_normal;
out vec4 v_light;
void main() {
  vec4 world = u_model * vec4(a_position, 1.0);
  v_world = world.xyz;
  v_normal = mat3(u_model) * a_normal;
  v_light = u_light_vp * world;
  gl_Position = u_view_proj * world;
}
)";

// Compiled in variants (SHADOWS, GRID, SPECULAR defined or not): llvmpipe runs both sides of
// a branch, so features that are off must not be in the program at all.
constexpr const char* kMeshFragment = R"(
in vec3 v_world;
in vec3 v_normal;
in vec4 v_light;
uniform vec3 u_color;  // linear
uniform vec3 u_light_dir;
uniform vec3 u_eye;
uniform sampler2DShadow u_shadow_map;
uniform vec3 u_horizon;  // linear
uniform vec3 u_focus;
uniform float u_extent;
out vec4 o_color;

#ifdef SHADOWS
// Four bilinear (hardware 2x2) taps of the shadow map: soft edges for 16 depth comparisons.
float lit_fraction(vec3 n) {
  vec3 p = v_light.xyz / v_light.w * 0.5 + 0.5;
  float bias = 0.0008 + 0.002 * (1.0 - abs(dot(n, u_light_dir)));
  vec2 texel = 1.0 / vec2(textureSize(u_shadow_map, 0));
  float sum = texture(u_shadow_map, vec3(p.xy + vec2(-0.75, -0.75) * texel, p.z - bias)) +
              texture(u_shadow_map, vec3(p.xy + vec2(0.75, -0.75) * texel, p.z - bias)) +
              texture(u_shadow_map, vec3(p.xy + vec2(-0.75, 0.75) * texel, p.z - bias)) +
              texture(u_shadow_map, vec3(p.xy + vec2(0.75, 0.75) * texel, p.z - bias));
  // Outside the map (beyond its depth range or its square): lit.
  vec3 outside = step(vec3(1.0), p) + step(p, vec3(0.0));
  return max(0.25 * sum, step(0.5, outside.x + outside.y + outside.z));
}
#endif

#ifdef GRID
// Anti-aliased lines every `spacing` metres of the two coordinates.
float grid_line(vec2 coord, float spacing) {
  vec2 c = coord / spacing;
  vec2 d = abs(fract(c - 0.5) - 0.5) / max(fwidth(c), vec2(1e-6));
  return 1.0 - clamp(min(d.x, d.y), 0.0, 1.0);
}
#endif

void main() {
  vec3 n = normalize(v_normal);
  if (!gl_FrontFacing) n = -n;
  vec3 base = u_color;
#ifdef GRID
  vec3 a = abs(n);
  vec2 coord = (a.y >= a.x && a.y >= a.z) ? v_world.xz : (a.x >= a.z ? v_world.zy : v_world.xy);
  float fade = 1.0 - smoothstep(25.0, 60.0, length(v_world - u_eye));
  base *= 1.0 - fade * max(0.22 * grid_line(coord, 1.0), 0.45 * grid_line(coord, 5.0));
#endif
  float shadow = 1.0;
#ifdef SHADOWS
  shadow = lit_fraction(n);
#endif
  vec3 l = u_light_dir;
  float diffuse = max(dot(n, l), 0.0) * shadow;
  // Hemisphere ambient: more light from the sky than from the ground.
  vec3 ambient = mix(vec3(0.16, 0.15, 0.14), vec3(0.34, 0.37, 0.42), 0.5 + 0.5 * n.y);
  vec3 color = base * (ambient + 0.95 * diffuse);
#ifdef SPECULAR
  vec3 h = normalize(l + normalize(u_eye - v_world));
  float s = max(dot(n, h), 0.0);
  s *= s; s *= s; s *= s; s *= s; s *= s;  // s^32
  color += vec3(0.35 * s * shadow);
#endif
  // Far from the action the ground fades into the sky's horizon colour (its edge unseen).
  if (u_extent > 0.0)
    color = mix(color, u_horizon, smoothstep(0.4 * u_extent, 0.95 * u_extent,
                                              length(v_world - u_focus)));
  o_color = vec4(sqrt(color), 1.0);  // gamma 2
}
)";

constexpr const char* kDepthVertex = R"(#version 330 core
layout(location = 0) in vec3 a_position;
uniform mat4 u_model;
uniform mat4 u_light_vp;
void main() { gl_Position = u_light_vp * u_model * vec4(a_position, 1.0); }
)";

constexpr const char* kDepthFragment = R"(#version 330 core
void main() {}
)";

constexpr const char* kPointVertex = R"(#version 330 core
layout(location = 0) in vec3 a_position;
uniform mat4 u_view;
uniform mat4 u_proj;
uniform float u_radius;
uniform float u_viewport_height;
void main() {
  gl_Position = u_proj * u_view * vec4(a_position, 1.0);
  gl_PointSize = max(2.0, u_viewport_height * u_proj[1][1] * u_radius / gl_Position.w);
}
)";

constexpr const char* kPointFragment = R"(#version 330 core
uniform vec3 u_color;
uniform vec3 u_light_view;
out vec4 o_color;
void main() {
  vec2 c = gl_PointCoord * 2.0 - 1.0;
  c.y = -c.y;
  float r2 = dot(c, c);
  if (r2 > 1.0) discard;
  vec3 n = vec3(c, sqrt(1.0 - r2));
  vec3 base = pow(u_color, vec3(2.2));
  float diffuse = max(dot(n, u_light_view), 0.0);
  float specular = 0.3 * pow(max(dot(n, normalize(u_light_view + vec3(0, 0, 1))), 0.0), 32.0);
  vec3 color = base * (0.3 + 0.8 * diffuse) + vec3(specular);
  o_color = vec4(pow(color, vec3(1.0 / 2.2)), 1.0);
}
)";

constexpr const char* kSpringVertex = R"(#version 330 core
layout(location = 0) in int a_self;
layout(location = 1) in int a_other;
layout(location = 2) in float a_rest;
layout(location = 3) in int a_type;
uniform samplerBuffer u_positions;
uniform mat4 u_view_proj;
uniform int u_coloring;
out vec3 v_color;
vec3 fetch(int i) {
  return vec3(texelFetch(u_positions, 3 * i).r, texelFetch(u_positions, 3 * i + 1).r,
              texelFetch(u_positions, 3 * i + 2).r);
}
void main() {
  vec3 p = fetch(a_self);
  vec3 q = fetch(a_other);
  if (u_coloring == 0) {
    v_color = a_type == 0 ? vec3(0.16, 0.33, 0.85) : (a_type == 1 ? vec3(0.10, 0.58, 0.30)
                                                                  : vec3(0.90, 0.55, 0.10));
  } else {
    // Strain (|p - q| - l0) / l0: blue compressed, white at rest, red stretched (full at 10 %).
    float s = clamp((length(p - q) - a_rest) / a_rest / 0.1, -1.0, 1.0);
    v_color = s < 0.0 ? mix(vec3(0.95), vec3(0.10, 0.25, 0.95), -s)
                      : mix(vec3(0.95), vec3(0.90, 0.10, 0.08), s);
  }
  gl_Position = u_view_proj * vec4(p, 1.0);
}
)";

constexpr const char* kColorFragment = R"(#version 330 core
in vec3 v_color;
out vec4 o_color;
void main() { o_color = vec4(v_color, 1.0); }
)";

constexpr const char* kFlatVertex = R"(#version 330 core
layout(location = 0) in vec3 a_position;
uniform mat4 u_view_proj;
uniform vec3 u_color;
uniform float u_point_size;
out vec3 v_color;
void main() {
  v_color = u_color;
  gl_Position = u_view_proj * vec4(a_position, 1.0);
  gl_PointSize = u_point_size;
}
)";

constexpr const char* kSkyVertex = R"(#version 330 core
out float v_height;
void main() {
  vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2) * 2.0 - 1.0;
  v_height = 0.5 * p.y + 0.5;
  gl_Position = vec4(p, 1.0, 1.0);  // at the far plane: drawn last, only where nothing else is
}
)";

constexpr const char* kSkyFragment = R"(#version 330 core
in float v_height;
uniform vec3 u_top;
uniform vec3 u_bottom;
out vec4 o_color;
void main() { o_color = vec4(mix(u_bottom, u_top, clamp(v_height, 0.0, 1.0)), 1.0); }
)";

// A program with its uniform locations looked up once.
struct Program {
  GLuint id = 0;
  GLint model = -1, view_proj = -1, light_vp = -1, color = -1, light_dir = -1, eye = -1,
        shadow_map = -1, shadows = -1, grid = -1, specular = -1, view = -1, proj = -1, radius = -1,
        viewport_height = -1, light_view = -1, positions = -1, coloring = -1, point_size = -1,
        top = -1, bottom = -1, horizon = -1, focus = -1, extent = -1;

  void make(const std::string& vertex, const std::string& fragment, const char* name) {
    id = detail::link_gl_program(vertex.c_str(), fragment.c_str(),
                                 std::string("renderer: the ") + name);
    const auto at = [this](const char* u) { return glGetUniformLocation(id, u); };
    model = at("u_model");
    view_proj = at("u_view_proj");
    light_vp = at("u_light_vp");
    color = at("u_color");
    light_dir = at("u_light_dir");
    eye = at("u_eye");
    shadow_map = at("u_shadow_map");
    shadows = at("u_shadows");
    grid = at("u_grid");
    specular = at("u_specular");
    view = at("u_view");
    proj = at("u_proj");
    radius = at("u_radius");
    viewport_height = at("u_viewport_height");
    light_view = at("u_light_view");
    positions = at("u_positions");
    coloring = at("u_coloring");
    point_size = at("u_point_size");
    top = at("u_top");
    bottom = at("u_bottom");
    horizon = at("u_horizon");
    focus = at("u_focus");
    extent = at("u_extent");
  }
};

void set(GLint at, const Mat4f& m) {
  if (at >= 0) glUniformMatrix4fv(at, 1, GL_FALSE, m.data());
}
void set(GLint at, const Vec3f& v) {
  if (at >= 0) glUniform3fv(at, 1, v.data());
}
void set(GLint at, float f) {
  if (at >= 0) glUniform1f(at, f);
}
void set(GLint at, int i) {
  if (at >= 0) glUniform1i(at, i);
}

Mat4f look_at(const Vec3f& eye, const Vec3f& target, const Vec3f& up_hint) {
  const Vec3f f = (target - eye).normalized();
  const Vec3f r = f.cross(up_hint).normalized();
  const Vec3f u = r.cross(f);
  Mat4f m = Mat4f::Identity();
  m.row(0).head<3>() = r;
  m.row(1).head<3>() = u;
  m.row(2).head<3>() = -f;
  m(0, 3) = -r.dot(eye);
  m(1, 3) = -u.dot(eye);
  m(2, 3) = f.dot(eye);
  return m;
}

Mat4f ortho(float l, float r, float b, float t, float n, float f) {
  Mat4f m = Mat4f::Identity();
  m(0, 0) = 2 / (r - l);
  m(1, 1) = 2 / (t - b);
  m(2, 2) = -2 / (f - n);
  m(0, 3) = -(r + l) / (r - l);
  m(1, 3) = -(t + b) / (t - b);
  m(2, 3) = -(f + n) / (f - n);
  return m;
}

// A triangle mesh on the GPU: interleaved position and normal, and indices.
struct MeshBuffers {
  GLuint vao = 0, vbo = 0, ebo = 0;
  GLsizei index_count = 0;
  int vertex_count = 0;
  std::vector<float> interleaved;  // [6 V] scratch for dynamic meshes
  std::vector<Vec3f> normals;      // [V] scratch

  void create(int vertices, const std::vector<std::array<int, 3>>& triangles, bool dynamic) {
    vertex_count = vertices;
    index_count = static_cast<GLsizei>(3 * triangles.size());
    interleaved.assign(static_cast<size_t>(6 * vertices), 0.0f);
    normals.assign(static_cast<size_t>(vertices), Vec3f::Zero());
    glGenVertexArrays(1, &vao);
    glGenBuffers(1, &vbo);
    glGenBuffers(1, &ebo);
    glBindVertexArray(vao);
    glBindBuffer(GL_ARRAY_BUFFER, vbo);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(interleaved.size() * sizeof(float)),
                 nullptr, dynamic ? GL_STREAM_DRAW : GL_STATIC_DRAW);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), nullptr);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float),
                          reinterpret_cast<void*>(3 * sizeof(float)));
    glEnableVertexAttribArray(1);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ebo);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER,
                 static_cast<GLsizeiptr>(triangles.size() * sizeof(std::array<int, 3>)),
                 triangles.data(), GL_STATIC_DRAW);
    glBindVertexArray(0);
  }

  // Smooth (area-weighted) vertex normals of `positions` [3 V], uploaded with them.
  void update(const float* positions, const std::vector<std::array<int, 3>>& triangles) {
    std::fill(normals.begin(), normals.end(), Vec3f::Zero());
    const auto p = [positions](int v) { return Eigen::Map<const Vec3f>(positions + 3 * v); };
    for (const auto& t : triangles) {
      const Vec3f n = (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0]));
      normals[t[0]] += n;
      normals[t[1]] += n;
      normals[t[2]] += n;
    }
    for (int v = 0; v < vertex_count; ++v) {
      const float length = normals[v].norm();
      const Vec3f n = length > 0 ? Vec3f(normals[v] / length) : Vec3f::UnitY();
      float* out = interleaved.data() + 6 * v;
      out[0] = positions[3 * v];
      out[1] = positions[3 * v + 1];
      out[2] = positions[3 * v + 2];
      out[3] = n.x();
      out[4] = n.y();
      out[5] = n.z();
    }
    glBindBuffer(GL_ARRAY_BUFFER, vbo);
    glBufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(interleaved.size() * sizeof(float)),
                    interleaved.data());
  }

  void draw() const {
    if (index_count == 0) return;
    glBindVertexArray(vao);
    glDrawElements(GL_TRIANGLES, index_count, GL_UNSIGNED_INT, nullptr);
  }

  void destroy() {
    glDeleteVertexArrays(1, &vao);
    glDeleteBuffers(1, &vbo);
    glDeleteBuffers(1, &ebo);
    vao = vbo = ebo = 0;
  }
};

// sRGB to the shaders' linear space (gamma 2, as they write sqrt(color)).
Vec3f linear(const Vec3f& c) { return c.cwiseProduct(c); }

}  // namespace

struct Renderer::Gpu {
  // The lit mesh program in its variants, by (shadows, grid, specular), compiled when first used.
  std::array<Program, 8> mesh;
  Program& mesh_variant(bool shadows, bool grid, bool specular) {
    Program& p = mesh[(shadows ? 4 : 0) + (grid ? 2 : 0) + (specular ? 1 : 0)];
    if (p.id == 0) {
      std::string header = "#version 330 core\n";
      if (shadows) header += "#define SHADOWS\n";
      if (grid) header += "#define GRID\n";
      if (specular) header += "#define SPECULAR\n";
      p.make(kMeshVertex, header + kMeshFragment, "surface");
    }
    return p;
  }
  Program depth, point, spring, flat, sky;
  GLuint empty_vao = 0;
  GLuint shadow_fbo = 0, shadow_texture = 0;
  int shadow_size = 0;

  unsigned long topology = ~0ul;
  std::vector<MeshBuffers> bodies, terrains;
  std::vector<Eigen::AlignedBox3f> terrain_bounds;  // each terrain's mesh in its own frame
  MeshBuffers floor;
  GLuint particle_vao = 0, particle_vbo = 0, particle_tbo = 0;
  GLsizei particle_count = 0;
  GLuint spring_vao = 0, spring_vbo = 0;
  GLsizei structural_vertices = 0, spring_vertices = 0;
  GLuint line_vao = 0, line_vbo = 0;

  void make_shadow_map(int size) {
    if (shadow_size == size) return;
    if (shadow_fbo) {
      glDeleteFramebuffers(1, &shadow_fbo);
      glDeleteTextures(1, &shadow_texture);
    }
    shadow_size = size;
    glGenTextures(1, &shadow_texture);
    glBindTexture(GL_TEXTURE_2D, shadow_texture);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, size, size, 0, GL_DEPTH_COMPONENT,
                 GL_UNSIGNED_INT, nullptr);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    glGenFramebuffers(1, &shadow_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, shadow_fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, shadow_texture, 0);
    glDrawBuffer(GL_NONE);
    glReadBuffer(GL_NONE);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw std::runtime_error("renderer: the shadow map framebuffer is incomplete");
  }

  void release_scene() {
    for (MeshBuffers& m : bodies) m.destroy();
    for (MeshBuffers& m : terrains) m.destroy();
    bodies.clear();
    terrains.clear();
    terrain_bounds.clear();
    glDeleteVertexArrays(1, &particle_vao);
    glDeleteBuffers(1, &particle_vbo);
    glDeleteTextures(1, &particle_tbo);
    glDeleteVertexArrays(1, &spring_vao);
    glDeleteBuffers(1, &spring_vbo);
    particle_vao = particle_vbo = particle_tbo = spring_vao = spring_vbo = 0;
  }

  // Buffers for a scene of a new topology.
  void build(const RenderScene& scene) {
    release_scene();
    topology = scene.topology;
    for (const SurfaceView& body : scene.bodies) {
      bodies.emplace_back();
      bodies.back().create(body.num_vertices(), body.triangles, true);
    }
    for (const TerrainView& terrain : scene.terrains) {
      terrains.emplace_back();
      MeshBuffers& m = terrains.back();
      m.create(static_cast<int>(terrain.vertices.size() / 3), terrain.triangles, false);
      m.update(terrain.vertices.data(), terrain.triangles);
      Eigen::AlignedBox3f box;
      for (size_t v = 0; v + 2 < terrain.vertices.size(); v += 3)
        box.extend(Vec3f(terrain.vertices[v], terrain.vertices[v + 1], terrain.vertices[v + 2]));
      terrain_bounds.push_back(box);
    }
    // Particles: one buffer, read as vertices (points) and as a texture buffer (springs).
    particle_count = static_cast<GLsizei>(scene.particles.size() / 3);
    glGenVertexArrays(1, &particle_vao);
    glGenBuffers(1, &particle_vbo);
    glBindVertexArray(particle_vao);
    glBindBuffer(GL_ARRAY_BUFFER, particle_vbo);
    glBufferData(
        GL_ARRAY_BUFFER,
        static_cast<GLsizeiptr>(std::max<size_t>(scene.particles.size(), 3) * sizeof(float)),
        nullptr, GL_STREAM_DRAW);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
    glEnableVertexAttribArray(0);
    glGenTextures(1, &particle_tbo);
    glBindTexture(GL_TEXTURE_BUFFER, particle_tbo);
    glTexBuffer(GL_TEXTURE_BUFFER, GL_R32F, particle_vbo);
    glBindTexture(GL_TEXTURE_BUFFER, 0);
    // Springs: two vertices each (self, other, rest length, type), structural first.
    struct SpringVertex {
      GLint self, other;
      float rest;
      GLint type;
    };
    std::vector<SpringVertex> vertices;
    vertices.reserve(2 * scene.springs.size());
    for (int pass = 0; pass < 2; ++pass) {
      for (size_t s = 0; s < scene.springs.size(); ++s) {
        const int type = s < scene.spring_type.size() ? scene.spring_type[s] : 0;
        if ((pass == 0) != (type == 0)) continue;
        const float rest = s < scene.spring_rest_length.size() ? scene.spring_rest_length[s] : 1;
        vertices.push_back({scene.springs[s][0], scene.springs[s][1], rest, type});
        vertices.push_back({scene.springs[s][1], scene.springs[s][0], rest, type});
      }
      if (pass == 0) structural_vertices = static_cast<GLsizei>(vertices.size());
    }
    spring_vertices = static_cast<GLsizei>(vertices.size());
    glGenVertexArrays(1, &spring_vao);
    glGenBuffers(1, &spring_vbo);
    glBindVertexArray(spring_vao);
    glBindBuffer(GL_ARRAY_BUFFER, spring_vbo);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices.size() * sizeof(SpringVertex)),
                 vertices.data(), GL_STATIC_DRAW);
    glVertexAttribIPointer(0, 1, GL_INT, sizeof(SpringVertex), nullptr);
    glVertexAttribIPointer(1, 1, GL_INT, sizeof(SpringVertex),
                           reinterpret_cast<void*>(offsetof(SpringVertex, other)));
    glVertexAttribPointer(2, 1, GL_FLOAT, GL_FALSE, sizeof(SpringVertex),
                          reinterpret_cast<void*>(offsetof(SpringVertex, rest)));
    glVertexAttribIPointer(3, 1, GL_INT, sizeof(SpringVertex),
                           reinterpret_cast<void*>(offsetof(SpringVertex, type)));
    for (GLuint a = 0; a < 4; ++a) glEnableVertexAttribArray(a);
    glBindVertexArray(0);
  }
};

Renderer::Renderer(RenderOptions options) : options_(options), gpu_(std::make_unique<Gpu>()) {
  Gpu& g = *gpu_;
  g.mesh_variant(options_.shadows, options_.grid, false);
  g.mesh_variant(options_.shadows, false, true);
  g.depth.make(kDepthVertex, kDepthFragment, "shadow depth");
  g.point.make(kPointVertex, kPointFragment, "particle");
  g.spring.make(kSpringVertex, kColorFragment, "spring");
  g.flat.make(kFlatVertex, kColorFragment, "line");
  g.sky.make(kSkyVertex, kSkyFragment, "sky");
  glGenVertexArrays(1, &g.empty_vao);
  // The floor: a unit square in y = 0, scaled and moved by its model matrix.
  g.floor.create(4, {{0, 2, 1}, {0, 3, 2}}, false);
  const float floor_vertices[12] = {-1, 0, -1, 1, 0, -1, 1, 0, 1, -1, 0, 1};
  g.floor.update(floor_vertices, {{0, 2, 1}, {0, 3, 2}});
  // The drag line and marker.
  glGenVertexArrays(1, &g.line_vao);
  glGenBuffers(1, &g.line_vbo);
  glBindVertexArray(g.line_vao);
  glBindBuffer(GL_ARRAY_BUFFER, g.line_vbo);
  glBufferData(GL_ARRAY_BUFFER, 6 * sizeof(float), nullptr, GL_STREAM_DRAW);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
  glEnableVertexAttribArray(0);
  glBindVertexArray(0);
}

Renderer::~Renderer() {
  // The context may be gone already when the owner destroys it last; the GL objects die with
  // the context then. Deleting them here covers a context that outlives the renderer.
  Gpu& g = *gpu_;
  g.release_scene();
  g.floor.destroy();
  glDeleteVertexArrays(1, &g.line_vao);
  glDeleteBuffers(1, &g.line_vbo);
  glDeleteVertexArrays(1, &g.empty_vao);
  if (g.shadow_fbo) {
    glDeleteFramebuffers(1, &g.shadow_fbo);
    glDeleteTextures(1, &g.shadow_texture);
  }
  for (Program* p : {&g.depth, &g.point, &g.spring, &g.flat, &g.sky}) glDeleteProgram(p->id);
  for (Program& p : g.mesh)
    if (p.id) glDeleteProgram(p.id);
}

void Renderer::draw(const RenderScene& scene, const Camera& camera, int width, int height) {
  Gpu& g = *gpu_;
  GLint framebuffer = 0;
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &framebuffer);
  if (scene.topology != g.topology || scene.bodies.size() != g.bodies.size() ||
      scene.terrains.size() != g.terrains.size())
    g.build(scene);

  // This frame's positions.
  for (size_t b = 0; b < scene.bodies.size(); ++b)
    if (scene.bodies[b].num_vertices() == g.bodies[b].vertex_count)
      g.bodies[b].update(scene.bodies[b].positions.data(), scene.bodies[b].triangles);
  const bool particles_needed = scene.show_particles || scene.show_springs;
  if (particles_needed && static_cast<GLsizei>(scene.particles.size() / 3) == g.particle_count &&
      g.particle_count > 0) {
    glBindBuffer(GL_ARRAY_BUFFER, g.particle_vbo);
    glBufferSubData(GL_ARRAY_BUFFER, 0,
                    static_cast<GLsizeiptr>(scene.particles.size() * sizeof(float)),
                    scene.particles.data());
  }

  const float aspect = static_cast<float>(width) / static_cast<float>(std::max(height, 1));
  const Mat4f view = camera.view();
  const Mat4f proj = camera.projection(aspect);
  const Mat4f view_proj = proj * view;
  const Vec3f eye = camera.eye();
  const Vec3f light = options_.light_direction.normalized();

  // The shadow map: an orthographic view along the light of the bodies and the ground their
  // shadows may fall on, snapped to whole texels so that shadows do not shimmer as it moves.
  Mat4f light_vp = Mat4f::Identity();
  // The window rectangle shadows can fall in (x0, y0, x1, y1 in pixels from the bottom left):
  // the ground is drawn unshadowed, then again with shadows inside it only.
  std::array<int, 4> shadow_rect{0, 0, width, height};
  const bool shadows = options_.shadows && scene.show_surfaces && !scene.bodies.empty();
  // The bodies and the finite obstacles (at their poses): what casts shadows, and what has
  // silhouettes to smooth.
  Vec3f lo, hi;
  scene.particle_bounds(lo, hi);
  if (!(lo.x() <= hi.x())) lo = hi = Vec3f::Zero();
  for (size_t t = 0; t < g.terrains.size(); ++t) {
    const Eigen::AlignedBox3f& box = g.terrain_bounds[t];
    if (!scene.terrains[t].casts_shadow || box.isEmpty()) continue;
    for (int corner = 0; corner < 8; ++corner) {
      const Vec3f local((corner & 1) ? box.max().x() : box.min().x(),
                        (corner & 2) ? box.max().y() : box.min().y(),
                        (corner & 4) ? box.max().z() : box.min().z());
      const Vec3f p = (scene.terrains[t].pose * local.homogeneous()).head<3>();
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
  {
    // Their rectangle in the picture, a few pixels wider; the whole picture when a corner is
    // behind the camera.
    edge_rect_ = {0, 0, width, height};
    float x0 = 1e9f, y0 = 1e9f, x1 = -1e9f, y1 = -1e9f;
    bool behind = false;
    for (int corner = 0; corner < 8 && !behind; ++corner) {
      const Vec3f p((corner & 1) ? hi.x() : lo.x(), (corner & 2) ? hi.y() : lo.y(),
                    (corner & 4) ? hi.z() : lo.z());
      const Eigen::Vector4f c = view_proj * Eigen::Vector4f(p.x(), p.y(), p.z(), 1);
      behind = c.w() <= 1e-6f;
      const float x = (0.5f * c.x() / c.w() + 0.5f) * static_cast<float>(width);
      const float y = (0.5f * c.y() / c.w() + 0.5f) * static_cast<float>(height);
      x0 = std::min(x0, x);
      x1 = std::max(x1, x);
      y0 = std::min(y0, y);
      y1 = std::max(y1, y);
    }
    if (!behind)
      edge_rect_ = {std::clamp(static_cast<int>(x0) - 4, 0, width),
                    std::clamp(static_cast<int>(y0) - 4, 0, height),
                    std::clamp(static_cast<int>(x1) + 5, 0, width),
                    std::clamp(static_cast<int>(y1) + 5, 0, height)};
  }
  if (shadows) {
    g.make_shadow_map(options_.shadow_map_size);
    const Vec3f centre = 0.5f * (lo + hi);
    const float size = (hi - lo).norm();
    const float reach = std::min(12.0f, std::max(2.0f, 2.0f * size));  // how far below
    {
      const Vec3f drop = -light * (reach / std::max(light.y(), 0.2f));
      float x0 = 1e9f, y0 = 1e9f, x1 = -1e9f, y1 = -1e9f;
      bool behind = false;
      for (int corner = 0; corner < 16; ++corner) {
        Vec3f p((corner & 1) ? hi.x() : lo.x(), (corner & 2) ? hi.y() : lo.y(),
                (corner & 4) ? hi.z() : lo.z());
        if (corner & 8) p += drop;
        const Eigen::Vector4f c = view_proj * Eigen::Vector4f(p.x(), p.y(), p.z(), 1);
        if (c.w() <= 1e-6f) {
          behind = true;
          break;
        }
        const float x = (0.5f * c.x() / c.w() + 0.5f) * static_cast<float>(width);
        const float y = (0.5f * c.y() / c.w() + 0.5f) * static_cast<float>(height);
        x0 = std::min(x0, x);
        x1 = std::max(x1, x);
        y0 = std::min(y0, y);
        y1 = std::max(y1, y);
      }
      if (!behind) {
        const auto clamp_x = [width](float v) { return std::clamp(static_cast<int>(v), 0, width); };
        const auto clamp_y = [height](float v) {
          return std::clamp(static_cast<int>(v), 0, height);
        };
        shadow_rect = {clamp_x(x0 - 8), clamp_y(y0 - 8), clamp_x(x1 + 9), clamp_y(y1 + 9)};
      }
    }
    const float radius = 0.5f * size + reach * std::sqrt(1 - light.y() * light.y()) + 0.5f;
    const Vec3f up = std::abs(light.y()) > 0.99f ? Vec3f::UnitZ() : Vec3f::UnitY();
    // A light view fixed in the world, the window moved in whole texels to the bodies.
    const Mat4f light_view = look_at(light, Vec3f::Zero(), up);
    const float texel = 2 * radius / static_cast<float>(g.shadow_size);
    const Eigen::Vector4f c = light_view * Eigen::Vector4f(centre.x(), centre.y(), centre.z(), 1);
    const float cx = texel * std::round(c.x() / texel), cy = texel * std::round(c.y() / texel);
    const float near = -c.z() - (0.5f * size + 5), far = -c.z() + 0.5f * size + reach + 10;
    light_vp = ortho(cx - radius, cx + radius, cy - radius, cy + radius, near, far) * light_view;
    glBindFramebuffer(GL_FRAMEBUFFER, g.shadow_fbo);
    glViewport(0, 0, g.shadow_size, g.shadow_size);
    glEnable(GL_DEPTH_TEST);
    glDepthMask(GL_TRUE);
    glClear(GL_DEPTH_BUFFER_BIT);
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(1.5f, 3.0f);
    glUseProgram(g.depth.id);
    set(g.depth.light_vp, light_vp);
    set(g.depth.model, Mat4f(Mat4f::Identity()));
    for (const MeshBuffers& m : g.bodies) m.draw();
    for (size_t t = 0; t < g.terrains.size(); ++t) {
      if (!scene.terrains[t].casts_shadow) continue;
      set(g.depth.model, scene.terrains[t].pose);
      g.terrains[t].draw();
    }
    glDisable(GL_POLYGON_OFFSET_FILL);
  }

  glBindFramebuffer(GL_FRAMEBUFFER, static_cast<GLuint>(framebuffer));
  glViewport(0, 0, width, height);
  glDisable(GL_SCISSOR_TEST);
  glDisable(GL_BLEND);
  glDisable(GL_CULL_FACE);
  glDepthMask(GL_TRUE);
  glClearDepth(1.0);
  // The colour too, to the horizon's: the ground and the sky are drawn single-sampled (below),
  // so the samples of a body's edge pixel that the body does not cover keep what the buffer
  // held when the pixel's centre is the body's. Uncleared, that was black or the last frame's
  // picture: a dark fringe along silhouettes under multisampling (issue 40).
  glClearColor(options_.sky_bottom.x(), options_.sky_bottom.y(), options_.sky_bottom.z(), 1.0f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);

  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);

  // Lit meshes: terrains and floor, then bodies.
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, shadows ? g.shadow_texture : 0);
  const auto use_mesh = [&](bool shadowed, bool grid, bool specular) -> Program& {
    Program& p = g.mesh_variant(shadowed, grid, specular);
    glUseProgram(p.id);
    set(p.view_proj, view_proj);
    set(p.light_vp, light_vp);
    set(p.light_dir, light);
    set(p.eye, eye);
    set(p.shadow_map, 0);
    set(p.horizon, linear(options_.sky_bottom));
    set(p.focus, scene.focus);
    set(p.extent, scene.ground_extent);
    return p;
  };
  // The ground (planes and the floor) with its grid; obstacles apart, plainly shaded.
  const auto draw_ground = [&](Program& p) {
    for (size_t t = 0; t < g.terrains.size(); ++t) {
      if (scene.terrains[t].casts_shadow) continue;
      set(p.model, scene.terrains[t].pose);
      set(p.color, linear(scene.terrains[t].color));
      g.terrains[t].draw();
    }
    if (scene.floor) {
      Mat4f model = Mat4f::Identity();
      const float half = scene.ground_extent > 0 ? scene.ground_extent : 60.0f;
      model(0, 0) = model(2, 2) = half;
      model(0, 3) = std::round(scene.focus.x());
      model(1, 3) = scene.floor_height;
      model(2, 3) = std::round(scene.focus.z());
      set(p.model, model);
      set(p.color, linear(Vec3f(0.72f, 0.74f, 0.76f)));
      g.floor.draw();
    }
  };
  // Front to back, roughly: the bodies, the obstacles, then the ground, so that the ground's
  // pixels the others cover fail the depth test before its shader runs (early depth test; the
  // ground is most of the picture and llvmpipe's cost is per shaded pixel).
  if (scene.show_surfaces && !g.bodies.empty()) {
    Program& p = use_mesh(shadows, false, true);
    set(p.model, Mat4f(Mat4f::Identity()));
    for (size_t b = 0; b < g.bodies.size(); ++b) {
      set(p.color, linear(scene.bodies[b].color));
      g.bodies[b].draw();
    }
  }
  bool obstacles = false;
  for (const TerrainView& t : scene.terrains) obstacles = obstacles || t.casts_shadow;
  if (obstacles) {
    Program& p = use_mesh(shadows, false, true);
    for (size_t t = 0; t < g.terrains.size(); ++t) {
      if (!scene.terrains[t].casts_shadow) continue;
      set(p.model, scene.terrains[t].pose);
      set(p.color, linear(scene.terrains[t].color));
      g.terrains[t].draw();
    }
  }
  // The ground and the sky without multisampling: one coverage and depth sample per pixel for
  // most of the picture (multisampled rasterization is most of llvmpipe's cost); their own
  // edges meet at the faded horizon, and the bodies' edges over them stay smooth (their samples
  // were written first).
  glDisable(GL_MULTISAMPLE);
  // The ground pushed back a few depth steps: a sheet lying on it (a cloth of thickness 0, the
  // faces of a body resting on it) is drawn over it, not in stripes with it (issue 40, item 8).
  glEnable(GL_POLYGON_OFFSET_FILL);
  glPolygonOffset(1.0f, 4.0f);
  if (!g.terrains.empty() || scene.floor) {
    const auto [x0, y0, x1, y1] = shadow_rect;
    if (shadows && x1 > x0 && y1 > y0) {
      // Each pixel of the ground shaded once: with shadows inside the rectangle they can fall
      // in, without them in the (up to four) bands around it.
      glEnable(GL_SCISSOR_TEST);
      glScissor(x0, y0, x1 - x0, y1 - y0);
      draw_ground(use_mesh(true, options_.grid, false));
      Program& plain = use_mesh(false, options_.grid, false);
      const std::array<std::array<int, 4>, 4> bands{{{0, 0, width, y0},
                                                     {0, y1, width, height - y1},
                                                     {0, y0, x0, y1 - y0},
                                                     {x1, y0, width - x1, y1 - y0}}};
      for (const auto& b : bands) {
        if (b[2] <= 0 || b[3] <= 0) continue;
        glScissor(b[0], b[1], b[2], b[3]);
        draw_ground(plain);
      }
      glDisable(GL_SCISSOR_TEST);
    } else {
      draw_ground(use_mesh(false, options_.grid, false));
    }
  }
  glDisable(GL_POLYGON_OFFSET_FILL);

  // Sky, behind everything: only the pixels nothing else covered are shaded.
  glDepthFunc(GL_LEQUAL);
  glDepthMask(GL_FALSE);
  glUseProgram(g.sky.id);
  set(g.sky.top, options_.sky_top);
  set(g.sky.bottom, options_.sky_bottom);
  glBindVertexArray(g.empty_vao);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_LESS);
  glEnable(GL_MULTISAMPLE);

  // Springs, read from the particle buffer as a texture.
  if (scene.show_springs && g.spring_vertices > 0) {
    glUseProgram(g.spring.id);
    set(g.spring.view_proj, view_proj);
    set(g.spring.coloring, scene.spring_coloring == SpringColoring::kStrain ? 1 : 0);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_BUFFER, g.particle_tbo);
    set(g.spring.positions, 1);
    glBindVertexArray(g.spring_vao);
    glDrawArrays(GL_LINES, 0,
                 scene.show_structural_only ? g.structural_vertices : g.spring_vertices);
    glBindTexture(GL_TEXTURE_BUFFER, 0);
    glActiveTexture(GL_TEXTURE0);
  }

  glEnable(GL_PROGRAM_POINT_SIZE);
  if (scene.show_particles && g.particle_count > 0) {
    glUseProgram(g.point.id);
    set(g.point.view, view);
    set(g.point.proj, proj);
    set(g.point.radius, scene.particle_radius);
    set(g.point.viewport_height, static_cast<float>(height));
    const Vec3f light_view = (view.topLeftCorner<3, 3>() * light).normalized();
    set(g.point.light_view, light_view);
    glBindVertexArray(g.particle_vao);
    // Each body's particles in its colour; without bodies, all of them in the jelly's.
    if (scene.bodies.empty()) {
      set(g.point.color, Vec3f(0.8f * Vec3f(0.85f, 0.13f, 0.22f)));
      glDrawArrays(GL_POINTS, 0, g.particle_count);
    }
    for (const SurfaceView& body : scene.bodies) {
      const int first = std::clamp(body.first_particle, 0, g.particle_count);
      const int count = std::clamp(body.num_particles, 0, g.particle_count - first);
      if (count == 0) continue;
      set(g.point.color, Vec3f(0.8f * body.color));
      glDrawArrays(GL_POINTS, first, count);
    }
  }

  // The drag: a line to the target and both ends marked, over everything.
  if (scene.drag) {
    glDisable(GL_DEPTH_TEST);
    const float line[6] = {scene.drag_from.x(), scene.drag_from.y(), scene.drag_from.z(),
                           scene.drag_to.x(),   scene.drag_to.y(),   scene.drag_to.z()};
    glBindBuffer(GL_ARRAY_BUFFER, g.line_vbo);
    glBufferSubData(GL_ARRAY_BUFFER, 0, sizeof line, line);
    glUseProgram(g.flat.id);
    set(g.flat.view_proj, view_proj);
    set(g.flat.color, Vec3f(1.0f, 0.85f, 0.1f));
    set(g.flat.point_size, 9.0f);
    glBindVertexArray(g.line_vao);
    glDrawArrays(GL_LINES, 0, 2);
    glDrawArrays(GL_POINTS, 0, 2);
    glEnable(GL_DEPTH_TEST);
  }
  glDisable(GL_PROGRAM_POINT_SIZE);
  glBindVertexArray(0);
  glUseProgram(0);
}

}  // namespace jelly::viewer
