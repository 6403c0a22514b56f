// Road users, events, paths, and the messages from ROS as JSON (conversions.h).
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "conversions.h"

namespace convoy::ros_bridge {

using nlohmann::json;

convoy_msgs::RoadUsers road_users(const data::RoadUsers& users, const Frames& frames,
                                  ros::Time stamp) {
  convoy_msgs::RoadUsers out;
  out.header.stamp = stamp;
  out.header.frame_id = frames.map;
  for (const data::RoadUser& u : users.users()) {
    if (u.absent()) continue;
    convoy_msgs::RoadUser m;
    m.id = u.id();
    m.category = u.category();
    m.model = u.model();
    m.pose.position.x = u.x();
    m.pose.position.y = u.y();
    m.pose.position.z = u.z();
    m.pose.orientation = quaternion_rpy(u.roll(), u.pitch(), u.yaw());
    m.twist.linear.x = u.vx();
    m.twist.linear.y = u.vy();
    m.twist.angular.z = u.yaw_rate();
    m.speed = u.speed();
    m.acceleration = u.acceleration();
    m.size.x = u.length();
    m.size.y = u.width();
    m.size.z = u.height();
    m.length_offset = u.length_offset();
    m.lights = u.lights();
    m.road = u.road();
    m.lane = u.lane();
    m.s = u.s();
    m.t = u.t();
    out.road_users.push_back(std::move(m));
  }
  return out;
}

std_msgs::ColorRGBA category_colour(const std::string& category) {
  std_msgs::ColorRGBA c;
  c.a = 0.8f;
  auto rgb = [&c](float r, float g, float b) {
    c.r = r;
    c.g = g;
    c.b = b;
  };
  if (category == "car") {
    rgb(0.2f, 0.4f, 1.0f);
  } else if (category == "truck") {
    rgb(1.0f, 0.5f, 0.0f);
  } else if (category == "bus") {
    rgb(1.0f, 0.85f, 0.0f);
  } else if (category == "pedestrian") {
    rgb(1.0f, 0.2f, 0.2f);
  } else if (category == "cyclist") {
    rgb(0.2f, 0.8f, 0.2f);
  } else {
    rgb(0.6f, 0.6f, 0.6f);
  }
  return c;
}

visualization_msgs::MarkerArray markers(const convoy_msgs::RoadUsers& users) {
  visualization_msgs::MarkerArray out;
  visualization_msgs::Marker clear;
  clear.header = users.header;
  clear.action = visualization_msgs::Marker::DELETEALL;
  clear.pose.orientation.w = 1;
  out.markers.push_back(clear);
  for (size_t i = 0; i < users.road_users.size(); ++i) {
    const convoy_msgs::RoadUser& u = users.road_users[i];
    visualization_msgs::Marker m;
    m.header = users.header;
    m.ns = u.category;
    m.id = static_cast<int32_t>(i);
    m.type = visualization_msgs::Marker::CUBE;
    m.action = visualization_msgs::Marker::ADD;
    m.pose.orientation = u.pose.orientation;
    // The box centre: length_offset ahead along the heading, half the height up (body x and z).
    geometry_msgs::Vector3 ahead;
    ahead.x = u.length_offset;
    ahead.z = 0.5 * u.size.z;
    geometry_msgs::Quaternion inverse = u.pose.orientation;
    inverse.w = -inverse.w;  // to_body_frame of the inverse rotation: body -> world
    const geometry_msgs::Vector3 offset = to_body_frame(inverse, ahead);
    m.pose.position.x = u.pose.position.x + offset.x;
    m.pose.position.y = u.pose.position.y + offset.y;
    m.pose.position.z = u.pose.position.z + offset.z;
    m.scale.x = std::max(u.size.x, 0.01);
    m.scale.y = std::max(u.size.y, 0.01);
    m.scale.z = std::max(u.size.z, 0.01);
    m.color = category_colour(u.category);
    out.markers.push_back(std::move(m));
  }
  return out;
}

namespace {

std::string text_of(const json& item, const char* key, size_t index) {
  const auto it = item.find(key);
  if (it == item.end() || it->is_null()) return {};
  if (it->is_string()) return it->get<std::string>();
  if (std::string(key) == "detail") return it->dump();
  throw std::invalid_argument("events[" + std::to_string(index) + "]." + key +
                              ": expected a string, got " + it->dump());
}

}  // namespace

std::vector<convoy_msgs::Event> events(const json& value, ros::Time stamp) {
  const json& items = value.at("events");
  if (!items.is_array()) throw std::invalid_argument("\"events\" is not a list");
  std::vector<convoy_msgs::Event> out;
  for (size_t i = 0; i < items.size(); ++i) {
    const json& item = items[i];
    if (!item.is_object())
      throw std::invalid_argument("events[" + std::to_string(i) + "] is not an object");
    convoy_msgs::Event e;
    e.header.stamp = stamp;
    e.kind = text_of(item, "kind", i);
    e.actor = text_of(item, "actor", i);
    e.other = text_of(item, "other", i);
    e.detail = text_of(item, "detail", i);
    if (const auto s = item.find("severity"); s != item.end() && !s->is_null()) {
      if (!s->is_number())
        throw std::invalid_argument("events[" + std::to_string(i) + "].severity: not a number");
      e.severity = s->get<double>();
    }
    out.push_back(std::move(e));
  }
  return out;
}

nav_msgs::Path path(const json& value, const Frames& frames, ros::Time stamp) {
  const json& points = value.at("path");
  if (!points.is_array()) throw std::invalid_argument("\"path\" is not a list");
  nav_msgs::Path out;
  out.header.stamp = stamp;
  out.header.frame_id = frames.map;
  for (size_t i = 0; i < points.size(); ++i) {
    const json& p = points[i];
    const bool numbers = p.is_array() && std::all_of(p.begin(), p.end(),
                                                     [](const json& v) { return v.is_number(); });
    if (!numbers || p.size() < 2 || p.size() > 4) {
      throw std::invalid_argument("path[" + std::to_string(i) +
                                  "]: expected [x, y, z?, yaw?] numbers, got " + p.dump());
    }
    geometry_msgs::PoseStamped pose;
    pose.header = out.header;
    pose.pose.position.x = p[0].get<double>();
    pose.pose.position.y = p[1].get<double>();
    pose.pose.position.z = p.size() > 2 ? p[2].get<double>() : 0.0;
    pose.pose.orientation = quaternion_rpy(0, 0, p.size() > 3 ? p[3].get<double>() : 0.0);
    out.poses.push_back(std::move(pose));
  }
  return out;
}

json control_json(const convoy_msgs::Control& control) {
  return {{"throttle", control.throttle},
          {"brake", control.brake},
          {"steer", control.steer},
          {"reverse", control.reverse != 0},
          {"stamp", control.header.stamp.toSec()}};
}

json twist_json(const geometry_msgs::Twist& twist) {
  return {{"linear", {twist.linear.x, twist.linear.y, twist.linear.z}},
          {"angular", {twist.angular.x, twist.angular.y, twist.angular.z}}};
}

json twist_stamped_json(const geometry_msgs::TwistStamped& twist) {
  json out = twist_json(twist.twist);
  out["stamp"] = twist.header.stamp.toSec();
  return out;
}

}  // namespace convoy::ros_bridge
