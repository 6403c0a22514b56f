// Weather input: the weather engine's JSON datapack (weather_effects.h, docs/weather.md),
// applied to the cameras (fog, rain, snow, night), the wheels' tyre friction and the wind.
//
// Config key: WeatherDataPack, the datapack's name (default "weather").
// Datapacks: <WeatherDataPack>, JSON, written. An empty one is ignored; one that is not JSON
// or has a wrong key is an error naming the engine, the datapack and the key. A reset keeps
// the last weather.
#pragma once

#include <optional>
#include <string>

#include "weather_effects.h"
#include "world_system.h"

namespace convoy::world {

class WeatherInput final : public WorldSystem {
 public:
  const char* name() const override { return "weather"; }
  void configure(const WorldContext& ctx, const nlohmann::json& config) override;
  bool set_datapack(const datapack::View& dp) override;
  void reset() override;

  const std::string& datapack_name() const { return datapack_; }
  // The weather applied (none before the first datapack).
  const std::optional<Weather>& weather() const { return weather_; }

 private:
  void apply() const;

  const WorldContext* ctx_ = nullptr;
  std::string datapack_ = "weather";
  std::optional<Weather> weather_;
};

}  // namespace convoy::world
