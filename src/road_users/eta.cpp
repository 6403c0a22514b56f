#include "road_users/eta.h"

#include <algorithm>
#include <cmath>

namespace convoy::road_users {

double eta(double d, double v, double a, double v0) {
  if (d <= 0) return 0;
  v = std::max(v, 0.0);
  const double t_up = std::max(v0 - v, 0.0) / a;
  const double d_up = v * t_up + 0.5 * a * t_up * t_up;
  if (d <= d_up) return (-v + std::sqrt(v * v + 2 * a * d)) / a;
  return t_up + (d - d_up) / std::max({v0, v, 0.1});  // one faster than v0 keeps its speed
}

}  // namespace convoy::road_users
