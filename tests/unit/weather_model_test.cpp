// The weather engine's model: initial state, the schedule's transitions, surfaces and their
// friction, the sun from the time of day, gusts from the seed, and bad input named by key.
#include "weather_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace convoy::weather {
namespace {

using nlohmann::json;

TEST(WeatherModel, DefaultsAreClearAndDry) {
  WeatherModel m(json::object());
  const auto& s = m.state();
  EXPECT_EQ(s.surface, "dry");
  EXPECT_DOUBLE_EQ(s.mu, 0.8);
  EXPECT_DOUBLE_EQ(s.precipitation, 0.0);
  EXPECT_NEAR(s.visibility_m, kClearVisibility, 1e-6);
  EXPECT_FALSE(s.night);
  EXPECT_DOUBLE_EQ(s.daylight, 1.0);
  EXPECT_EQ(s.to_json()["precipitation_type"], "none");
}

TEST(WeatherModel, SurfacesGiveTheirFriction) {
  for (const auto& [name, mu] :
       {std::pair{"dry", 0.8}, {"wet", 0.5}, {"snow", 0.25}, {"ice", 0.1}}) {
    WeatherModel m(json{{"Surface", name}});
    EXPECT_EQ(m.state().surface, name);
    EXPECT_DOUBLE_EQ(m.state().mu, mu) << name;
  }
}

TEST(WeatherModel, ScheduleRainFromThirtySecondsThenDrying) {
  // Rain from t = 30 s (the road wet at once), stopping at 60 s; the road dries over 100 s.
  WeatherModel m(json::parse(R"({"Schedule": [
      {"Time": 30, "Precipitation": 0.8, "Surface": "wet"},
      {"Time": 60, "Precipitation": 0},
      {"Time": 60, "Surface": "dry", "Transition": 100}]})"));
  EXPECT_EQ(m.advance(29.9).surface, "dry");
  EXPECT_DOUBLE_EQ(m.state().precipitation, 0.0);
  const auto& rain = m.advance(30.0);
  EXPECT_EQ(rain.surface, "wet");
  EXPECT_DOUBLE_EQ(rain.mu, 0.5);
  EXPECT_DOUBLE_EQ(rain.precipitation, 0.8);
  EXPECT_EQ(rain.to_json()["precipitation_type"], "rain");
  const auto& drying = m.advance(85.0);  // a quarter of the way back to dry
  EXPECT_DOUBLE_EQ(drying.precipitation, 0.0);
  EXPECT_NEAR(drying.mu, 0.5 + 0.25 * 0.3, 1e-9);
  EXPECT_NEAR(drying.wetness, 0.75, 1e-9);
  EXPECT_EQ(drying.surface, "wet");  // named dry from half way
  EXPECT_EQ(m.advance(111.0).surface, "dry");
  EXPECT_DOUBLE_EQ(m.advance(200.0).mu, 0.8);
}

TEST(WeatherModel, FogThickensInLogSpace) {
  WeatherModel m(json::parse(R"({"Visibility": 10000,
      "Schedule": [{"Time": 10, "Visibility": 100, "Transition": 20}]})"));
  EXPECT_NEAR(m.advance(10).visibility_m, 10000, 1e-6);
  EXPECT_NEAR(m.advance(20).visibility_m, 1000, 1e-6);  // half way: the geometric mean
  EXPECT_NEAR(m.advance(40).visibility_m, 100, 1e-9);
  EXPECT_TRUE(m.state().to_json()["fog"].get<bool>());
}

TEST(WeatherModel, ChangesStartFromTheCurrentValue) {
  // The second change starts half way through the first.
  WeatherModel m(json::parse(R"({"Schedule": [
      {"Time": 0, "Precipitation": 1.0, "Transition": 10},
      {"Time": 5, "Precipitation": 0.0, "Transition": 5}]})"));
  EXPECT_NEAR(m.advance(5).precipitation, 0.5, 1e-12);
  EXPECT_NEAR(m.advance(7.5).precipitation, 0.25, 1e-12);
  EXPECT_NEAR(m.advance(10).precipitation, 0.0, 1e-12);
}

TEST(WeatherModel, SunFromTimeOfDayAndNight) {
  auto [noon_alt, noon_az] = WeatherModel::sun_at(12);
  EXPECT_NEAR(noon_alt, 60, 1e-9);
  EXPECT_NEAR(noon_az, 180, 1e-9);
  EXPECT_NEAR(WeatherModel::sun_at(6).first, 0, 1e-9);
  EXPECT_NEAR(WeatherModel::sun_at(6).second, 90, 1e-9);
  EXPECT_NEAR(WeatherModel::sun_at(18).second, 270, 1e-9);
  WeatherModel night(json{{"TimeOfDay", 23}});
  EXPECT_TRUE(night.state().night);
  EXPECT_DOUBLE_EQ(night.state().daylight, 0.0);
  WeatherModel dusk(json::parse(
      R"({"TimeOfDay": 17, "Schedule": [{"Time": 0, "TimeOfDay": 19, "Transition": 100}]})"));
  EXPECT_FALSE(dusk.advance(0).night);
  EXPECT_TRUE(dusk.advance(100).night);
  EXPECT_GT(dusk.advance(40).daylight, 0.0);
}

TEST(WeatherModel, AzimuthTurnsTheShortWay) {
  WeatherModel m(json::parse(R"({"WindDirection": 350, "WindSpeed": 5, "Gusts": 0,
      "Schedule": [{"Time": 0, "WindDirection": 10, "Transition": 10}]})"));
  EXPECT_NEAR(m.advance(5).wind_direction_deg, 0.0, 1e-9);
  EXPECT_NEAR(m.state().wind_x, 5.0, 1e-9);
  EXPECT_NEAR(m.state().wind_y, 0.0, 1e-9);
}

TEST(WeatherModel, GustsFollowTheSeed) {
  auto run = [](uint64_t seed) {
    WeatherModel m(json{{"WindSpeed", 10.0}, {"Gusts", 0.3}, {"Seed", seed}});
    std::vector<double> v;
    for (int k = 1; k <= 200; ++k) v.push_back(m.advance(k * 0.05).wind_speed_mps);
    return v;
  };
  const auto a = run(3), b = run(3), c = run(4);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
  double lo = 1e9, hi = 0;
  for (double x : a) lo = std::min(lo, x), hi = std::max(hi, x);
  EXPECT_LT(lo, 10.0);
  EXPECT_GT(hi, 10.0);
  // reset() replays the same gusts
  WeatherModel m(json{{"WindSpeed", 10.0}, {"Seed", 3}});
  std::vector<double> first, again;
  for (int k = 1; k <= 50; ++k) first.push_back(m.advance(k * 0.05).wind_speed_mps);
  m.reset();
  for (int k = 1; k <= 50; ++k) again.push_back(m.advance(k * 0.05).wind_speed_mps);
  EXPECT_EQ(first, again);
}

std::string error_of(const std::string& config) {
  try {
    WeatherModel m(json::parse(config));
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(WeatherModel, BadInputNamesTheKey) {
  EXPECT_EQ(error_of(R"({"Surface": "mud"})").rfind("Surface: unknown surface \"mud\"", 0), 0u)
      << error_of(R"({"Surface": "mud"})");
  EXPECT_EQ(error_of(R"({"Visibility": -5})").rfind("Visibility: must be > 0", 0), 0u);
  const std::string order = error_of(
      R"({"Schedule": [{"Time": 30, "Precipitation": 1}, {"Time": 20, "Precipitation": 0}]})");
  EXPECT_EQ(order.rfind("Schedule[1].Time: the schedule is out of order", 0), 0u) << order;
  EXPECT_EQ(error_of(R"({"Schedule": [{"Time": 1, "Surface": "gravel"}]})")
                .rfind("Schedule[0].Surface: unknown surface", 0),
            0u);
  EXPECT_EQ(error_of(R"({"Schedule": [{"Time": 1, "Visibility": 0}]})")
                .rfind("Schedule[0].Visibility: must be > 0", 0),
            0u);
  EXPECT_EQ(error_of(R"({"Schedule": [{"Time": 1, "Rain": 1}]})")
                .rfind("Schedule[0].Rain: unknown key", 0),
            0u);
  EXPECT_EQ(error_of(R"({"Precipitation": 2})").rfind("Precipitation: must be in [0, 1]", 0), 0u);
  EXPECT_EQ(error_of(R"({"PrecipitationType": "hail"})").rfind("PrecipitationType: expected", 0),
            0u);
  EXPECT_EQ(error_of(R"({"Schedule": [{"Precipitation": 1}]})")
                .rfind("Schedule[0]: expected an object with Time", 0),
            0u);
  EXPECT_EQ(error_of(R"({"TimeOfDay": 25})").rfind("TimeOfDay: must be in [0, 24]", 0), 0u);
  EXPECT_EQ(error_of(R"({"WindSpeed": -1})").rfind("WindSpeed: must be >= 0", 0), 0u);
}

TEST(WeatherModel, ControlAtOnceAndOverTime) {
  WeatherModel m(json::parse(R"({"Gusts": 0})"));
  m.advance(1.0);
  // At once: from the step it arrives.
  EXPECT_TRUE(m.control(json::parse(R"({"Precipitation": 0.6, "Surface": "wet"})"), 1.0, "wc"));
  EXPECT_DOUBLE_EQ(m.advance(1.05).precipitation, 0.6);
  EXPECT_EQ(m.state().surface, "wet");
  EXPECT_DOUBLE_EQ(m.state().mu, 0.5);
  EXPECT_NEAR(m.state().visibility_m, 20000.0, 1e-6);  // not named: unchanged
  // Over 10 s, linearly (visibility in log space), from the value it has when it arrives.
  EXPECT_TRUE(m.control(json::parse(R"({"Precipitation": 0.0, "Visibility": 200,
                                        "WindDirection": 350, "TransitionTime": 10})"),
                        2.0, "wc"));
  EXPECT_NEAR(m.advance(7.0).precipitation, 0.3, 1e-12);
  EXPECT_NEAR(m.state().visibility_m, 2000.0, 1e-6);       // geometric mean of 20000 and 200
  EXPECT_NEAR(m.state().wind_direction_deg, 355.0, 1e-9);  // the short way round
  EXPECT_NEAR(m.advance(12.0).precipitation, 0.0, 1e-12);
  EXPECT_NEAR(m.state().visibility_m, 200.0, 1e-9);
  // The same control again is ignored (it does not restart the transition).
  EXPECT_FALSE(m.control(json::parse(R"({"Precipitation": 0.0, "Visibility": 200,
                                         "WindDirection": 350, "TransitionTime": 10})"),
                         12.0, "wc"));
}

TEST(WeatherModel, ControlOverridesTheSchedule) {
  WeatherModel m(json::parse(R"({"Schedule": [
      {"Time": 0, "Precipitation": 1.0, "Transition": 10},
      {"Time": 20, "Precipitation": 0.2, "Visibility": 500, "Surface": "snow"}]})"));
  m.advance(5.0);
  // Half way through the Schedule's rain, a control takes precipitation to 0 over 5 s.
  m.control(json::parse(R"({"Precipitation": 0.0, "TransitionTime": 5, "Surface": "ice"})"), 5.0,
            "wc");
  EXPECT_NEAR(m.advance(7.5).precipitation, 0.25, 1e-12);
  EXPECT_EQ(m.state().surface, "ice");  // half way
  EXPECT_NEAR(m.advance(15.0).precipitation, 0.0, 1e-12);
  // The Schedule's later change no longer moves the keys the control named ...
  EXPECT_NEAR(m.advance(25.0).precipitation, 0.0, 1e-12);
  EXPECT_EQ(m.state().surface, "ice");
  EXPECT_DOUBLE_EQ(m.state().mu, 0.1);
  // ... but still the others.
  EXPECT_NEAR(m.state().visibility_m, 500.0, 1e-9);
  // reset() forgets the controls.
  m.reset();
  EXPECT_NEAR(m.advance(25.0).precipitation, 0.2, 1e-12);
  EXPECT_EQ(m.state().surface, "snow");
}

std::string control_error(const char* keys) {
  WeatherModel m(json::object());
  try {
    m.control(json::parse(keys), 0.0, "weather_control");
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(WeatherModel, BadControlNamesTheKey) {
  EXPECT_EQ(control_error(R"({"Surface": "mud"})")
                .rfind("weather_control.Surface: unknown surface \"mud\"", 0),
            0u);
  EXPECT_EQ(
      control_error(R"({"Visibility": -5})").rfind("weather_control.Visibility: must be > 0", 0),
      0u);
  EXPECT_EQ(control_error(R"({"Rain": 1})").rfind("weather_control.Rain: unknown key", 0), 0u)
      << control_error(R"({"Rain": 1})");
  EXPECT_EQ(control_error(R"({"Time": 1})").rfind("weather_control.Time: unknown key", 0), 0u);
  EXPECT_EQ(control_error(R"({"TransitionTime": -1})")
                .rfind("weather_control.TransitionTime: must be >= 0", 0),
            0u);
  EXPECT_EQ(control_error(R"({"Precipitation": "heavy"})")
                .rfind("weather_control.Precipitation: expected a number", 0),
            0u);
  EXPECT_EQ(control_error(R"({"TimeOfDay": 12, "SunAltitude": 10})")
                .rfind("weather_control.TimeOfDay: give either", 0),
            0u);
  EXPECT_EQ(control_error(R"([1, 2])").rfind("weather_control: expected a JSON object", 0), 0u);
}

}  // namespace
}  // namespace convoy::weather
