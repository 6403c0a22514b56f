// The ros_bridge engine's config (bridge_config.h).
#include "bridge_config.h"

#include <cctype>
#include <stdexcept>

namespace convoy::ros_bridge {

using nlohmann::json;

std::string type_name(InType type) {
  switch (type) {
    case InType::kControl:
      return "convoy_msgs/Control";
    case InType::kTwist:
      return "geometry_msgs/Twist";
    default:
      return "geometry_msgs/TwistStamped";
  }
}

std::string name_problem(const std::string& name) {
  if (name.empty()) return "empty";
  const size_t start = name[0] == '/' || name[0] == '~' ? 1 : 0;
  if (start == name.size()) return "names nothing after '" + name + "'";
  if (!std::isalpha(static_cast<unsigned char>(name[start]))) return "must start with a letter";
  for (size_t i = start; i < name.size(); ++i) {
    const unsigned char c = name[i];
    if (c == '/' && (i + 1 == name.size() || name[i + 1] == '/'))
      return i + 1 == name.size() ? "ends with '/'" : "has '//'";
    if (c == '/' && !std::isalpha(static_cast<unsigned char>(name[i + 1])))
      return "each part must start with a letter";
    if (c != '/' && c != '_' && !std::isalnum(c))
      return std::string("has the character '") + static_cast<char>(c) + "'";
  }
  return {};
}

namespace {

std::invalid_argument key_error(const std::string& key, const std::string& why) {
  return std::invalid_argument(key + ": " + why);
}

void check_name(const std::string& key, const std::string& name) {
  if (std::string why = name_problem(name); !why.empty())
    throw key_error(key, "\"" + name + "\" is not a ROS name (" + why + ")");
}

InType parse_type(const std::string& key, const std::string& text) {
  for (InType t : {InType::kControl, InType::kTwist, InType::kTwistStamped})
    if (type_name(t) == text) return t;
  throw key_error(key, "unsupported type \"" + text +
                           "\" (the bridge subscribes to convoy_msgs/Control, "
                           "geometry_msgs/Twist and geometry_msgs/TwistStamped)");
}

}  // namespace

BridgeConfig parse_config(const json& config) {
  BridgeConfig c;
  c.node_name = config.at("NodeName").get<std::string>();
  if (std::string why = name_problem(c.node_name);
      !why.empty() || c.node_name.find('/') != std::string::npos) {
    throw key_error("NodeName", "\"" + c.node_name + "\" is not a ROS node name" +
                                    (why.empty() ? " (no '/')" : " (" + why + ")"));
  }
  c.master_uri = config.at("MasterURI").get<std::string>();
  c.start_master = config.at("StartMaster").get<bool>();
  c.synchronous = config.at("Synchronous").get<bool>();
  c.sync_topic = config.at("SyncTopic").get<std::string>();
  c.sync_timeout_s = config.at("SyncTimeout").get<double>();
  if (!(c.sync_timeout_s > 0))
    throw key_error("SyncTimeout", "must be > 0 s, got " + config.at("SyncTimeout").dump());
  c.publish_clock = config.at("PublishClock").get<bool>();
  c.frames.map = config.at("MapFrame").get<std::string>();
  c.frames.base = config.at("BaseFrame").get<std::string>();
  c.frames.camera = config.at("CameraFrame").get<std::string>();
  c.camera_hfov = config.at("CameraHorizontalFov").get<double>();
  if (!(c.camera_hfov > 0 && c.camera_hfov < 3.14159))
    throw key_error("CameraHorizontalFov",
                    "must be in (0, pi) rad, got " + config.at("CameraHorizontalFov").dump());
  if (config.contains("SensorFrames")) {
    for (const auto& [frame, id] : config.at("SensorFrames").items()) {
      if (!id.is_string() || id.get<std::string>().empty() || id.get<std::string>()[0] == '/')
        throw key_error("SensorFrames/" + frame,
                        "must be a frame id (no leading '/'), got " + id.dump());
      c.sensor_frames[frame] = id.get<std::string>();
    }
  }
  const json& subscribe = config.at("Subscribe");
  for (size_t i = 0; i < subscribe.size(); ++i) {
    const std::string key = "Subscribe/" + std::to_string(i);
    Subscription s;
    s.topic = subscribe[i].at("Topic").get<std::string>();
    check_name(key + "/Topic", s.topic);
    s.type = parse_type(key + "/Type", subscribe[i].at("Type").get<std::string>());
    for (const Subscription& other : c.subscribe)
      if (other.topic == s.topic) throw key_error(key + "/Topic", s.topic + " is listed twice");
    c.subscribe.push_back(s);
  }
  if (c.synchronous) {
    check_name("SyncTopic", c.sync_topic);
    bool found = false;
    for (const Subscription& s : c.subscribe) found = found || s.topic == c.sync_topic;
    if (!found) {
      std::string topics;
      for (const Subscription& s : c.subscribe) topics += (topics.empty() ? "" : ", ") + s.topic;
      throw key_error("SyncTopic", "\"" + c.sync_topic + "\" is not one of the Subscribe topics (" +
                                       (topics.empty() ? "none" : topics) +
                                       "); Synchronous waits for a message on it");
    }
  }
  return c;
}

}  // namespace convoy::ros_bridge
