// A link's LiDAR sensor from libsdformat's DOM (for world_description.cpp): the SDF
// parameters through lidar::parse_lidar, the pose in the link's frame, the names.
#pragma once

#include <filesystem>
#include <sdf/Sensor.hh>
#include <string>

#include "world_description.h"

namespace convoy::world {

// True for <sensor type="lidar|gpu_lidar|ray|gpu_ray">.
bool is_lidar_sensor(const sdf::Sensor* sensor);

// The sensor of link `link` of model `model`. Throws std::runtime_error
// "<file>: model 'M' link 'L' sensor 'S': <field>: <problem>" for bad parameters.
LidarDesc lidar_desc(const sdf::Sensor* sensor, const std::string& model, const std::string& link,
                     const std::filesystem::path& file);

}  // namespace convoy::world
