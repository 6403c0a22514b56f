// The ROS side of the ros_bridge engine (ros_node.h).
#include "ros_node.h"

#include <ros/master.h>
#include <ros/param.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/Image.h>
#include <tf2_msgs/TFMessage.h>
#include <unistd.h>

#include <boost/make_shared.hpp>
#include <cstdlib>
#include <functional>
#include <map>
#include <stdexcept>
#include <vector>

#include "conversions.h"
#include "inbox.h"
#include "master_process.h"
#include "master_uri.h"
#include "sync.h"

namespace convoy::ros_bridge {

using nlohmann::json;
using std::chrono::milliseconds;

namespace {

constexpr auto kProbeTimeout = milliseconds(2000);
constexpr auto kMasterStartTimeout = milliseconds(10000);
constexpr double kConnectTimeout = 2.0;  // s for the subscriber to reach SyncTopic's publishers

std::string this_host() {
  char buf[256] = {};
  gethostname(buf, sizeof buf - 1);
  return buf;
}

ros::Time ros_time(int64_t ns) {
  ros::Time t;
  t.fromNSec(static_cast<uint64_t>(ns));
  return t;
}

std::string resolved(const std::string& topic) {
  try {
    return ros::names::resolve(topic);
  } catch (const std::exception&) {
    return topic;
  }
}

// What the master knows about `topic`: its type and the nodes that publish it.
TopicOnMaster ask_master(const std::string& topic) {
  TopicOnMaster known;
  const std::string name = resolved(topic);
  ros::master::V_TopicInfo topics;
  if (ros::master::getTopics(topics)) {
    for (const auto& t : topics)
      if (t.name == name) known.type = t.datatype;
  }
  XmlRpc::XmlRpcValue args, result, payload;
  args[0] = ros::this_node::getName();
  if (!ros::master::execute("getSystemState", args, result, payload, false) ||
      payload.getType() != XmlRpc::XmlRpcValue::TypeArray || payload.size() < 1) {
    return known;
  }
  XmlRpc::XmlRpcValue& publishers = payload[0];
  for (int i = 0; i < publishers.size(); ++i) {
    if (std::string(publishers[i][0]) != name) continue;
    for (int j = 0; j < publishers[i][1].size(); ++j) {
      const std::string node = publishers[i][1][j];
      if (node != ros::this_node::getName()) known.publishers.push_back(node);
    }
  }
  return known;
}

}  // namespace

struct RosNode::Impl {
  struct Publisher {
    std::string type;
    ros::Publisher publisher;
  };
  BridgeConfig config;
  MasterUri master;
  MasterProcess master_process;
  std::unique_ptr<ros::NodeHandle> node;
  std::unique_ptr<Inbox> inbox;
  ros::Publisher clock;
  std::map<std::string, Publisher> publishers;
  std::vector<std::function<void()>> pending;  // publishes of the next step, in order

  void connect(const std::string& engine);
  void check_topic_types() const;
  template <class M>
  ros::Publisher publisher(const std::string& topic);
  std::string timeout_text(int64_t step_ns) const;
};

void RosNode::Impl::connect(const std::string& engine) {
  const std::string where = master.text + " (" + master.source + ")";
  const MasterProbe probe = probe_master(master, kProbeTimeout);
  if (probe.state != MasterProbe::kMaster) {
    const bool local = is_local_host(master.host, this_host());
    if (local && probe.state == MasterProbe::kNotMaster) {
      throw std::runtime_error("no ROS master at " + where +
                               " and none can be started: " + probe.why + "; port " +
                               std::to_string(master.port) + " is taken by something else");
    }
    if (!local || !config.start_master) {
      throw std::runtime_error(
          "no ROS master at " + where + " and none can be started: " + probe.why +
          (local ? "; StartMaster is false" : "; " + master.host + " is not this machine"));
    }
    std::filesystem::path log;
    if (const char* run_dir = std::getenv("CONVOY_RUN_DIR"); run_dir && *run_dir)
      log = std::filesystem::path(run_dir) / "logs" / (engine + "_rosmaster.log");
    try {
      master_process.start(master, log, kMasterStartTimeout);
    } catch (const std::runtime_error& e) {
      throw std::runtime_error("no ROS master at " + where +
                               " and none can be started: " + e.what());
    }
  }
  ros::M_string remappings{{"__master", master.text}};
  // A master on the loopback: the node's own URI too, unless ROS_IP / ROS_HOSTNAME say.
  const bool loopback = master.host == "localhost" || master.host.rfind("127.", 0) == 0;
  if (loopback && !std::getenv("ROS_IP") && !std::getenv("ROS_HOSTNAME"))
    remappings["__ip"] = "127.0.0.1";
  if (!ros::isInitialized()) {
    ros::init(remappings, config.node_name,
              ros::init_options::NoSigintHandler | ros::init_options::NoRosout);
  }
  ros::master::setRetryTimeout(ros::WallDuration(5.0));
  node = std::make_unique<ros::NodeHandle>();
}

void RosNode::Impl::check_topic_types() const {
  ros::master::V_TopicInfo topics;
  if (!ros::master::getTopics(topics)) return;
  for (const Subscription& s : config.subscribe) {
    const std::string name = resolved(s.topic);
    for (const auto& t : topics) {
      if (t.name != name) continue;
      if (std::string why = type_mismatch(s.topic, t.datatype, type_name(s.type)); !why.empty())
        throw std::runtime_error(why);
    }
  }
}

template <class M>
ros::Publisher RosNode::Impl::publisher(const std::string& topic) {
  const std::string type = ros::message_traits::datatype<M>();
  if (const auto it = publishers.find(topic); it != publishers.end()) {
    if (it->second.type != type) {
      throw std::invalid_argument("it goes to the topic " + topic + " as " + type +
                                  ", which already carries " + it->second.type);
    }
    return it->second.publisher;
  }
  if (std::string why = name_problem(topic); !why.empty()) {
    throw std::invalid_argument("\"" + topic + "\" is not a ROS topic name (" + why +
                                "); the datapack's name is the topic it is published on");
  }
  ros::Publisher p = node->advertise<M>(topic, 10, true);
  publishers[topic] = Publisher{type, p};
  return p;
}

std::string RosNode::Impl::timeout_text(int64_t step_ns) const {
  std::string expected;
  for (const Subscription& s : config.subscribe)
    if (s.topic == config.sync_topic) expected = type_name(s.type);
  TopicOnMaster known = ask_master(config.sync_topic);
  known.connected = inbox->sync_publishers();
  return timeout_message(config.sync_topic, step_ns, config.sync_timeout_s, expected, known,
                         inbox->late());
}

RosNode::RosNode(const std::string& engine, const BridgeConfig& config)
    : impl_(std::make_unique<Impl>()) {
  Impl& d = *impl_;
  d.config = config;
  d.master = choose_master_uri(config.master_uri, std::getenv("ROS_MASTER_URI"));
  d.connect(engine);
  d.check_topic_types();
  d.inbox = std::make_unique<Inbox>(*d.node, config);
  if (config.publish_clock) {
    ros::param::set("/use_sim_time", true);
    d.clock = d.node->advertise<rosgraph_msgs::Clock>("/clock", 10, true);
  }
  // The nodes already publishing SyncTopic: connect to them before the first step, whose
  // answer would otherwise go to nobody.
  if (config.synchronous) {
    const auto known = ask_master(config.sync_topic).publishers;
    d.inbox->wait_for_publishers(static_cast<uint32_t>(known.size()), kConnectTimeout);
  }
}

RosNode::~RosNode() {
  Impl& d = *impl_;
  d.inbox.reset();
  d.publishers.clear();
  d.clock = ros::Publisher();
  d.node.reset();
  if (ros::isStarted()) ros::shutdown();
  d.master_process.stop();
}

std::string RosNode::master() const {
  return impl_->master.text + " (" + impl_->master.source + ")";
}
bool RosNode::started_master() const { return impl_->master_process.running(); }

void RosNode::step(int64_t step_ns) {
  Impl& d = *impl_;
  d.inbox->begin_step(step_ns);
  rosgraph_msgs::Clock clock;
  clock.clock = ros_time(step_ns);
  auto publish = [&d, &clock] {
    if (d.config.publish_clock) d.clock.publish(clock);
    for (auto& p : d.pending) p();
  };
  publish();
  if (!d.inbox->wait(d.config.sync_timeout_s, publish))
    throw std::runtime_error(d.timeout_text(step_ns));
  d.pending.clear();
}

const json* RosNode::latest(const std::string& topic) const { return impl_->inbox->latest(topic); }

void RosNode::clear() {
  impl_->pending.clear();
  impl_->inbox->clear();
}

void RosNode::queue_camera(const std::string& topic, uint32_t height, uint32_t width,
                           uint32_t depth, std::string_view pixels, int64_t stamp_ns) {
  const std::string encoding = image_encoding(depth);
  if (encoding.empty()) {
    throw std::invalid_argument("camera frames of " + std::to_string(depth) +
                                " bytes per pixel have no ROS encoding here (1 mono8, 3 rgb8, "
                                "4 rgba8)");
  }
  auto msg = boost::make_shared<sensor_msgs::Image>();
  msg->header.stamp = ros_time(stamp_ns);
  msg->header.frame_id = impl_->config.frames.camera;
  msg->height = height;
  msg->width = width;
  msg->encoding = encoding;
  msg->step = width * depth;
  msg->data.assign(pixels.begin(), pixels.end());
  auto info = boost::make_shared<sensor_msgs::CameraInfo>(
      camera_info(width, height, impl_->config.camera_hfov));
  info->header = msg->header;
  ros::Publisher images = impl_->publisher<sensor_msgs::Image>(topic);
  ros::Publisher infos = impl_->publisher<sensor_msgs::CameraInfo>(camera_info_topic(topic));
  impl_->pending.push_back([images, infos, msg, info] {
    images.publish(msg);
    infos.publish(info);
  });
}

void RosNode::queue_link(const std::string& topic, const data::Link& link, int64_t stamp_ns) {
  auto odom = boost::make_shared<nav_msgs::Odometry>(
      odometry(link, impl_->config.frames, ros_time(stamp_ns)));
  auto tf = boost::make_shared<tf2_msgs::TFMessage>();
  tf->transforms.push_back(transform(*odom));
  ros::Publisher odoms = impl_->publisher<nav_msgs::Odometry>(topic);
  ros::Publisher tfs = impl_->publisher<tf2_msgs::TFMessage>("/tf");
  impl_->pending.push_back([odoms, tfs, odom, tf] {
    odoms.publish(odom);
    tfs.publish(tf);
  });
}

void RosNode::queue_road_users(const std::string& topic, const data::RoadUsers& users,
                               int64_t stamp_ns) {
  auto msg = boost::make_shared<convoy_msgs::RoadUsers>(
      road_users(users, impl_->config.frames, ros_time(stamp_ns)));
  auto boxes = boost::make_shared<visualization_msgs::MarkerArray>(markers(*msg));
  ros::Publisher msgs = impl_->publisher<convoy_msgs::RoadUsers>(topic);
  ros::Publisher marks = impl_->publisher<visualization_msgs::MarkerArray>(topic + "/markers");
  impl_->pending.push_back([msgs, marks, msg, boxes] {
    msgs.publish(msg);
    marks.publish(boxes);
  });
}

void RosNode::queue_point_cloud(const std::string& topic, const data::PointCloud& cloud) {
  auto msg = boost::make_shared<sensor_msgs::PointCloud2>(
      point_cloud2(cloud, impl_->config.sensor_frames));
  ros::Publisher p = impl_->publisher<sensor_msgs::PointCloud2>(topic);
  impl_->pending.push_back([p, msg] { p.publish(msg); });
}

void RosNode::queue_imu(const std::string& topic, const data::Imu& reading) {
  auto msg = boost::make_shared<sensor_msgs::Imu>(imu(reading, impl_->config.sensor_frames));
  ros::Publisher p = impl_->publisher<sensor_msgs::Imu>(topic);
  impl_->pending.push_back([p, msg] { p.publish(msg); });
}

void RosNode::queue_navsat(const std::string& topic, const data::NavSat& fix) {
  auto msg =
      boost::make_shared<sensor_msgs::NavSatFix>(navsat_fix(fix, impl_->config.sensor_frames));
  ros::Publisher p = impl_->publisher<sensor_msgs::NavSatFix>(topic);
  impl_->pending.push_back([p, msg] { p.publish(msg); });
}

void RosNode::queue_json(const std::string& topic, const json& value, int64_t stamp_ns) {
  const bool has_events = value.is_object() && value.contains("events");
  const bool has_path = value.is_object() && value.contains("path");
  if (has_events == has_path) {
    throw std::invalid_argument(
        "a JSON datapack for the ros_bridge engine is {\"events\": [...]} or {\"path\": [[x, y, "
        "z?, yaw?], ...]}, got " +
        value.dump().substr(0, 200));
  }
  if (has_events) {
    auto list = events(value, ros_time(stamp_ns));
    ros::Publisher p = impl_->publisher<convoy_msgs::Event>(topic);
    impl_->pending.push_back([p, list = std::move(list)] {
      for (const auto& e : list) p.publish(e);
    });
  } else {
    auto msg =
        boost::make_shared<nav_msgs::Path>(path(value, impl_->config.frames, ros_time(stamp_ns)));
    ros::Publisher p = impl_->publisher<nav_msgs::Path>(topic);
    impl_->pending.push_back([p, msg] { p.publish(msg); });
  }
}

}  // namespace convoy::ros_bridge
