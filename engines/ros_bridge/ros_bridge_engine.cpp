// The ros_bridge engine (ros_bridge_engine.h): the datapacks, read with Convoy's codecs
// (C++20), handed to the ROS node (ros_node.h, C++17).
#include "ros_bridge_engine.h"

#include <cstdio>
#include <stdexcept>

#include "datapack/camera.h"
#include "datapack/json.h"
#include "datapack/proto.h"
#include "datapack/registry.h"

namespace convoy::ros_bridge {

using nlohmann::json;

CONVOY_REGISTER_ENGINE("ros_bridge", RosBridgeEngine);

std::vector<engine::DataPackId> RosBridgeEngine::initialize(const std::string& name,
                                                            const json& config, int64_t) {
  name_ = name;
  config_ = parse_config(config);
  node_ = std::make_unique<RosNode>(name, config_);
  std::fprintf(stderr, "ros_bridge '%s': node /%s, master %s%s\n", name.c_str(),
               config_.node_name.c_str(), node_->master().c_str(),
               node_->started_master() ? ", started by the bridge" : "");
  std::vector<engine::DataPackId> ids;
  for (const Subscription& s : config_.subscribe) {
    engine::DataPackId id;
    id.set_name(s.topic);
    id.set_engine_name(name);
    id.set_type(std::string(datapack::kJsonType));
    ids.push_back(id);
  }
  return ids;
}

int64_t RosBridgeEngine::step(int64_t duration_ns) {
  node_->step(time_ns_);
  time_ns_ += duration_ns;
  return time_ns_;
}

void RosBridgeEngine::set_datapack(const datapack::View& dp) {
  if (dp.empty()) return;
  try {
    queue(dp);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(dp.describe() + ": " + e.what());
  }
}

void RosBridgeEngine::queue(const datapack::View& dp) {
  const std::string& topic = dp.id().name();
  const std::string type = dp.is_json() ? "json" : dp.proto_type();
  if (type == datapack::type_name<data::Camera>()) {
    const datapack::CameraImage image = datapack::read_camera(dp);
    if (image.width == 0 || image.height == 0) return;
    node_->queue_camera(topic, image.height, image.width, image.depth, image.pixels, time_ns_);
  } else if (type == datapack::type_name<data::Link>()) {
    node_->queue_link(topic, datapack::read_proto<data::Link>(dp), time_ns_);
  } else if (type == datapack::type_name<data::RoadUsers>()) {
    node_->queue_road_users(topic, datapack::read_proto<data::RoadUsers>(dp), time_ns_);
  } else if (type == datapack::type_name<data::PointCloud>()) {
    node_->queue_point_cloud(topic, datapack::read_proto<data::PointCloud>(dp));
  } else if (type == datapack::type_name<data::Imu>()) {
    node_->queue_imu(topic, datapack::read_proto<data::Imu>(dp));
  } else if (type == datapack::type_name<data::NavSat>()) {
    node_->queue_navsat(topic, datapack::read_proto<data::NavSat>(dp));
  } else if (dp.is_json()) {
    node_->queue_json(topic, datapack::read_json(dp), time_ns_);
  } else {
    throw std::invalid_argument("type " + (type.empty() ? std::string("?") : type) +
                                ": the ros_bridge engine '" + name_ +
                                "' publishes convoy.data.Camera, convoy.data.Link, "
                                "convoy.data.RoadUsers, convoy.data.PointCloud, convoy.data.Imu, "
                                "convoy.data.NavSat and JSON {\"events\"} or {\"path\"} "
                                "datapacks");
  }
}

void RosBridgeEngine::get_datapack(const engine::DataPackId& id, datapack::Builder& out) {
  if (!node_) return;
  if (const json* value = node_->latest(id.name())) datapack::write_json(out, *value);
}

void RosBridgeEngine::reset() {
  time_ns_ = 0;
  if (node_) node_->clear();
}

void RosBridgeEngine::shutdown() { node_.reset(); }

}  // namespace convoy::ros_bridge
