// sdformat's (ignition math) poses and vectors as Eigen's, for the world's description.
#pragma once

#include <Eigen/Geometry>
#include <ignition/math/Pose3.hh>
#include <ignition/math/Vector3.hh>

namespace convoy::world {

inline Eigen::Isometry3d to_eigen(const ignition::math::Pose3d& p) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = Eigen::Vector3d(p.Pos().X(), p.Pos().Y(), p.Pos().Z());
  t.linear() = Eigen::Quaterniond(p.Rot().W(), p.Rot().X(), p.Rot().Y(), p.Rot().Z())
                   .normalized()
                   .toRotationMatrix();
  return t;
}

inline Eigen::Vector3d to_eigen(const ignition::math::Vector3d& v) { return {v.X(), v.Y(), v.Z()}; }

}  // namespace convoy::world
