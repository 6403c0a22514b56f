// Convoy's custom sensors from libsdformat's DOM (for world_description.cpp and
// sensor_config.cpp): sdformat 12 knows no radar or odometer, but keeps a <sensor
// type="custom"> and its <plugin>'s children as written, so
//   <sensor name="radar" type="custom"><plugin filename="convoy_radar" name="P">...</plugin>
//   <sensor name="odom" type="custom"><plugin filename="convoy_wheel_odometry" name="P">
//     <left_joint>rear_left_wheel_joint</left_joint> <right_joint>...</right_joint>
//     <steering_joint>front_left_steering_joint</steering_joint>            (optional)
//     <wheel_radius>0.3</wheel_radius> <track>1.6</track> <wheelbase>0</wheelbase>
//     <scale_stddev>0</scale_stddev> <slip_stddev>0</slip_stddev></plugin></sensor>
// (radar parameters: src/radar/radar_model.h; the defaults above are the smart car's).
#pragma once

#include <filesystem>
#include <sdf/Sensor.hh>
#include <string>

#include "world_description.h"

namespace convoy::world {

bool is_radar_sensor(const sdf::Sensor* sensor);
bool is_odometry_sensor(const sdf::Sensor* sensor);

// Throw std::runtime_error "<file>: model 'M' link 'L' sensor 'S': <element>: <problem>".
RadarDesc radar_desc(const sdf::Sensor* sensor, const std::string& model, const std::string& link,
                     const std::filesystem::path& file);
OdometryDesc odometry_desc(const sdf::Sensor* sensor, const std::string& model,
                           const std::string& link, const std::filesystem::path& file);

}  // namespace convoy::world
