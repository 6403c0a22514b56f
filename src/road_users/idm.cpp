#include "road_users/idm.h"

#include <algorithm>
#include <cmath>

namespace convoy::road_users {

double Idm::accel(double v, double gap, double vl, double v0_here) const {
  const double v0e = std::max(v0_here, 0.1);
  double acc = a * (1.0 - std::pow(std::max(v, 0.0) / v0e, delta));
  if (std::isfinite(gap)) {
    const double dv = v - vl;
    const double s_star = s0 + std::max(0.0, v * T + v * dv / (2.0 * std::sqrt(a * b)));
    const double g = std::max(gap, 0.01);
    acc -= a * (s_star / g) * (s_star / g);
  }
  return acc;
}

}  // namespace convoy::road_users
