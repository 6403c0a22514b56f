// A link's camera from libsdformat's DOM (for world_description.cpp): <sensor type="camera">
// and <sensor type="segmentation_camera">, as lidar_desc.h and nav_desc.h read theirs.
#pragma once

#include <filesystem>
#include <sdf/Sensor.hh>
#include <string>

#include "world_description.h"

namespace convoy::world {

// True for <sensor type="camera"> and <sensor type="segmentation_camera">.
bool is_camera_sensor(const sdf::Sensor* sensor);

// The camera of link `link` of model `model` (scoped_name "<model>::<link>::<sensor>"). Throws
// std::runtime_error "<file>: model 'M' link 'L' sensor 'S': <field>: <problem>".
CameraDesc camera_desc(const sdf::Sensor* sensor, const std::string& model, const std::string& link,
                       const std::filesystem::path& file);

}  // namespace convoy::world
