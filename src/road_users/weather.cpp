#include "road_users/weather.h"

#include <algorithm>

namespace convoy::road_users {

Driving adapt_to_weather(const Idm& base, const Weather& weather) {
  Driving d{base};
  const double mu = weather.mu, visibility_m = weather.visibility_m;
  const double loss = std::clamp(1.0 - mu / 0.8, 0.0, 1.0);  // 0 dry .. 1 no grip
  const double grip = std::max(0.5 * mu * 9.81, 0.3);        // comfortable use of the grip
  d.speed_factor = 1.0 - 0.4 * loss;
  d.idm.v0 = base.v0 * d.speed_factor;
  d.idm.T = base.T * (1.0 + 0.5 * loss);
  d.idm.a = std::min(base.a, grip);
  d.idm.b = std::min(base.b, grip);
  if (visibility_m < 1000.0) {
    d.idm.T *= 1.0 + 0.3 * std::clamp((1000.0 - visibility_m) / 900.0, 0.0, 1.0);
    // Stop within the visibility: 1.5 s v + v^2 / (2 grip) = V.
    const double tr = 1.5;
    d.visibility_speed = grip * (-tr + std::sqrt(tr * tr + 2.0 * visibility_m / grip));
  }
  return d;
}

double desired_speed(const Driving& driving, double limit_factor,
                     std::optional<double> lane_limit) {
  double v = driving.idm.v0;
  if (limit_factor > 0 && lane_limit && std::isfinite(*lane_limit))
    v = limit_factor * *lane_limit * driving.speed_factor;
  return std::min(v, driving.visibility_speed);
}

}  // namespace convoy::road_users
