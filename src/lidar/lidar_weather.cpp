#include "lidar/lidar_weather.h"

#include <algorithm>

namespace convoy::lidar {

double LidarWeather::extinction() const {
  double alpha = 0;
  if (std::isfinite(visibility) && visibility > 0) alpha += 3.912 / visibility;
  const double p = std::clamp<double>(precipitation, 0, 1);
  alpha += p * (snow ? 0.01 : 0.002);
  return alpha;
}

double LidarWeather::spurious_probability() const {
  const double p = std::clamp<double>(precipitation, 0, 1);
  double q = p * (snow ? 0.015 : 0.004);
  if (std::isfinite(visibility) && visibility > 0) q += 0.02 * std::min(1.0, 50.0 / visibility);
  return q;
}

WeatherEffect attenuate(double alpha, double range, float intensity, double u) {
  if (alpha <= 0) return {true, intensity};
  const double t = std::exp(-2 * alpha * range);
  const bool kept = t * std::sqrt(std::max(intensity, 0.0f)) >= 0.02 * (0.5 + u);
  return {kept, static_cast<float>(intensity * t)};
}

Spurious spurious_return(double probability, double range_min, double u_hit, double u_range,
                         double u_intensity) {
  if (u_hit >= probability) return {};
  Spurious s;
  s.range = range_min - 3.0 * std::log1p(-u_range);  // exponential, mean 3 m past range_min
  s.intensity = static_cast<float>(0.02 + 0.08 * u_intensity);
  return s;
}

}  // namespace convoy::lidar
