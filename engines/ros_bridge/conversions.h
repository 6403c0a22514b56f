// Convoy's datapacks as ROS messages and ROS messages as JSON datapacks, apart from ROS's
// transport: plain functions of their inputs (tests/ros_bridge/conversions_test.cpp).
#pragma once

#include <convoy_msgs/Control.h>
#include <convoy_msgs/Event.h>
#include <convoy_msgs/RoadUsers.h>
#include <geometry_msgs/TransformStamped.h>
#include <geometry_msgs/Twist.h>
#include <geometry_msgs/TwistStamped.h>
#include <nav_msgs/Odometry.h>
#include <nav_msgs/Path.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/NavSatFix.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_msgs/ColorRGBA.h>
#include <visualization_msgs/MarkerArray.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bridge_config.h"
#include "convoy/datapacks.pb.h"
#include "convoy/nav_sensors.pb.h"
#include "convoy/point_cloud.pb.h"
#include "convoy/road_users.pb.h"

namespace convoy::ros_bridge {

// --- Camera -------------------------------------------------------------------------------
// The camera_info topic next to an image topic: "/convoy/camera/image_raw" ->
// "/convoy/camera/camera_info"; a name without a parent namespace ("image", "/image") gets
// "/camera_info" appended.
std::string camera_info_topic(const std::string& image_topic);
// sensor_msgs/Image encoding of `depth` bytes per pixel: "mono8" (1), "rgb8" (3), "rgba8" (4);
// "" for others.
std::string image_encoding(uint32_t depth);
// A pinhole camera of horizontal field of view `hfov` (rad) with square pixels, principal
// point at the image centre (width / 2, height / 2), plumb_bob with zero distortion.
sensor_msgs::CameraInfo camera_info(uint32_t width, uint32_t height, double hfov);

// --- Link ---------------------------------------------------------------------------------
// `v` (world frame) in the frame of orientation `q` (x y z w): the inverse rotation.
geometry_msgs::Vector3 to_body_frame(const geometry_msgs::Quaternion& q,
                                     const geometry_msgs::Vector3& v);
// Odometry of a link: pose in frames.map, child frames.base, twist (linear and angular) in
// the child frame. Missing fields of the Link are zero (the rotation: identity).
nav_msgs::Odometry odometry(const data::Link& link, const Frames& frames, ros::Time stamp);
// The transform frames.map -> frames.base of the odometry's pose.
geometry_msgs::TransformStamped transform(const nav_msgs::Odometry& odom);

// --- Road users, events, path -------------------------------------------------------------
// Quaternion of yaw (about z), then pitch (y), then roll (x), as ROS's tf2 setRPY.
geometry_msgs::Quaternion quaternion_rpy(double roll, double pitch, double yaw);
// Every present road user (absent ones are left out), poses in frames.map.
convoy_msgs::RoadUsers road_users(const data::RoadUsers& users, const Frames& frames,
                                  ros::Time stamp);
// Colour of a category's markers: car blue, truck orange, bus yellow, pedestrian red,
// cyclist green, others grey; alpha 0.8.
std_msgs::ColorRGBA category_colour(const std::string& category);
// DELETEALL, then a CUBE per road user of `users` (namespace its category, id its index),
// its bounding box: centred length_offset ahead of the reference point, on the ground.
visualization_msgs::MarkerArray markers(const convoy_msgs::RoadUsers& users);
// {"events": [{"kind", "actor", "other", "severity", "detail"}...]} as messages. Throws
// std::invalid_argument saying which item is malformed.
std::vector<convoy_msgs::Event> events(const nlohmann::json& value, ros::Time stamp);
// {"path": [[x, y, z?, yaw?], ...]} as a nav_msgs/Path in frames.map. Throws
// std::invalid_argument saying which point is malformed.
nav_msgs::Path path(const nlohmann::json& value, const Frames& frames, ros::Time stamp);

// --- LiDAR, IMU, GNSS (nav_conversions.cpp) -------------------------------------------------
// Each is stamped with its reading's simulated time (time_ns) and framed by its `frame`
// (<model>::<link>::<sensor>) or what SensorFrames maps it to.
std::string sensor_frame(const std::string& frame, const SensorFrames& frames);
// An unorganised cloud (height 1, one point a return, ring-major) with the datapack's fields
// (x y z intensity instance label ring column flags), point_step 32, little-endian. Throws
// std::invalid_argument for a dtype without a PointField type or bytes not whole points.
sensor_msgs::PointCloud2 point_cloud2(const data::PointCloud& cloud, const SensorFrames& frames);
// No orientation (SDF's enable_orientation false): orientation_covariance[0] = -1 (REP 145).
// Covariances are 0 (unknown). Throws std::invalid_argument without 3 rates and 3 accelerations.
sensor_msgs::Imu imu(const data::Imu& reading, const SensorFrames& frames);
// STATUS_FIX by GPS, covariance unknown.
sensor_msgs::NavSatFix navsat_fix(const data::NavSat& fix, const SensorFrames& frames);

// --- Messages from ROS as JSON datapacks --------------------------------------------------
nlohmann::json control_json(const convoy_msgs::Control& control);  // throttle brake steer ...
nlohmann::json twist_json(const geometry_msgs::Twist& twist);      // linear, angular
nlohmann::json twist_stamped_json(const geometry_msgs::TwistStamped& twist);  // + stamp

}  // namespace convoy::ros_bridge
