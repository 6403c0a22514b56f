// LiDAR datapacks: the world's <sensor type="lidar|gpu_lidar|ray|gpu_ray">s (lidar_desc.h),
// scanned with src/lidar against the scene the cameras render (camera_sensors.h).
//
// Config keys: GazeboRNGSeed (sensor k of the world, in SDF order, draws its noise from seed
// GazeboRNGSeed + k), EngineTimestep (s; a sensor's <update_rate> above 1 / EngineTimestep is
// refused: "model 'M' link 'L' sensor 'S': <update_rate>: ...").
// Datapacks (as the camera's: NRP-Core's scoped name, and the plugin's name if it has one):
//   <model>::<link>::<sensor>, <plugin>::<sensor>   PointCloudDataPack (convoy.data.PointCloud)
// A sensor scans only once its datapack has been asked for (the first request scans at
// once); from then on after every engine step at which it is due (its update_rate in
// simulated time; 0: every step), at its link's pose times its own pose. Returns off the
// sensor's own model are left out (its body may still shadow what lies behind it). The
// weather is the one the cameras were given last (WeatherDataPack), clear air before.
// A datapack is unchanged() until its sensor scans again.
#pragma once

#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "lidar/lidar_scene.h"
#include "lidar/lidar_sensor.h"
#include "scan_book.h"
#include "world_description.h"
#include "world_system.h"

namespace convoy::world {

class LidarSensors final : public WorldSystem {
 public:
  LidarSensors();
  ~LidarSensors() override;
  const char* name() const override { return "lidars"; }
  void configure(const WorldContext& ctx, const nlohmann::json& config) override;
  std::vector<ProvidedDataPack> provides() const override { return provided_; }
  void get_datapack(const std::string& name, datapack::Builder& out) override;
  bool unchanged(const std::string& name) override;
  void after_step() override;
  void reset() override;

  size_t count() const { return sensors_.size(); }
  // Sensor i's latest cloud (empty before its first scan) and how many scans it made.
  const lidar::PointCloud& cloud(size_t i) const { return sensors_[i].cloud; }
  uint64_t scans(size_t i) const { return sensors_[i].scans; }

 private:
  struct Sensor {
    const LidarDesc* desc = nullptr;
    int link = -1;  // physics link index (-1: not simulated, at link_pose)
    Eigen::Isometry3d link_pose = Eigen::Isometry3d::Identity();  // as loaded
    uint32_t own_model = 0;  // the model carrying it: left out of its returns
    uint64_t seed = 0;
    std::unique_ptr<lidar::LidarSensor> sensor;
    lidar::PointCloud cloud;
    double next_update = 0;
    bool wanted = false;
    uint64_t scans = 0;
  };
  void scan(Sensor& s);
  void fill(const Sensor& s, datapack::Builder& out) const;

  const WorldContext* ctx_ = nullptr;
  std::unique_ptr<lidar::LidarScene> scene_;  // made at the first scan (again after a reset)
  std::vector<Sensor> sensors_;
  ScanBook<Sensor> book_{sensors_};  // datapack names, when each scans, what was sent
  std::vector<ProvidedDataPack> provided_;
};

}  // namespace convoy::world
