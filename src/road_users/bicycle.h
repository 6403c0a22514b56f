// The kinematic bicycle: a vehicle's planar motion from its speed and steering angle, with
// the rear axle as reference point (no slip; right for the low lateral accelerations of
// everyday driving).
#pragma once

namespace convoy::road_users {

// A pose in the plane: the rear axle's centre and the heading (rad, from +x, counter-clockwise).
struct PlanarPose {
  double x = 0, y = 0, yaw = 0;
};

struct KinematicBicycle {
  double wheelbase = 2.7;  // m, rear to front axle
};

struct BicycleMotion {
  PlanarPose pose;      // after the step; yaw in [-pi, pi]
  double yaw_rate = 0;  // rad/s during the step
};

// One step of dt s at speed v (m/s) and steering angle `steer` (rad, left positive):
// yaw rate v tan(steer) / wheelbase, moved along the heading at mid-step (semi-implicit
// Euler: at a constant steer the poses lie exactly on a circle).
BicycleMotion step_bicycle(const KinematicBicycle& bicycle, const PlanarPose& pose, double v,
                           double steer, double dt);

}  // namespace convoy::road_users
