// Whether a radar sees an object, by rays into the LiDAR's Embree scene (lidar_scene.h: the
// scene the cameras render): five rays from the sensor to the object's box centre and to
// points 0.35 of its width and height off the centre across the line of sight. A ray sees
// the object when the first surface it meets is one of the object's (surfaces of the
// sensor's own model are passed through); the fraction of rays that do is the visible
// fraction, and the nearest such hit the range to the object.
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "lidar/lidar_scene.h"
#include "radar/radar_targets.h"

namespace convoy::radar {

struct Visibility {
  double fraction = 0;  // 0..1
  double range = -1;    // m to the nearest visible part (< 0: none seen)
};

constexpr int kVisibilityRays = 5;

// `origin`: the sensor in the world; `own_model`: its model's id (0: none).
Visibility visibility(const lidar::LidarScene& scene, const Eigen::Vector3d& origin,
                      const SceneObject& object, uint32_t own_model);

}  // namespace convoy::radar
