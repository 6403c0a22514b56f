// What a radar at a pose sees of the scene's objects (radar_targets.h): the targets in its
// field of view with some part visible by rays (radar_occlusion.h), in its frame, with their
// velocities relative to it. The world engine's radar system and the benchmark share it;
// radar_detect.h then turns the targets into returns.
#pragma once

#include <Eigen/Geometry>
#include <functional>
#include <string>
#include <vector>

#include "lidar/lidar_scene.h"
#include "radar/radar_detect.h"
#include "radar/radar_targets.h"

namespace convoy::radar {

// `sensor_velocity`: the sensor's world velocity; `own_model`: its model's id (left out, its
// surfaces passed through); `class_of`: a model id's class name.
std::vector<Target> visible_targets(const RadarParams& p, const lidar::LidarScene& rays,
                                    const std::vector<SceneObject>& objects,
                                    const Eigen::Isometry3d& world_from_sensor,
                                    const Eigen::Vector3d& sensor_velocity, uint32_t own_model,
                                    const std::function<std::string(uint32_t)>& class_of);

}  // namespace convoy::radar
