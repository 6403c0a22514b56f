#include "weather_model.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace convoy::weather {
namespace {

using nlohmann::json;

[[noreturn]] void bad(const std::string& key, const std::string& why) {
  throw std::invalid_argument(key + ": " + why);
}

double number(const json& obj, const char* k, const std::string& key) {
  const json& v = obj.at(k);
  if (!v.is_number() || !std::isfinite(v.get<double>()))
    bad(key, "expected a number, got " + v.dump());
  return v.get<double>();
}

const SurfaceInfo* surface_named(const std::string& name) {
  for (const auto& s : kSurfaces)
    if (name == s.name) return &s;
  return nullptr;
}

double wrap180(double a) {
  a = std::fmod(a + 180.0, 360.0);
  if (a < 0) a += 360.0;
  return a - 180.0;
}

double smoothstep(double e0, double e1, double x) {
  const double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
  return t * t * (3 - 2 * t);
}

}  // namespace

json WeatherState::to_json() const {
  return {{"time_s", time_s},
          {"precipitation", precipitation},
          {"precipitation_type", precipitation > 0 ? precipitation_type : std::string("none")},
          {"visibility_m", visibility_m},
          {"fog", visibility_m < 1000.0},
          {"surface", surface},
          {"mu", mu},
          {"wetness", wetness},
          {"snow_cover", snow_cover},
          {"sun_altitude_deg", sun_altitude_deg},
          {"sun_azimuth_deg", sun_azimuth_deg},
          {"daylight", daylight},
          {"night", night},
          {"wind_speed_mps", wind_speed_mps},
          {"wind_direction_deg", wind_direction_deg},
          {"wind", {wind_x, wind_y}},
          {"seed", seed}};
}

std::pair<double, double> WeatherModel::sun_at(double hours) {
  // Up at 6 in the east, 60 degrees high in the south at 12, down at 18 in the west.
  const double phase = (hours - 6.0) / 12.0 * std::numbers::pi;
  const double altitude = 60.0 * std::sin(phase);
  const double azimuth = std::fmod(90.0 + (hours - 6.0) * 15.0 + 720.0, 360.0);
  return {altitude, azimuth};
}

void WeatherModel::read_keys(const json& obj, const std::string& where, bool strict,
                             const std::vector<std::string>& allowed, Change* c) {
  auto key = [&](const std::string& k) { return where.empty() ? k : where + "." + k; };
  auto set = [&](int k, double v) {
    c->has[k] = true;
    c->to[k] = v;
  };
  if (strict) {
    static const char* state_keys[] = {"Precipitation", "PrecipitationType", "Visibility",
                                       "Surface",       "SunAltitude",       "SunAzimuth",
                                       "TimeOfDay",     "WindSpeed",         "WindDirection"};
    std::string list;
    for (const auto& a : allowed) list += a + ", ";
    for (const char* k : state_keys) list += std::string(k) + (k == state_keys[8] ? "" : ", ");
    for (const auto& [k, v] : obj.items()) {
      if (std::find(std::begin(state_keys), std::end(state_keys), k) == std::end(state_keys) &&
          std::find(allowed.begin(), allowed.end(), k) == allowed.end())
        bad(key(k), "unknown key (" + list + ")");
    }
  }
  if (obj.contains("Precipitation")) {
    const double p = number(obj, "Precipitation", key("Precipitation"));
    if (p < 0 || p > 1) bad(key("Precipitation"), "must be in [0, 1], got " + std::to_string(p));
    set(kPrecipitation, p);
  }
  if (obj.contains("PrecipitationType")) {
    const json& v = obj["PrecipitationType"];
    if (!v.is_string() || (v != "rain" && v != "snow"))
      bad(key("PrecipitationType"), "expected \"rain\" or \"snow\", got " + v.dump());
    c->precipitation_type = v.get<std::string>();
  }
  if (obj.contains("Visibility")) {
    const double v = number(obj, "Visibility", key("Visibility"));
    if (!(v > 0)) bad(key("Visibility"), "must be > 0 m, got " + obj["Visibility"].dump());
    set(kVisibility, std::log(std::min(v, 1e7)));
  }
  if (obj.contains("Surface")) {
    const json& v = obj["Surface"];
    const SurfaceInfo* s = v.is_string() ? surface_named(v.get<std::string>()) : nullptr;
    if (!s) bad(key("Surface"), "unknown surface " + v.dump() + " (dry, wet, snow, ice)");
    c->surface = s->name;
    set(kMu, s->mu);
    set(kWetness, s->wetness);
    set(kSnow, s->snow_cover);
  }
  if (obj.contains("TimeOfDay")) {
    if (obj.contains("SunAltitude") || obj.contains("SunAzimuth"))
      bad(key("TimeOfDay"), "give either TimeOfDay or SunAltitude/SunAzimuth, not both");
    const double h = number(obj, "TimeOfDay", key("TimeOfDay"));
    if (h < 0 || h > 24)
      bad(key("TimeOfDay"), "must be in [0, 24] hours, got " + obj["TimeOfDay"].dump());
    auto [alt, az] = sun_at(h);
    set(kAltitude, alt);
    set(kAzimuth, az);
  }
  if (obj.contains("SunAltitude")) {
    const double a = number(obj, "SunAltitude", key("SunAltitude"));
    if (a < -90 || a > 90) bad(key("SunAltitude"), "must be in [-90, 90] degrees");
    set(kAltitude, a);
  }
  if (obj.contains("SunAzimuth")) set(kAzimuth, number(obj, "SunAzimuth", key("SunAzimuth")));
  if (obj.contains("WindSpeed")) {
    const double w = number(obj, "WindSpeed", key("WindSpeed"));
    if (w < 0) bad(key("WindSpeed"), "must be >= 0 m/s, got " + obj["WindSpeed"].dump());
    set(kWindSpeed, w);
  }
  if (obj.contains("WindDirection"))
    set(kWindDirection, number(obj, "WindDirection", key("WindDirection")));
}

WeatherModel::WeatherModel(const json& config) {
  if (!config.is_object()) bad("config", "expected an object");
  initial_[kPrecipitation] = 0;
  initial_[kVisibility] = std::log(kClearVisibility);
  initial_[kAltitude] = 45;
  initial_[kAzimuth] = 135;
  initial_[kWindSpeed] = 0;
  initial_[kWindDirection] = 0;
  initial_surface_ = "dry";
  initial_type_ = "rain";

  Change initial;
  read_keys(config, "", false, {}, &initial);
  for (int k = 0; k < kKeys; ++k)
    if (initial.has[k]) initial_[k] = initial.to[k];
  if (!initial.surface.empty()) initial_surface_ = initial.surface;
  if (!initial.precipitation_type.empty()) initial_type_ = initial.precipitation_type;
  const SurfaceInfo* s0 = surface_named(initial_surface_);
  initial_[kMu] = s0->mu;
  initial_[kWetness] = s0->wetness;
  initial_[kSnow] = s0->snow_cover;
  if (config.contains("Seed")) {
    const json& v = config["Seed"];
    if (!v.is_number_integer() || v.get<int64_t>() < 0) bad("Seed", "expected an integer >= 0");
    seed_ = v.get<uint64_t>();
  }
  if (config.contains("Gusts")) {
    gusts_ = number(config, "Gusts", "Gusts");
    if (gusts_ < 0 || gusts_ > 1) bad("Gusts", "must be in [0, 1]");
  } else {
    gusts_ = 0.3;
  }

  if (config.contains("Schedule")) {
    const json& sched = config["Schedule"];
    if (!sched.is_array()) bad("Schedule", "expected a list of {Time, Transition, ...}");
    for (size_t i = 0; i < sched.size(); ++i) {
      const std::string where = "Schedule[" + std::to_string(i) + "]";
      const json& e = sched[i];
      if (!e.is_object() || !e.contains("Time"))
        bad(where, "expected an object with Time (s) and the keys to change");
      Change c;
      c.time = number(e, "Time", where + ".Time");
      if (c.time < 0) bad(where + ".Time", "must be >= 0 s, got " + e["Time"].dump());
      if (!changes_.empty() && c.time < changes_.back().time) {
        bad(where + ".Time", "the schedule is out of order: " + e["Time"].dump() +
                                 " s comes after Schedule[" + std::to_string(i - 1) +
                                 "].Time = " + sched[i - 1]["Time"].dump() + " s");
      }
      if (e.contains("Transition")) {
        c.transition = number(e, "Transition", where + ".Transition");
        if (c.transition < 0) bad(where + ".Transition", "must be >= 0 s");
      }
      read_keys(e, where, true, {"Time", "Transition"}, &c);
      changes_.push_back(std::move(c));
    }
    // Each change starts from the values its keys have at its time.
    for (size_t i = 0; i < changes_.size(); ++i) {
      Change& c = changes_[i];
      for (int k = 0; k < kKeys; ++k) {
        if (!c.has[k]) continue;
        c.from[k] = value_at(k, c.time, i);
        if (k == kAzimuth || k == kWindDirection)
          c.to[k] = c.from[k] + wrap180(c.to[k] - c.from[k]);
      }
    }
  }
  reset();
}

double WeatherModel::value_at(int key, double t, size_t changes_before) const {
  double v = initial_[key];
  for (size_t i = 0; i < changes_before && i < changes_.size(); ++i) {
    const Change& c = changes_[i];
    if (c.time > t) break;
    if (!c.has[key]) continue;
    const double f = c.transition > 0 ? std::min(1.0, (t - c.time) / c.transition) : 1.0;
    v = c.from[key] + (c.to[key] - c.from[key]) * f;
  }
  return v;
}

double WeatherModel::current(int key, double t) const {
  for (auto it = controls_.rbegin(); it != controls_.rend(); ++it) {
    if (it->time > t || !it->has[key]) continue;
    const double f = it->transition > 0 ? std::min(1.0, (t - it->time) / it->transition) : 1.0;
    return it->from[key] + (it->to[key] - it->from[key]) * f;
  }
  return value_at(key, t, changes_.size());
}

bool WeatherModel::control(const json& keys, double t, const std::string& where) {
  if (!keys.is_object()) bad(where, "expected a JSON object of weather keys, got " + keys.dump());
  if (keys == last_control_) return false;
  Change c;
  c.time = t;
  if (keys.contains("TransitionTime")) {
    c.transition = number(keys, "TransitionTime", where + ".TransitionTime");
    if (c.transition < 0)
      bad(where + ".TransitionTime", "must be >= 0 s, got " + keys["TransitionTime"].dump());
  }
  read_keys(keys, where, true, {"TransitionTime"}, &c);
  for (int k = 0; k < kKeys; ++k) {
    if (!c.has[k]) continue;
    c.from[k] = current(k, t);
    if (k == kAzimuth || k == kWindDirection) c.to[k] = c.from[k] + wrap180(c.to[k] - c.from[k]);
  }
  controls_.push_back(std::move(c));
  last_control_ = keys;
  return true;
}

void WeatherModel::reset() {
  controls_.clear();
  last_control_ = json();
  rng_.seed(seed_);
  gust_ = 0;
  last_t_ = -1;
  advance(0.0);
}

const WeatherState& WeatherModel::advance(double t) {
  if (t > last_t_) {
    // Ornstein-Uhlenbeck gust factor, unit variance, 3 s time constant.
    const double dt = last_t_ < 0 ? 0.0 : t - last_t_;
    const double a = std::exp(-dt / 3.0);
    std::normal_distribution<double> n01(0.0, 1.0);
    const double draw = n01(rng_);
    gust_ = last_t_ < 0 ? 0.0 : a * gust_ + std::sqrt(1 - a * a) * draw;
    last_t_ = t;
  }
  WeatherState& s = state_;
  s.time_s = t;
  s.seed = seed_;
  s.precipitation = std::clamp(current(kPrecipitation, t), 0.0, 1.0);
  s.visibility_m = std::exp(current(kVisibility, t));
  s.mu = current(kMu, t);
  s.wetness = current(kWetness, t);
  s.snow_cover = current(kSnow, t);
  s.sun_altitude_deg = current(kAltitude, t);
  s.sun_azimuth_deg = std::fmod(current(kAzimuth, t) + 720.0, 360.0);
  s.daylight = smoothstep(-6.0, 6.0, s.sun_altitude_deg);
  s.night = s.sun_altitude_deg < 0;
  const double base = current(kWindSpeed, t);
  s.wind_speed_mps = std::max(0.0, base * (1.0 + gusts_ * gust_));
  s.wind_direction_deg = std::fmod(current(kWindDirection, t) + 720.0, 360.0);
  const double dir = s.wind_direction_deg * std::numbers::pi / 180.0;
  s.wind_x = s.wind_speed_mps * std::cos(dir);
  s.wind_y = s.wind_speed_mps * std::sin(dir);
  // The surface named: the last change's target once it is half done; the precipitation
  // type: the last change's. A control overrides the Schedule's later changes of the same.
  double surface_ctl = INFINITY, type_ctl = INFINITY;  // time of the first control naming it
  for (const Change& c : controls_) {
    if (c.time > t) break;
    if (!c.surface.empty()) surface_ctl = std::min(surface_ctl, c.time);
    if (!c.precipitation_type.empty()) type_ctl = std::min(type_ctl, c.time);
  }
  s.surface = initial_surface_;
  s.precipitation_type = initial_type_;
  auto apply = [&](const Change& c, bool surface_ok, bool type_ok) {
    if (type_ok && !c.precipitation_type.empty()) s.precipitation_type = c.precipitation_type;
    if (surface_ok && !c.surface.empty()) {
      const double f = c.transition > 0 ? (t - c.time) / c.transition : 1.0;
      if (f >= 0.5) s.surface = c.surface;
    }
  };
  for (const Change& c : changes_) {
    if (c.time > t) break;
    apply(c, c.time < surface_ctl, c.time < type_ctl);
  }
  for (const Change& c : controls_) {
    if (c.time > t) break;
    apply(c, true, true);
  }
  return s;
}

}  // namespace convoy::weather
