#pragma once
// Scalar and vector types used throughout jelly: positions and velocities are flat 3N vectors.
// Only <Eigen/Core>: public headers name Eigen's geometry types (AlignedBox, Transform) through
// the forward declarations it holds; a source that uses them (or cross()) includes
// <Eigen/Geometry> itself.
#include <Eigen/Core>

namespace jelly {

using Real = double;
using Vec3 = Eigen::Vector3d;
using VecX = Eigen::VectorXd;

// Particle i of a flat 3N vector: the segment [3i, 3i + 3).
inline Eigen::VectorBlock<VecX, 3> particle(VecX& v, int i) { return v.segment<3>(3 * i); }
inline Eigen::VectorBlock<const VecX, 3> particle(const VecX& v, int i) {
  return v.segment<3>(3 * i);
}

}  // namespace jelly
