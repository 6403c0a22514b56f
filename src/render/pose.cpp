#include "render/pose.h"

#include <cmath>
#include <stdexcept>

namespace convoy::render {

Pose identity_pose() { return {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}; }

Pose make_pose(double x, double y, double z, double roll, double pitch, double yaw) {
  const double cr = std::cos(roll), sr = std::sin(roll);
  const double cp = std::cos(pitch), sp = std::sin(pitch);
  const double cy = std::cos(yaw), sy = std::sin(yaw);
  // Columns of Rz(yaw) * Ry(pitch) * Rx(roll).
  return {cy * cp,
          sy * cp,
          -sp,
          0,
          cy * sp * sr - sy * cr,
          sy * sp * sr + cy * cr,
          cp * sr,
          0,
          cy * sp * cr + sy * sr,
          sy * sp * cr - cy * sr,
          cp * cr,
          0,
          x,
          y,
          z,
          1};
}

Pose make_pose_quat(const std::array<double, 3>& xyz, const std::array<double, 4>& wxyz) {
  const double n =
      std::sqrt(wxyz[0] * wxyz[0] + wxyz[1] * wxyz[1] + wxyz[2] * wxyz[2] + wxyz[3] * wxyz[3]);
  if (!(n > 0) || !std::isfinite(n)) {
    throw std::invalid_argument("make_pose_quat: quaternion has no direction");
  }
  const double w = wxyz[0] / n, x = wxyz[1] / n, y = wxyz[2] / n, z = wxyz[3] / n;
  return {1 - 2 * (y * y + z * z),
          2 * (x * y + w * z),
          2 * (x * z - w * y),
          0,
          2 * (x * y - w * z),
          1 - 2 * (x * x + z * z),
          2 * (y * z + w * x),
          0,
          2 * (x * z + w * y),
          2 * (y * z - w * x),
          1 - 2 * (x * x + y * y),
          0,
          xyz[0],
          xyz[1],
          xyz[2],
          1};
}

Pose compose(const Pose& a, const Pose& b) {
  Pose r{};
  for (int c = 0; c < 4; ++c) {
    for (int row = 0; row < 4; ++row) {
      double s = 0;
      for (int k = 0; k < 4; ++k) s += a[4 * k + row] * b[4 * c + k];
      r[4 * c + row] = s;
    }
  }
  return r;
}

Pose with_scale(const Pose& pose, double sx, double sy, double sz) {
  Pose r = pose;
  const double s[3] = {sx, sy, sz};
  for (int c = 0; c < 3; ++c) {
    for (int row = 0; row < 4; ++row) r[4 * c + row] *= s[c];
  }
  return r;
}

}  // namespace convoy::render
