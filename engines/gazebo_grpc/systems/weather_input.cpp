#include "systems/weather_input.h"

#include <stdexcept>

#include "camera_sensors.h"
#include "datapack/json.h"
#include "physics_world.h"

namespace convoy::world {

void WeatherInput::configure(const WorldContext& ctx, const nlohmann::json& config) {
  ctx_ = &ctx;
  datapack_ = config.value("WeatherDataPack", std::string("weather"));
}

bool WeatherInput::set_datapack(const datapack::View& dp) {
  if (dp.id().name() != datapack_) return false;
  if (dp.empty()) return true;
  const std::string where = ctx_->where(dp.id().name());
  if (!dp.is_json()) throw std::runtime_error(where + "expected the weather engine's JSON");
  try {
    weather_ = weather_from_json(datapack::read_json(dp));
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(where + e.what());
  }
  apply();
  return true;
}

void WeatherInput::reset() {
  if (weather_) apply();
}

void WeatherInput::apply() const {
  const Weather& w = *weather_;
  ctx_->physics->set_wheel_friction(w.mu);
  ctx_->physics->set_wind(Eigen::Vector3d(w.wind_x, w.wind_y, 0.0));
  ctx_->cameras->set_weather(w);
}

}  // namespace convoy::world
