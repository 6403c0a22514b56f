// Planar wheel odometry (issue 27): a vehicle's pose and speed integrated from its two rear
// wheels' spin, as an ABS wheel-speed odometer gives it, with its errors.
//
//   speed    = r (w_left s_left + w_right s_right) / 2      (m/s, forward)
//   yaw rate = r (w_right s_right - w_left s_left) / track  (rad/s)
//              or, with a steering angle and a wheelbase, speed tan(steering) / wheelbase
//   x, y, yaw: integrated at the mid-point heading every sample
// r: wheel radius (m), w: joint speeds (rad/s), s: each wheel's scale factor, drawn once per
// sensor from N(1, scale_stddev) (tyre wear, pressure); every sample each wheel's surface
// speed gets white noise N(0, slip_stddev) m/s (slip, the encoder's jitter). Draws from the
// counter-based generator of nav_sensors/noise.h keyed by (seed, wheel, sample): the same seed
// gives the same track.
#pragma once

#include <cstdint>

namespace convoy::wheel_odometry {

struct OdometryParams {
  double wheel_radius = 0.3;  // m
  double track = 1.6;         // m, between the rear wheels
  double wheelbase = 0;       // m, for the steering's yaw rate (0: wheel speeds' difference)
  double scale_stddev = 0;    // relative, per wheel, drawn once
  double slip_stddev = 0;     // m/s, per wheel and sample
  double update_rate = 0;     // Hz; 0: every step

  // Throws std::invalid_argument naming the field.
  void validate() const;
};

struct OdometryState {
  double x = 0, y = 0, yaw = 0, speed = 0, yaw_rate = 0, steering = 0, distance = 0;
};

class OdometryModel {
 public:
  OdometryModel(const OdometryParams& params, uint64_t seed);
  // One sample `dt` s after the last: the rear wheels' joint speeds (rad/s, forward
  // positive), the steering angle (rad; used when the wheelbase is set).
  const OdometryState& update(double left, double right, double steering, double dt);
  const OdometryState& state() const { return state_; }
  void reset();
  double scale(int wheel) const { return scale_[wheel]; }

 private:
  OdometryParams p_;
  uint64_t seed_;
  double scale_[2] = {1, 1};
  uint64_t samples_ = 0;
  OdometryState state_;
};

}  // namespace convoy::wheel_odometry
