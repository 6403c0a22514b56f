// A LiDAR sensor: casts one revolution of rays (lidar_model.h's layout) into a LidarScene and
// returns the labelled point cloud (point_cloud.h).
//
//   LidarSensor sensor(parse_lidar(sensor_element));
//   LidarScene world(render_scene);                 // once
//   ...  world.update(render_scene);                // each step the sensor is due
//   PointCloud cloud;
//   sensor.scan(world, world_from_sensor, t, seed, LidarWeather::from(atmosphere), &cloud);
//
// The whole revolution is cast at one instant (no motion distortion). A ray returns the
// nearest visible surface between range_min and range_max: its point in the sensor frame at
// the measured range (plus gaussian noise when the model has it), intensity = the surface's
// reflectivity x |cos(incidence)| (then the weather, lidar_weather.h), and the instance's
// ground-truth labels. Rays go to Embree 16 at a time (neighbouring columns of one ring) on
// two threads (the caller's and one kept worker). All randomness comes from a hash of
// (seed, time, ray index): the same inputs give the same cloud bit for bit, however the rays
// were shared between the threads.
#pragma once

#include <cstdint>
#include <vector>

#include "core/two_way.h"
#include "lidar/lidar_model.h"
#include "lidar/lidar_scene.h"
#include "lidar/lidar_weather.h"
#include "lidar/point_cloud.h"
#include "render/pose.h"

namespace convoy::lidar {

class LidarSensor {
 public:
  // Validates the model (throws std::invalid_argument naming the field).
  explicit LidarSensor(const LidarModel& model);

  const LidarModel& model() const { return model_; }
  // Unit direction of ray (ring, column) in the sensor frame.
  std::array<float, 3> direction(int ring, int column) const;

  // One revolution from `world_from_sensor` (rigid) at simulated time `time` (s).
  void scan(const LidarScene& scene, const render::Pose& world_from_sensor, double time,
            uint64_t seed, const LidarWeather& weather, PointCloud* out);

 private:
  struct RayResult {
    float range;  // < 0: no return
    float intensity;
    int instance;  // render::Scene instance, -1: none (or a weather return)
    uint32_t flags;
  };
  void cast_block(const LidarScene& scene, const render::Pose& pose, size_t first, size_t count,
                  uint64_t key, const LidarWeather& weather);

  LidarModel model_;
  std::vector<float> dirs_;  // x y z per ray, ring-major
  std::vector<RayResult> results_;
  TwoWay split_{1};
};

}  // namespace convoy::lidar
