// Poses for the renderer: 4x4 column-major matrices, world-from-object.
//
// Element (row r, column c) is m[4 * c + r], as in OpenGL and glm, so a Pose can be handed to
// glm::make_mat4. A Pose may carry scale (it is any affine transform); a camera's pose must
// be rigid. Positions in metres, angles in radians, SDF's conventions throughout.
#pragma once

#include <array>

namespace convoy::render {

using Pose = std::array<double, 16>;

Pose identity_pose();
// SDF <pose>x y z roll pitch yaw</pose>: rotation Rz(yaw) * Ry(pitch) * Rx(roll).
Pose make_pose(double x, double y, double z, double roll = 0, double pitch = 0, double yaw = 0);
// Position and unit quaternion (w, x, y, z); the quaternion is normalised here.
Pose make_pose_quat(const std::array<double, 3>& xyz, const std::array<double, 4>& wxyz);
// a * b: the pose of b's frame in a's parent when b is given in a's frame.
Pose compose(const Pose& a, const Pose& b);
// pose * diag(sx, sy, sz, 1): scales the object along its own axes.
Pose with_scale(const Pose& pose, double sx, double sy, double sz);

}  // namespace convoy::render
