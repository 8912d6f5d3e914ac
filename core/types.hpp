#pragma once
// Scalar and vector types used throughout jelly: positions and velocities are flat 3N vectors.
// Only <Eigen/Core>: public headers name Eigen's geometry types (AlignedBox, Transform) through
// the forward declarations it holds; a source that uses them (or cross()) includes
// <Eigen/Geometry> itself.
#include <Eigen/Core>

namespace jelly {

using Real = double;           // every scalar of the library
using Vec3 = Eigen::Vector3d;  // a point or vector in 3D (m, m/s, N)
using VecX = Eigen::VectorXd;  // a flat vector of 3N entries: particle i at [3i, 3i + 3)

// Particle i of a flat 3N vector: the segment [3i, 3i + 3).
inline Eigen::VectorBlock<VecX, 3> particle(VecX& v, int i) { return v.segment<3>(3 * i); }
// The same for a read-only vector.
inline Eigen::VectorBlock<const VecX, 3> particle(const VecX& v, int i) {
  return v.segment<3>(3 * i);
}

}  // namespace jelly
