// The ROS side of the ros_bridge engine: one roscpp node that finds (or starts) the master,
// subscribes to the Subscribe topics (inbox.h), and publishes /clock and the step's data on
// latched topics. It compiles as C++17 (ROS's message headers do not compile as C++20), and
// this header, which the engine's C++20 translation unit includes, names no ROS type.
#pragma once

#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "bridge_config.h"
#include "convoy/datapacks.pb.h"
#include "convoy/nav_sensors.pb.h"
#include "convoy/point_cloud.pb.h"
#include "convoy/road_users.pb.h"

namespace convoy::ros_bridge {

class RosNode {
 public:
  // Finds the master (starting one when it is local, unreachable and config.start_master),
  // starts the node, checks the Subscribe topics' types on the master, subscribes, sets
  // /use_sim_time. `engine` names the master's log, logs/<engine>_rosmaster.log in
  // $CONVOY_RUN_DIR. Throws std::runtime_error naming the master or the topic.
  RosNode(const std::string& engine, const BridgeConfig& config);
  // Shuts the node down and stops the master it started.
  ~RosNode();
  RosNode(const RosNode&) = delete;
  RosNode& operator=(const RosNode&) = delete;

  // Queue messages for the next step, stamped `stamp_ns`, on `topic` and its siblings
  // (ros_bridge_engine.h). Throw std::invalid_argument saying what is wrong with the data or
  // the topic (the caller names the datapack).
  void queue_camera(const std::string& topic, uint32_t height, uint32_t width, uint32_t depth,
                    std::string_view pixels, int64_t stamp_ns);
  void queue_link(const std::string& topic, const data::Link& link, int64_t stamp_ns);
  void queue_road_users(const std::string& topic, const data::RoadUsers& users, int64_t stamp_ns);
  // Sensors: stamped with their reading's time, not `stamp_ns`'s step (conversions.h).
  void queue_point_cloud(const std::string& topic, const data::PointCloud& cloud);
  void queue_imu(const std::string& topic, const data::Imu& reading);
  void queue_navsat(const std::string& topic, const data::NavSat& fix);
  // {"events": [...]} or {"path": [...]}.
  void queue_json(const std::string& topic, const nlohmann::json& value, int64_t stamp_ns);

  // The step at `step_ns`: publishes /clock, then the queued messages in order, then (when
  // Synchronous) waits for the answer on SyncTopic. Throws std::runtime_error on timeout
  // (sync.h's timeout_message).
  void step(int64_t step_ns);
  // The latest message on a Subscribe topic as JSON, nullptr before the first.
  const nlohmann::json* latest(const std::string& topic) const;
  // Forgets the latest messages and the queued ones (reset).
  void clear();
  // "http://HOST:PORT (SOURCE)", and whether the node started that master.
  std::string master() const;
  bool started_master() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace convoy::ros_bridge
