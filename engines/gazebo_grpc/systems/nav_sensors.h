// IMU and GNSS datapacks: the world's <sensor type="imu">s and <sensor type="navsat">s
// (nav_desc.h), read through src/nav_sensors from the motion of the link carrying them.
//
// Config keys: GazeboRNGSeed (sensor k of the world, in SDF order, draws its noise from
// streams of (GazeboRNGSeed, k)), EngineTimestep (s; an <update_rate> above 1 / EngineTimestep
// is refused: "model 'M' link 'L' sensor 'S': <update_rate>: ...").
// Datapacks (NRP-Core's scoped name, and the plugin's name if it has one):
//   <model>::<link>::<sensor>, <plugin>::<sensor>   ImuDataPack (convoy.data.Imu) or
//                                                    NavSatDataPack (convoy.data.NavSat)
// Every physics step the sensor frame's velocity is differenced into its acceleration (the
// link's velocity at the sensor's offset); after every engine step at which a sensor is due
// (its update_rate in simulated time; 0: every step) it reads. The GNSS converts positions on
// the world's <spherical_coordinates> (WGS84). A datapack is unchanged() until its sensor
// reads again. Readings start at the first step, whether or not asked for: the noise's
// state depends on the time only, so asking changes nothing.
#pragma once

#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "nav_sensors/imu_model.h"
#include "nav_sensors/navsat_model.h"
#include "world_description.h"
#include "world_system.h"

namespace convoy::world {

class NavSensors final : public WorldSystem {
 public:
  const char* name() const override { return "nav_sensors"; }
  void configure(const WorldContext& ctx, const nlohmann::json& config) override;
  std::vector<ProvidedDataPack> provides() const override { return provided_; }
  void get_datapack(const std::string& name, datapack::Builder& out) override;
  bool unchanged(const std::string& name) override;
  void post_update(double dt) override;
  void after_step() override;
  void reset() override;

  size_t count() const { return sensors_.size(); }
  uint64_t readings(size_t i) const { return sensors_[i].readings; }

 private:
  struct Sensor {
    const NavSensorDesc* desc = nullptr;
    int link = -1;  // physics link index (-1: not simulated, at link_pose, at rest)
    Eigen::Isometry3d link_pose = Eigen::Isometry3d::Identity();
    std::optional<nav_sensors::ImuModel> imu;
    std::optional<nav_sensors::NavSatModel> navsat;
    nav_sensors::VelocityDifferentiator accel;
    nav_sensors::ImuSample motion;  // of the last physics step
    Eigen::Vector3d position = Eigen::Vector3d::Zero(), velocity = Eigen::Vector3d::Zero();
    nav_sensors::ImuReading imu_reading;
    nav_sensors::NavSatReading navsat_reading;
    double next_update = 0, last_read = 0;
    uint64_t readings = 0;
  };
  void sample(Sensor& s, double dt);
  void read(Sensor& s);
  void fill(const Sensor& s, datapack::Builder& out) const;

  const WorldContext* ctx_ = nullptr;
  std::vector<Sensor> sensors_;
  std::unordered_map<std::string, size_t> by_datapack_;
  std::vector<ProvidedDataPack> provided_;
  std::unordered_map<std::string, uint64_t> sent_;  // datapack -> the reading sent
};

}  // namespace convoy::world
