// Pure pursuit (Coulter 1992): the steering angle that takes a kinematic bicycle's rear axle
// on a circular arc through a target point a lookahead distance ahead on its path.
#pragma once

#include "road_users/bicycle.h"
#include "road_users/path.h"

namespace convoy::road_users {

struct PurePursuit {
  // Lookahead from the front axle along the path: max(min_lookahead, gain v + offset) m.
  double min_lookahead = 4.0;
  double lookahead_gain = 0.8;  // s
  double lookahead_offset = 2.0;
  double max_steer = 0.6;  // rad, either way

  double lookahead(double v) const;
  // The steering angle towards (tx, ty) from `pose` (rear axle) for a wheelbase: atan of
  // 2 wheelbase sin(alpha) / distance (at least 1 m), clamped to max_steer.
  double steer(const PlanarPose& pose, double tx, double ty, double wheelbase) const;
};

// The point `a` m along `path`; with `beyond_end`, past its end it goes on straight along the
// last heading (else it stays at the end).
opendrive::Pose2 pursuit_target(const Path& path, double a, bool beyond_end);

// Steering for a bicycle whose rear axle is at `arc` on `path` (at `pose`), at speed v.
double pursue(const PurePursuit& pursuit, const KinematicBicycle& bicycle, const Path& path,
              double arc, const PlanarPose& pose, double v, bool beyond_end);

}  // namespace convoy::road_users
