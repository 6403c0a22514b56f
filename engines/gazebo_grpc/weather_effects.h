// The weather datapack as the world engine applies it (docs/weather.md): to its cameras (fog,
// rain, snow, wet and snowy ground, the sun, night and headlights) and to its physics (tyre
// friction, wind).
#pragma once

#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

namespace convoy::world {

struct Weather {
  double precipitation = 0;  // 0-1
  bool snow = false;         // precipitation is snow
  double visibility_m = std::numeric_limits<double>::infinity();
  double mu = 0.8, wetness = 0, snow_cover = 0;
  double sun_altitude_deg = 45, sun_azimuth_deg = 135;  // compass azimuth
  double daylight = 1;
  bool night = false;
  double wind_x = 0, wind_y = 0;  // m/s
  uint64_t seed = 0;
};

// Reads the weather engine's JSON (keys of weather_model.h's WeatherState; missing keys keep
// their defaults). Throws std::invalid_argument naming the key for a wrong type or value.
Weather weather_from_json(const nlohmann::json& j);

}  // namespace convoy::world
