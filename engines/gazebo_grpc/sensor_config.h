// Sensors mounted by the engine config's "Sensors" list (src/config/sensor_keys.h: the keys,
// presets and the checks the coordinator makes before the run starts). Each entry becomes
// SDF's <sensor> element (sensor_sdf_text), read by the same code as a sensor written in the
// model's SDF (lidar_desc.h, nav_desc.h), and is added to its link's description after the
// world is loaded (and cached): the systems (lidar_sensors, nav_sensors) do the rest.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "config/sensor_keys.h"
#include "world_description.h"

namespace convoy::world {

// The <sensor name=... type=...>...</sensor> text of `entry`.
std::string sensor_sdf_text(const config::SensorEntry& entry);

// Adds the config's sensors to `desc`. Throws std::runtime_error "Sensors/i: model 'M' link
// 'L' sensor 'S': <problem>" for a bad entry, a model or a link not in `desc` (a second line
// behind the coordinator's check), or the SDF's own complaint. `step_s`: 1 / the step rate.
void mount_config_sensors(const nlohmann::json& config, double step_s, WorldDesc* desc);

}  // namespace convoy::world
