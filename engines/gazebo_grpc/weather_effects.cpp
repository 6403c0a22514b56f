#include "weather_effects.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace convoy::world {

Weather weather_from_json(const nlohmann::json& j) {
  if (!j.is_object()) throw std::invalid_argument("expected a JSON object, got " + j.dump());
  Weather w;
  auto num = [&](const char* key, double* out, double lo, double hi) {
    if (!j.contains(key) || j[key].is_null()) return;
    const auto& v = j[key];
    if (!v.is_number()) throw std::invalid_argument(std::string(key) + ": expected a number");
    const double d = v.get<double>();
    if (!(d >= lo && d <= hi))
      throw std::invalid_argument(std::string(key) + ": " + v.dump() + " is out of range [" +
                                  std::to_string(lo) + ", " + std::to_string(hi) + "]");
    *out = d;
  };
  num("precipitation", &w.precipitation, 0, 1);
  num("visibility_m", &w.visibility_m, 1e-3, std::numeric_limits<double>::infinity());
  num("mu", &w.mu, 0, 10);
  num("wetness", &w.wetness, 0, 1);
  num("snow_cover", &w.snow_cover, 0, 1);
  num("sun_altitude_deg", &w.sun_altitude_deg, -90, 90);
  num("sun_azimuth_deg", &w.sun_azimuth_deg, -720, 720);
  num("daylight", &w.daylight, 0, 1);
  if (j.contains("precipitation_type")) {
    const auto& t = j["precipitation_type"];
    if (!t.is_string() || (t != "rain" && t != "snow" && t != "none"))
      throw std::invalid_argument(
          "precipitation_type: expected \"rain\", \"snow\" or \"none\", got " + t.dump());
    w.snow = t == "snow";
    if (t == "none") w.precipitation = 0;
  }
  if (j.contains("night")) {
    if (!j["night"].is_boolean()) throw std::invalid_argument("night: expected true or false");
    w.night = j["night"].get<bool>();
  } else {
    w.night = w.sun_altitude_deg < 0;
  }
  if (!j.contains("daylight")) {
    const double t = std::clamp((w.sun_altitude_deg + 6.0) / 12.0, 0.0, 1.0);
    w.daylight = t * t * (3 - 2 * t);
  }
  if (j.contains("wind")) {
    const auto& v = j["wind"];
    if (!v.is_array() || v.size() < 2 || !v[0].is_number() || !v[1].is_number())
      throw std::invalid_argument("wind: expected [x, y] in m/s");
    w.wind_x = v[0].get<double>();
    w.wind_y = v[1].get<double>();
  }
  if (j.contains("seed")) {
    if (!j["seed"].is_number_integer()) throw std::invalid_argument("seed: expected an integer");
    w.seed = j["seed"].get<uint64_t>();
  }
  return w;
}

}  // namespace convoy::world
