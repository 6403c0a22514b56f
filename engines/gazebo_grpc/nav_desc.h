// A link's IMU or GNSS sensor from libsdformat's DOM (for world_description.cpp): SDF's <imu>
// and <navsat> with their <noise> as src/nav_sensors models them, the pose in the link's
// frame, the names; and the world's <spherical_coordinates>.
#pragma once

#include <filesystem>
#include <sdf/Sensor.hh>
#include <sdf/World.hh>
#include <string>

#include "world_description.h"

namespace convoy::world {

// True for <sensor type="imu"> and <sensor type="navsat"> (or "gps", its old name).
bool is_nav_sensor(const sdf::Sensor* sensor);

// The sensor of link `link` of model `model`. Throws std::runtime_error
// "<file>: model 'M' link 'L' sensor 'S': <field>: <problem>" for bad parameters.
NavSensorDesc nav_desc(const sdf::Sensor* sensor, const std::string& model, const std::string& link,
                       const std::filesystem::path& file);

// The world's <spherical_coordinates> (zeros when it has none). Throws std::runtime_error
// "<file>: world 'W': spherical_coordinates: <field>: <problem>".
nav_sensors::GeoOrigin geo_origin(const sdf::World* world, const std::filesystem::path& file);

}  // namespace convoy::world
