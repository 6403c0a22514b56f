// What the weather does to LiDAR returns: inputs mirroring render::Atmosphere (the world
// engine sets both from one weather datapack) and the per-ray rules, deterministic for the
// random numbers they are given.
//
// Extinction (1/m): alpha = 3.912 / visibility (Koschmieder, as the camera's fog) plus
// precipitation p (0-1) x 0.002 for rain (about 2 km of visibility in a downpour) or x 0.01
// for snow. A return at range r keeps T = exp(-2 alpha r) of its intensity (out and back).
// It is lost when T sqrt(reflectivity x cos) falls below 0.02 (0.5 + u), u uniform per ray:
// a 25 % target fades out between about 0.36 and 0.5 of the visibility in fog, bright paint a
// little further. Clear air (alpha = 0) loses nothing.
// Spurious near returns: each ray meets a raindrop, flake or fog droplet before its surface
// with probability rain 0.004 p, snow 0.015 p, fog 0.02 min(1, 50 m / visibility); at a range
// drawn from an exponential of mean 3 m past range_min (kept only when nearer than the true
// return and within range_max), with intensity 0.02-0.1 and no ground truth.
#pragma once

#include <cmath>
#include <limits>

#include "render/scene.h"

namespace convoy::lidar {

struct LidarWeather {
  float visibility = std::numeric_limits<float>::infinity();  // m
  float precipitation = 0;                                    // 0-1
  bool snow = false;

  static LidarWeather from(const render::Atmosphere& a) {
    return {a.visibility, a.precipitation, a.snow};
  }
  double extinction() const;  // alpha, 1/m
  double spurious_probability() const;
  bool clear() const { return extinction() <= 0 && spurious_probability() <= 0; }
};

// A return's fate under the weather. u1, u2 uniform in [0, 1) from the ray's random stream.
struct WeatherEffect {
  bool kept;
  float intensity;  // scaled
};
WeatherEffect attenuate(double alpha, double range, float intensity, double u);

// A spurious return's range and intensity for this ray, or range < 0 for none.
struct Spurious {
  double range = -1;
  float intensity = 0;
};
Spurious spurious_return(double probability, double range_min, double u_hit, double u_range,
                         double u_intensity);

}  // namespace convoy::lidar
