// The ros_bridge engine's config (schema.json), parsed once into a typed struct. Like every
// header of the bridge that the engine's C++20 translation unit includes, it includes no ROS
// message header (those do not compile as C++20: they use std::allocator<void>::rebind).
#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace convoy::ros_bridge {

// The frames of the messages the bridge publishes.
struct Frames {
  std::string map = "map", base = "base_link", camera = "camera";
};

// The message types the bridge subscribes to.
enum class InType { kControl, kTwist, kTwistStamped };

// Frame ids of sensor messages by the sensor's datapack frame (<model>::<link>::<sensor>);
// a sensor not listed keeps that name.
using SensorFrames = std::map<std::string, std::string>;

struct Subscription {
  std::string topic;
  InType type = InType::kControl;
};

struct BridgeConfig {
  std::string node_name = "convoy";
  std::string master_uri;  // "" : $ROS_MASTER_URI, else the default
  bool start_master = true;
  bool synchronous = true;
  std::string sync_topic = "/convoy/control";
  double sync_timeout_s = 10;
  std::vector<Subscription> subscribe;
  bool publish_clock = true;
  Frames frames;
  double camera_hfov = 1.57;
  SensorFrames sensor_frames;  // SensorFrames
};

// "convoy_msgs/Control", "geometry_msgs/Twist", "geometry_msgs/TwistStamped".
std::string type_name(InType type);

// Reads the engine's config (defaults filled in by the schema). Throws std::invalid_argument
// naming the key: an unsupported Type, a topic twice, SyncTopic not among the Subscribe
// topics when Synchronous, SyncTimeout <= 0, an invalid ROS name.
BridgeConfig parse_config(const nlohmann::json& config);

// "" when `name` is a valid ROS graph resource name (absolute, relative or private), else why not.
std::string name_problem(const std::string& name);

}  // namespace convoy::ros_bridge
