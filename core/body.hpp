#pragma once
// A body of the model: a named range of particles and springs with its own material and render
// surface; and BodyPart, what a body builder (geometry/) returns before it joins a model.
#include <array>
#include <optional>
#include <string>
#include <vector>

#include <jelly/core/springs.hpp>
#include <jelly/core/surface.hpp>
#include <jelly/core/types.hpp>

namespace jelly {

// Particles of a body chosen by name (a mesh's vertex group, a lattice corner), body-local.
struct ParticleGroup {
  std::string name;
  std::vector<int> particles;
};

// The volume a body fills, for measuring how much it is crushed (core/body_volume.hpp): the
// lattice's cells (corner c at grid offset (c & 1, (c >> 1) & 1, (c >> 2) & 1)) or a mesh's
// tetrahedra (positively oriented at rest). Both empty: a body without volume (cloth).
struct VolumeElements {
  std::vector<std::array<int, 8>> cells;
  std::vector<std::array<int, 4>> tets;

  bool empty() const { return cells.empty() && tets.empty(); }
  long size() const { return static_cast<long>(cells.size() + tets.size()); }
  void shift_particles(int offset);
};

// What a body builder makes: particles, springs and surface with indices local to the part.
struct BodyPart {
  std::string kind;  // the body kind that built it ("cube", "box", "cloth", ...)
  VecX mass;         // [n] kg
  VecX position;     // [3n] rest positions (m)
  Springs springs;   // local particle indices
  Surface surface;   // local particle indices
  Real spacing = 0;  // typical distance between neighbouring particles (m)
  std::vector<ParticleGroup> groups;
  VolumeElements volume;  // local particle indices
  // A sheet without volume (cloth): its particles keep their contact radius from terrains and
  // obstacles by default (Body::thickness), so the surface they span stays outside them.
  bool sheet = false;

  int num_particles() const { return static_cast<int>(mass.size()); }
};

struct Body {
  std::string name;  // unique in the model; the HDF5 group /particles/<name>
  std::string kind;
  int first_particle = 0, num_particles = 0;
  int first_spring = 0, num_springs = 0;
  Real spacing = 0;  // typical distance between neighbouring particles (m)
  Real radius = 0;   // contact radius of its particles (m)
  // The distance its particles keep from terrains and obstacles (m), in every contact model and
  // integrator: a sheet's contact radius by default, 0 for a body with volume.
  Real thickness = 0;
  // The body's motion at the start (initial_state): every particle moves with
  // velocity + angular_velocity x (x - c), c the body's centre of mass at rest.
  Vec3 velocity = Vec3::Zero();          // m/s
  Vec3 angular_velocity = Vec3::Zero();  // rad/s
  Surface surface;                       // global particle indices
  std::vector<ParticleGroup> groups;     // global particle indices
  VolumeElements volume;                 // global particle indices
  // Its colour in pictures and exports: sRGB [r, g, b], each in [0, 1]; none = the viewer's
  // palette by body index.
  std::optional<Vec3> color;

  int end_particle() const { return first_particle + num_particles; }
  int end_spring() const { return first_spring + num_springs; }
  bool contains(int particle) const {
    return particle >= first_particle && particle < end_particle();
  }
};

}  // namespace jelly
