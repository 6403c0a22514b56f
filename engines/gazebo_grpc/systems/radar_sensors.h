// Radar datapacks: the world's radars (<sensor type="custom"> with a convoy_radar plugin,
// radar_desc.h, or a config "Sensors" entry of Type radar), object-level returns from
// src/radar against the scene the cameras render, occlusion by rays into an Embree scene of
// it (src/lidar's LidarScene).
//
// Config keys: GazeboRNGSeed (radar k of the world, in SDF order, draws from streams of
// (GazeboRNGSeed, k)), EngineTimestep (s; an <update_rate> above 1 / EngineTimestep is
// refused: "model 'M' link 'L' sensor 'S': <update_rate>: ...").
// Datapacks (NRP-Core's scoped name, and the plugin's name if it has one):
//   <model>::<link>::<sensor>, <plugin>::<sensor>   RadarDataPack (convoy.data.Radar)
// The objects are the scene's labelled models (every model but the ground and the radar's
// own; actors too), each with its box and velocity (radar/radar_targets.h: tracked after
// every engine step from the start, so the first scan has velocities). A radar scans once its
// datapack has been asked for (the first request scans at once), then after every engine step
// at which it is due (update_rate in simulated time; 0: every step), at its link's pose times
// its own. Its own velocity is its link's (physics) at the sensor's offset. Each return
// carries its object's ground truth (model id, name, class). A datapack is unchanged() until
// its radar scans again.
#pragma once

#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "lidar/lidar_scene.h"
#include "radar/radar_detect.h"
#include "radar/radar_targets.h"
#include "scan_book.h"
#include "world_description.h"
#include "world_system.h"

namespace convoy::world {

class RadarSensors final : public WorldSystem {
 public:
  RadarSensors();
  ~RadarSensors() override;
  const char* name() const override { return "radars"; }
  void configure(const WorldContext& ctx, const nlohmann::json& config) override;
  std::vector<ProvidedDataPack> provides() const override { return provided_; }
  void get_datapack(const std::string& name, datapack::Builder& out) override;
  bool unchanged(const std::string& name) override;
  void after_step() override;
  void reset() override;

  size_t count() const { return sensors_.size(); }
  // Radar i's latest returns (empty before its first scan) and how many scans it made.
  const std::vector<radar::Detection>& detections(size_t i) const { return sensors_[i].detections; }
  uint64_t scans(size_t i) const { return sensors_[i].scans; }

 private:
  struct Sensor {
    const RadarDesc* desc = nullptr;
    int link = -1;  // physics link index (-1: not simulated, at link_pose, at rest)
    Eigen::Isometry3d link_pose = Eigen::Isometry3d::Identity();
    uint32_t own_model = 0;
    uint64_t seed = 0;
    std::vector<radar::Detection> detections;
    double time = 0, next_update = 0;
    bool wanted = false;
    uint64_t scans = 0;
  };
  void track();
  void scan(Sensor& s);
  void fill(const Sensor& s, datapack::Builder& out) const;

  const WorldContext* ctx_ = nullptr;
  std::unique_ptr<lidar::LidarScene> scene_;  // made at the first scan (again after a reset)
  radar::ObjectTracker objects_;
  std::vector<Sensor> sensors_;
  ScanBook<Sensor> book_{sensors_};  // datapack names, when each scans, what was sent
  std::vector<ProvidedDataPack> provided_;
};

}  // namespace convoy::world
