// EngineType "weather": the weather as a participant (docs/weather.md).
//
// Each step it publishes the weather at the engine's simulated time as a JSON datapack (the
// state of weather_model.h): precipitation (rain or snow), fog as visibility in metres, the
// road surface and its friction mu, the sun, and the wind with gusts drawn from Seed. A
// Schedule in the config changes it over simulated time. The world engine applies it to
// its cameras and wheels; road-user engines adapt to it; a TF passes it on.
//
// Datapacks written:
//   <DataPack> ("weather")  JSON: time_s, precipitation, precipitation_type ("rain", "snow",
//       "none"), visibility_m, fog, surface, mu, wetness, snow_cover, sun_altitude_deg,
//       sun_azimuth_deg, daylight, night, wind_speed_mps, wind_direction_deg, wind [x, y],
//       seed.
// Datapacks read:
//   <ControlDataPack> ("weather_control")  optional JSON: any of the state keys (Precipitation,
//       PrecipitationType, Visibility, Surface, SunAltitude, SunAzimuth, TimeOfDay, WindSpeed,
//       WindDirection) and TransitionTime (s, default 0). From the step it arrives the keys
//       move linearly to the new values over TransitionTime; from then on they no longer
//       follow the Schedule (WeatherModel::control). The scenario engine's EnvironmentAction.
#include <cstdio>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "datapack/json.h"
#include "engine/engine.h"
#include "weather_model.h"

namespace convoy::engines::weather {
namespace {

using nlohmann::json;

class WeatherEngine final : public Engine {
 public:
  std::vector<engine::DataPackId> initialize(const std::string& name, const json& config,
                                             int64_t) override {
    name_ = name;
    dp_name_ = config.value("DataPack", std::string("weather"));
    control_name_ = config.value("ControlDataPack", std::string("weather_control"));
    try {
      model_ = std::make_unique<convoy::weather::WeatherModel>(config);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error("weather engine '" + name + "': " + e.what());
    }
    const auto& s = model_->state();
    std::fprintf(stderr,
                 "weather engine '%s': %s, precipitation %.2f (%s), visibility %.0f m, sun %.1f "
                 "deg, wind %.1f m/s\n",
                 name.c_str(), s.surface.c_str(), s.precipitation, s.precipitation_type.c_str(),
                 s.visibility_m, s.sun_altitude_deg, s.wind_speed_mps);
    engine::DataPackId id;
    id.set_name(dp_name_);
    id.set_engine_name(name);
    id.set_type(std::string(datapack::kJsonType));
    return {id};
  }

  int64_t step(int64_t duration_ns) override {
    time_ns_ += duration_ns;
    model_->advance(static_cast<double>(time_ns_) * 1e-9);
    return time_ns_;
  }

  void set_datapack(const datapack::View& dp) override {
    if (dp.empty()) return;
    const std::string& name = dp.id().name();
    if (name != control_name_) {
      throw std::runtime_error("weather engine '" + name_ + "' reads only '" + control_name_ +
                               "' (got '" + name + "'); its Schedule changes the weather");
    }
    if (!dp.is_json()) {
      throw std::runtime_error("weather engine '" + name_ + "': " + name +
                               ": expected a JSON datapack of weather keys");
    }
    try {
      const nlohmann::json keys = datapack::read_json(dp);
      if (model_->control(keys, static_cast<double>(time_ns_) * 1e-9, name)) {
        std::fprintf(stderr, "weather engine '%s': t=%.3f s: %s\n", name_.c_str(),
                     static_cast<double>(time_ns_) * 1e-9, keys.dump().c_str());
      }
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error("weather engine '" + name_ + "': " + e.what());
    }
  }

  void get_datapack(const engine::DataPackId&, datapack::Builder& out) override {
    datapack::write_json(out, model_->state().to_json());
  }

  void reset() override {
    time_ns_ = 0;
    model_->reset();
  }

 private:
  std::string name_, dp_name_, control_name_;
  std::unique_ptr<convoy::weather::WeatherModel> model_;
  int64_t time_ns_ = 0;
};

}  // namespace

CONVOY_REGISTER_ENGINE("weather", WeatherEngine);

}  // namespace convoy::engines::weather
