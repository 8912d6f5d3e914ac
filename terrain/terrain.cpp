#include <Eigen/Geometry>
#include <jelly/terrain/terrain.hpp>

namespace jelly {

Eigen::Isometry3d Terrain::pose(Real t) const {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = position(t);
  return pose;
}

void Terrain::set_contact(const ContactParams& contact) {
  contact.validate("contact.");
  contact_ = contact;
}

}  // namespace jelly
