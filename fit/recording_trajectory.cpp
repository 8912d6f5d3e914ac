#include <jelly/fit/detail/recording_trajectory.hpp>

#include <jelly/core/errors.hpp>
#include <jelly/fit/spring_fit.hpp>

namespace jelly {

namespace {

Scene recording_scene(const Recording& recording) {
  require(!recording.scene_json.empty(), "recording.parameters.scene", "(none)",
          "a recording written by `jelly run`, which stores its scene");
  return parse_scene(recording.scene_json);
}

}  // namespace

Trajectory trajectory_from_recording(const Recording& recording) {
  const Scene scene = recording_scene(recording);
  Trajectory t;
  t.model = recording.model;
  t.times = recording.time;
  t.positions = recording.position;
  if (recording.velocity.size() == recording.position.size()) t.velocities = recording.velocity;
  const std::vector<PolymorphicValue<TerrainSpec>> specs = scene.terrains;
  if (!specs.empty()) {
    t.terrains = [specs] {
      Terrains terrains;
      for (const auto& spec : specs) terrains.push_back(spec->make());
      return terrains;
    };
  }
  t.integrator = scene.integrator.name;
  t.integrator_options = scene.integrator.options;
  t.dt = scene.integrator.dt;
  t.body_contact = scene.body_contact;
  t.validate();
  return t;
}

Scene fitted_scene(const Recording& recording, const FitResult& result) {
  Scene scene = recording_scene(recording);
  for (BodySpec& body : scene.bodies) apply_fit(body.material, result, body.name);
  return scene;
}

}  // namespace jelly
