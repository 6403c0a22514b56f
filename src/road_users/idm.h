// The Intelligent Driver Model (Treiber, Hennecke, Helbing 2000): a driver's longitudinal
// acceleration from its speed, its desired speed and the gap to the one ahead.
#pragma once

namespace convoy::road_users {

// A driver's IDM parameters: desired speed v0 (m/s), time headway T (s), jam distance s0 (m),
// maximum acceleration a and comfortable deceleration b (m/s^2), acceleration exponent delta.
struct Idm {
  double v0 = 13.9, T = 1.5, s0 = 2.0, a = 1.5, b = 2.0, delta = 4.0;

  // Acceleration at speed v with a leader `gap` m ahead (bumper to bumper) at speed vl, where
  // the desired speed is v0_here (at least 0.1 m/s is used); gap = +inf: free road. A gap
  // under 0.01 m counts as 0.01 m. Not clamped: the caller bounds it by its braking limit.
  double accel(double v, double gap, double vl, double v0_here) const;
};

}  // namespace convoy::road_users
