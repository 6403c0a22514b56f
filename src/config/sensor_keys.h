// The world engine's "Sensors" key (issue 27): sensors mounted on a model's link by the
// config instead of the model's SDF. Each entry
//   {"Type": "gpu_lidar", "Name": "lidar", "Model": "smart_car", "Link": "base_link",
//    "Pose": [x, y, z, roll, pitch, yaw], "UpdateRate": 10, "Preset": "vlp16",
//    "HorizontalSamples": 1024, ...}
// Types: lidar, gpu_lidar, ray, gpu_ray (a LiDAR), imu, navsat (gps), radar, wheel_odometry
// (docs/radar.md: their keys below, as SensorEntry names them). A LiDAR takes a Preset
// (vlp16, hdl32, hdl64) and overrides; "SDF" is raw XML put inside the <sensor> element (noise
// models of an IMU or a GNSS). The engine (engines/gazebo_grpc/sensor_config.h) turns each
// entry into SDF's <sensor> element; the coordinator checks the entries before the run starts
// (read_sensor_keys), so bad input exits 2.
#pragma once

#include <array>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

namespace convoy::config {

struct SensorEntry {
  std::string type, name, model, link;
  std::array<double, 6> pose{};  // x y z roll pitch yaw, in the link's frame
  double update_rate = 0;        // Hz; 0: every step
  // LiDAR (after the preset and overrides); angles in radians, ranges in metres
  int h_samples = 0, v_samples = 0;
  double h_min = 0, h_max = 0, v_min = 0, v_max = 0;
  double range_min = 0, range_max = 0, range_resolution = 0.01, noise_stddev = 0;
  // radar ("HorizontalFov", "VerticalFov", "RangeMin", "RangeMax", "RangeStddev",
  // "AzimuthStddev", "ElevationStddev", "RangeRateStddev", "RcsStddev", "DetectionRange",
  // "Clutter"; UpdateRate 20 Hz by default)
  double h_fov = 1.2, v_fov = 0.2, range_stddev = 0.1, azimuth_stddev = 0.005,
         elevation_stddev = 0.01, range_rate_stddev = 0.1, rcs_stddev = 1, detection_range = 0,
         clutter = 2;
  // wheel_odometry ("LeftJoint", "RightJoint", "SteeringJoint", "WheelRadius", "Track",
  // "Wheelbase", "ScaleStddev", "SlipStddev"; UpdateRate 50 Hz by default)
  std::string left_joint = "rear_left_wheel_joint", right_joint = "rear_right_wheel_joint",
              steering_joint;
  double wheel_radius = 0.3, track = 1.6, wheelbase = 0, scale_stddev = 0, slip_stddev = 0;
  std::string sdf;  // extra XML inside <sensor>
  bool is_lidar() const;
};

using Problems = std::vector<std::pair<std::string, std::string>>;  // (pointer, message)

// The entries of engine config `engine` ("Sensors", absent: none), checked without the world:
// the type, the names, samples >= 1, ranges >= 0 and min < max, angles in order, the rate
// not above 1 / `step_s` (0: unchecked). A problem is "<pointer>/Sensors/i/<Key>", "model 'M'
// link 'L' sensor 'S': <problem>". Entries with problems are left out.
std::vector<SensorEntry> read_sensor_entries(const nlohmann::json& engine, double step_s,
                                             const std::string& pointer, Problems* problems);

// The above, plus each entry's model and link (and an odometer's joints) looked up in the engine's
// SDF without parsing it fully: GazeboSDFModels' files, the world file's models and the models its
// <include>s find next to it (models/NAME/model.sdf). A model found nowhere, or a link its file
// lacks, is a problem; a model whose file cannot be found is left to the engine. For the
// coordinator.
void read_sensor_keys(const nlohmann::json& engine, double step_s, const std::string& pointer,
                      Problems* problems);

struct EngineConfig;  // simulation_config.h
// read_sensor_keys for each gazebo_grpc engine of a config (its EngineTimestep the step).
void read_engine_sensor_keys(const std::vector<EngineConfig>& engines, Problems* problems);

}  // namespace convoy::config
