// The weather's state over simulated time: the `weather` engine's model (weather_engine.cpp),
// kept apart so that it is tested without an engine process.
//
// A WeatherModel is made from the engine's config: the initial state (top-level keys) and a
// Schedule of changes. Each change, at its Time (s), moves the keys it names to new values,
// linearly over its Transition (s; 0: at once). Visibility moves in log space (fog thickens
// evenly to the eye), angles the short way round. A change starts from whatever value its
// keys have at its Time, so changes may overlap. The surface moves as its numbers (mu,
// wetness, snow cover); the surface named is the target's once the transition is half done.
//
// Gusts: the wind's speed is WindSpeed x (1 + Gusts x g), g an Ornstein-Uhlenbeck process
// (unit variance, 3 s time constant) drawn from Seed, one draw per step: the same seed and
// steps give the same gusts.
//
// Config keys (all optional; see engines/weather/schema.json):
//   Seed, Precipitation (0-1), PrecipitationType ("rain" | "snow"), Visibility (m, > 0),
//   Surface ("dry" | "wet" | "snow" | "ice"), SunAltitude, SunAzimuth (degrees; azimuth is a
//   compass bearing, 0 = north = world +y, 90 = east = world +x), TimeOfDay (hours, 0-24; sets
//   the sun on a simple path: up at 6, highest (60 degrees, south) at 12, down at 18),
//   WindSpeed (m/s), WindDirection (degrees, where the wind blows towards, counter-clockwise
//   from world +x), Gusts (0-1), Schedule ([{Time, Transition, <state keys>}], in time order).
//
// Control at run time: control(keys, t) takes a dict of state keys plus TransitionTime (s,
// default 0) at simulated time t (the `weather` engine's ControlDataPack). From t the keys it
// names move linearly from their value at t to the new ones over TransitionTime, as a
// Schedule entry would; from then on the Schedule no longer moves those keys (the control
// overrides it; a later control overrides an earlier one). Keys it does not name go on as
// before. The same control received again (equal content) is ignored.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

namespace convoy::weather {

// Tyre-road friction per surface (Noon; Bosch Automotive Handbook).
struct SurfaceInfo {
  const char* name;
  double mu, wetness, snow_cover;
};
inline constexpr SurfaceInfo kSurfaces[] = {{"dry", 0.8, 0.0, 0.0},
                                            {"wet", 0.5, 1.0, 0.0},
                                            {"snow", 0.25, 0.2, 1.0},
                                            {"ice", 0.1, 0.6, 0.0}};

// Meteorological visibility of clear air (m): fog is visibility below 1000 m.
inline constexpr double kClearVisibility = 20000.0;

struct WeatherState {
  double time_s = 0;
  double precipitation = 0;  // 0-1
  std::string precipitation_type = "rain";
  double visibility_m = kClearVisibility;
  std::string surface = "dry";
  double mu = 0.8, wetness = 0, snow_cover = 0;
  double sun_altitude_deg = 45, sun_azimuth_deg = 135;
  double daylight = 1;  // 1 by day, 0 by night, a ramp through civil twilight (-6..+6 degrees)
  bool night = false;   // the sun below the horizon
  double wind_speed_mps = 0, wind_direction_deg = 0;  // with gusts
  double wind_x = 0, wind_y = 0;                      // m/s, world frame
  uint64_t seed = 0;

  nlohmann::json to_json() const;
};

class WeatherModel {
 public:
  // Throws std::invalid_argument naming the key ("Schedule[2].Surface: ...") on bad input.
  explicit WeatherModel(const nlohmann::json& config);

  // The state at simulated time t (s); advances the gusts by one draw when t has moved on.
  const WeatherState& advance(double t);
  const WeatherState& state() const { return state_; }
  void reset();
  // A change at run time from simulated time t (>= the last advance's); throws
  // std::invalid_argument naming "<where>.<Key>" on bad input. Returns false when it was the
  // same as the previous control (ignored).
  bool control(const nlohmann::json& keys, double t, const std::string& where);

  // The sun's (altitude, azimuth) in degrees at `hours` on the simple path (see above).
  static std::pair<double, double> sun_at(double hours);

 private:
  enum Key {
    kPrecipitation,
    kVisibility,
    kMu,
    kWetness,
    kSnow,
    kAltitude,
    kAzimuth,
    kWindSpeed,
    kWindDirection,
    kKeys
  };
  struct Change {
    double time = 0, transition = 0;
    bool has[kKeys] = {};
    double to[kKeys] = {};
    double from[kKeys] = {};  // filled in order: the value at `time`
    std::string surface, precipitation_type;
  };
  double value_at(int key, double t, size_t changes_before) const;
  // With the run-time controls: the last control naming the key at or before t wins, from the
  // value the key had when it came; else the Schedule.
  double current(int key, double t) const;
  // Reads the state keys of `obj` into c; `allowed` are the keys accepted besides the state
  // keys (unknown keys are errors when strict); errors name where.Key (Key alone when where
  // is empty).
  static void read_keys(const nlohmann::json& obj, const std::string& where, bool strict,
                        const std::vector<std::string>& allowed, Change* c);

  double initial_[kKeys] = {};
  std::string initial_surface_, initial_type_;
  double gusts_ = 0;
  uint64_t seed_ = 0;
  std::vector<Change> changes_;
  std::vector<Change> controls_;  // run-time changes, in order of arrival
  nlohmann::json last_control_;
  std::mt19937_64 rng_;
  double gust_ = 0, last_t_ = -1;
  WeatherState state_;
};

}  // namespace convoy::weather
