// EngineType "ros_bridge": a ROS 1 node (roscpp) between Convoy's loop and a ROS stack. Each
// step publishes the simulated time and the datapacks the transceiver functions sent, then, when
// Synchronous, waits for the ROS side's answer, so that a ROS driver runs in lockstep with the
// simulation.
//
// Config keys (schema.json):
//   NodeName            "convoy"            the ROS node's name (no anonymous suffix)
//   MasterURI           ""                  "": $ROS_MASTER_URI, else http://localhost:11311
//   StartMaster         true                no master answers at a local URI: start
//                                           `rosmaster --core -p PORT` (its output in
//                                           $CONVOY_RUN_DIR/logs/<engine>_rosmaster.log),
//                                           stopped at shutdown
//   Synchronous         true                each step waits for a message on SyncTopic
//   SyncTopic           "/convoy/control"   one of the Subscribe topics
//   SyncTimeout         10                  s; no answer within it: an error naming the topic
//   Subscribe           [/convoy/control convoy_msgs/Control, /cmd_vel geometry_msgs/Twist]
//                                           [{"Topic", "Type"}]; types: convoy_msgs/Control,
//                                           geometry_msgs/Twist, geometry_msgs/TwistStamped
//   PublishClock        true                /clock each step, and /use_sim_time = true
//   MapFrame, BaseFrame, CameraFrame        "map", "base_link", "camera"
//   CameraHorizontalFov 1.57                rad, for camera_info
//   SensorFrames        {}                  {"<model>::<link>::<sensor>": "frame id"} for the
//                                           LiDAR, IMU and GNSS messages
//
// Datapacks read (published on the topic named like the datapack, stamped with the engine's
// time at the start of the step, in the order received; all publishers are latched, so a
// node that subscribes late still gets the step's data):
//   convoy.data.Camera     sensor_msgs/Image (mono8, rgb8, rgba8) on NAME, frame CameraFrame,
//                          and sensor_msgs/CameraInfo on the sibling camera_info topic
//   convoy.data.Link       nav_msgs/Odometry on NAME (MapFrame -> BaseFrame, twist in
//                          BaseFrame) and the transform on /tf
//   convoy.data.RoadUsers  convoy_msgs/RoadUsers on NAME, visualization_msgs/MarkerArray on
//                          NAME/markers
//   convoy.data.PointCloud sensor_msgs/PointCloud2 on NAME (x y z intensity instance label ring
//                          column flags, height 1), stamped with the scan's time
//   convoy.data.Imu        sensor_msgs/Imu on NAME, stamped with the reading's time
//   convoy.data.NavSat     sensor_msgs/NavSatFix on NAME, stamped with the reading's time
//                          (the three framed <model>::<link>::<sensor>, or as SensorFrames maps it)
//   JSON {"events": [...]}  a convoy_msgs/Event per item on NAME
//   JSON {"path": [[x, y, z?, yaw?], ...]}  nav_msgs/Path on NAME
//   anything else: an error naming the datapack and its type.
// Datapacks written: one JSON datapack per Subscribe topic, named like the topic, with its
// latest message (empty before the first): Control {"throttle", "brake", "steer", "reverse",
// "stamp"}; Twist {"linear": [x, y, z], "angular": [x, y, z]}; TwistStamped the same and
// "stamp" (s).
//
// The synchronous step at t (sync.h): /clock = t, the queued data, then a wait for a message on
// SyncTopic stamped t or later (or unstamped and received after the step published); older
// stamped ones are dropped as late. Initialize first connects to the nodes that already
// publish SyncTopic; a publisher that connects while a step waits gets the step's messages
// again (ROS drops what goes out before a connection is up), so a ROS node may see a step's
// /clock and data twice and should answer each (a repeated answer is harmless).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "engine/engine.h"
#include "ros_node.h"

namespace convoy::ros_bridge {

class RosBridgeEngine final : public engines::Engine {
 public:
  std::vector<engine::DataPackId> initialize(const std::string& name, const nlohmann::json& config,
                                             int64_t timestep_ns) override;
  int64_t step(int64_t duration_ns) override;
  void set_datapack(const datapack::View& datapack) override;
  void get_datapack(const engine::DataPackId& id, datapack::Builder& out) override;
  void reset() override;
  void shutdown() override;

 private:
  void queue(const datapack::View& dp);

  std::string name_;
  BridgeConfig config_;
  std::unique_ptr<RosNode> node_;
  int64_t time_ns_ = 0;
};

}  // namespace convoy::ros_bridge
