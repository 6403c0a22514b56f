// Driving as people do in bad weather (docs/weather.md): on a road of friction mu (0.8 dry)
// the desired speed is x (1 - 0.4 (1 - mu/0.8)) and the time headway T x (1 + 0.5 (1 -
// mu/0.8)); a and b are at most 0.5 mu g (at least 0.3 m/s^2); in fog (visibility V < 1000 m)
// T grows by up to 30 % more and the speed is capped so that it stops within V (1.5 s of
// reaction plus braking at that grip).
#pragma once

#include <cmath>
#include <optional>

#include "road_users/idm.h"

namespace convoy::road_users {

struct Weather {
  double mu = 0.8;                 // road friction
  double visibility_m = INFINITY;  // m
};

// A driver's parameters for the weather it drives in.
struct Driving {
  Idm idm;                             // v0, T, a and b adapted
  double speed_factor = 1.0;           // on the speed limit
  double visibility_speed = INFINITY;  // m/s: at most this, to stop within the visibility
};

// The driver with IDM parameters `base` (as configured, for dry clear weather) in `weather`.
Driving adapt_to_weather(const Idm& base, const Weather& weather);

// Its desired speed: idm.v0; on a lane with a known speed limit (lane_limit, m/s) and
// limit_factor > 0, limit_factor x the limit x the speed factor instead; at most the
// visibility speed.
double desired_speed(const Driving& driving, double limit_factor, std::optional<double> lane_limit);

}  // namespace convoy::road_users
