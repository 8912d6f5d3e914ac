#pragma once
// A recording read from an HDF5 file (io/recording.hpp) as a trajectory to fit: its model, frames
// and velocities, with the terrains, integrator and dt of the scene stored in the file.
#include <string>

#include <jelly/fit/spring_fit.hpp>
#include <jelly/io/recording.hpp>
#include <jelly/io/scene.hpp>

namespace jelly {

// Throws InputError when the recording holds no scene (it was not written by `jelly run`) or its
// scene is invalid. The coefficients of the returned model are those of the recording's scene.
Trajectory trajectory_from_recording(const Recording& recording);

// The recording's scene with the fitted coefficients written into every body's spring types.
Scene fitted_scene(const Recording& recording, const FitResult& result);

}  // namespace jelly
