// Camera and link conversions (conversions.h).
#include <cmath>

#include "conversions.h"

namespace convoy::ros_bridge {

std::string camera_info_topic(const std::string& image_topic) {
  const size_t slash = image_topic.rfind('/');
  if (slash == std::string::npos || slash == 0) return image_topic + "/camera_info";
  return image_topic.substr(0, slash) + "/camera_info";
}

std::string image_encoding(uint32_t depth) {
  switch (depth) {
    case 1:
      return "mono8";
    case 3:
      return "rgb8";
    case 4:
      return "rgba8";
    default:
      return "";
  }
}

sensor_msgs::CameraInfo camera_info(uint32_t width, uint32_t height, double hfov) {
  sensor_msgs::CameraInfo info;
  info.width = width;
  info.height = height;
  const double f = 0.5 * width / std::tan(0.5 * hfov);
  const double cx = 0.5 * width, cy = 0.5 * height;
  info.distortion_model = "plumb_bob";
  info.D.assign(5, 0.0);
  info.K = {f, 0, cx, 0, f, cy, 0, 0, 1};
  info.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  info.P = {f, 0, cx, 0, 0, f, cy, 0, 0, 0, 1, 0};
  return info;
}

geometry_msgs::Vector3 to_body_frame(const geometry_msgs::Quaternion& q,
                                     const geometry_msgs::Vector3& v) {
  // v' = q* v q: the rotation matrix of q, transposed.
  const double x = q.x, y = q.y, z = q.z, w = q.w;
  const double r00 = 1 - 2 * (y * y + z * z), r01 = 2 * (x * y - z * w), r02 = 2 * (x * z + y * w);
  const double r10 = 2 * (x * y + z * w), r11 = 1 - 2 * (x * x + z * z), r12 = 2 * (y * z - x * w);
  const double r20 = 2 * (x * z - y * w), r21 = 2 * (y * z + x * w), r22 = 1 - 2 * (x * x + y * y);
  geometry_msgs::Vector3 out;
  out.x = r00 * v.x + r10 * v.y + r20 * v.z;
  out.y = r01 * v.x + r11 * v.y + r21 * v.z;
  out.z = r02 * v.x + r12 * v.y + r22 * v.z;
  return out;
}

namespace {

geometry_msgs::Vector3 vector3(const google::protobuf::RepeatedField<float>& v) {
  geometry_msgs::Vector3 out;
  if (v.size() > 0) out.x = v[0];
  if (v.size() > 1) out.y = v[1];
  if (v.size() > 2) out.z = v[2];
  return out;
}

geometry_msgs::Quaternion unit_quaternion(const google::protobuf::RepeatedField<float>& r) {
  geometry_msgs::Quaternion q;
  q.w = 1;
  if (r.size() < 4) return q;
  const double n = std::sqrt(double(r[0]) * r[0] + double(r[1]) * r[1] + double(r[2]) * r[2] +
                             double(r[3]) * r[3]);
  if (!(n > 0) || !std::isfinite(n)) return q;
  q.x = r[0] / n;
  q.y = r[1] / n;
  q.z = r[2] / n;
  q.w = r[3] / n;
  return q;
}

}  // namespace

nav_msgs::Odometry odometry(const data::Link& link, const Frames& frames, ros::Time stamp) {
  nav_msgs::Odometry odom;
  odom.header.stamp = stamp;
  odom.header.frame_id = frames.map;
  odom.child_frame_id = frames.base;
  const geometry_msgs::Vector3 p = vector3(link.position());
  odom.pose.pose.position.x = p.x;
  odom.pose.pose.position.y = p.y;
  odom.pose.pose.position.z = p.z;
  odom.pose.pose.orientation = unit_quaternion(link.rotation());
  const auto& q = odom.pose.pose.orientation;
  odom.twist.twist.linear = to_body_frame(q, vector3(link.linear_velocity()));
  odom.twist.twist.angular = to_body_frame(q, vector3(link.angular_velocity()));
  return odom;
}

geometry_msgs::TransformStamped transform(const nav_msgs::Odometry& odom) {
  geometry_msgs::TransformStamped t;
  t.header = odom.header;
  t.child_frame_id = odom.child_frame_id;
  t.transform.translation.x = odom.pose.pose.position.x;
  t.transform.translation.y = odom.pose.pose.position.y;
  t.transform.translation.z = odom.pose.pose.position.z;
  t.transform.rotation = odom.pose.pose.orientation;
  return t;
}

geometry_msgs::Quaternion quaternion_rpy(double roll, double pitch, double yaw) {
  const double cr = std::cos(roll / 2), sr = std::sin(roll / 2);
  const double cp = std::cos(pitch / 2), sp = std::sin(pitch / 2);
  const double cy = std::cos(yaw / 2), sy = std::sin(yaw / 2);
  geometry_msgs::Quaternion q;
  q.w = cr * cp * cy + sr * sp * sy;
  q.x = sr * cp * cy - cr * sp * sy;
  q.y = cr * sp * cy + sr * cp * sy;
  q.z = cr * cp * sy - sr * sp * cy;
  return q;
}

}  // namespace convoy::ros_bridge
