// LiDAR, IMU and GNSS conversions (conversions.h): PointCloud2, Imu, NavSatFix.
#include <cstring>
#include <stdexcept>

#include "conversions.h"

namespace convoy::ros_bridge {

namespace {

ros::Time stamp_of(int64_t time_ns) {
  ros::Time t;
  t.fromNSec(static_cast<uint64_t>(time_ns < 0 ? 0 : time_ns));
  return t;
}

uint8_t ros_datatype(const std::string& dtype) {
  using F = sensor_msgs::PointField;
  if (dtype == "<f4") return F::FLOAT32;
  if (dtype == "<f8") return F::FLOAT64;
  if (dtype == "<u4") return F::UINT32;
  if (dtype == "<i4") return F::INT32;
  if (dtype == "<u2") return F::UINT16;
  if (dtype == "<i2") return F::INT16;
  if (dtype == "u1" || dtype == "|u1" || dtype == "<u1") return F::UINT8;
  if (dtype == "i1" || dtype == "|i1" || dtype == "<i1") return F::INT8;
  return 0;
}

}  // namespace

std::string sensor_frame(const std::string& frame, const SensorFrames& frames) {
  if (const auto it = frames.find(frame); it != frames.end()) return it->second;
  return frame;
}

sensor_msgs::PointCloud2 point_cloud2(const data::PointCloud& cloud, const SensorFrames& frames) {
  static const char* const kNames[] = {"x",     "y",    "z",      "intensity", "instance",
                                       "label", "ring", "column", "flags"};
  static const uint32_t kOffsets[] = {0, 4, 8, 12, 16, 20, 24, 26, 28};
  static const char* const kTypes[] = {"<f4", "<f4", "<f4", "<f4", "<u4",
                                       "<u4", "<u2", "<u2", "<u4"};
  sensor_msgs::PointCloud2 msg;
  msg.header.stamp = stamp_of(cloud.time_ns());
  msg.header.frame_id = sensor_frame(cloud.frame(), frames);
  const uint32_t step = cloud.point_step() ? cloud.point_step() : 32;
  if (cloud.points().size() % step)
    throw std::invalid_argument("PointCloud: " + std::to_string(cloud.points().size()) +
                                " bytes of points is not a whole number of " +
                                std::to_string(step) + "-byte points");
  const auto add = [&msg, step](const std::string& name, uint32_t offset, const std::string& t) {
    const uint8_t type = ros_datatype(t);
    if (type == 0)
      throw std::invalid_argument("PointCloud field " + name + ": dtype " + t +
                                  " has no sensor_msgs/PointField type");
    if (offset >= step)
      throw std::invalid_argument("PointCloud field " + name + ": offset " +
                                  std::to_string(offset) + " beyond point_step");
    sensor_msgs::PointField f;
    f.name = name;
    f.offset = offset;
    f.datatype = type;
    f.count = 1;
    msg.fields.push_back(f);
  };
  if (cloud.fields_size() == 0) {
    for (int i = 0; i < 9; ++i) add(kNames[i], kOffsets[i], kTypes[i]);
  } else {
    for (const auto& f : cloud.fields()) add(f.name(), f.offset(), f.dtype());
  }
  msg.height = 1;  // unorganised: returns only, ring-major
  msg.width = static_cast<uint32_t>(cloud.points().size() / step);
  msg.is_bigendian = false;
  msg.point_step = step;
  msg.row_step = step * msg.width;
  msg.is_dense = true;
  msg.data.resize(cloud.points().size());
  if (!msg.data.empty()) std::memcpy(msg.data.data(), cloud.points().data(), msg.data.size());
  return msg;
}

sensor_msgs::Imu imu(const data::Imu& reading, const SensorFrames& frames) {
  sensor_msgs::Imu msg;
  msg.header.stamp = stamp_of(reading.time_ns());
  msg.header.frame_id = sensor_frame(reading.frame(), frames);
  if (reading.orientation_size() == 4) {
    msg.orientation.x = reading.orientation(0);
    msg.orientation.y = reading.orientation(1);
    msg.orientation.z = reading.orientation(2);
    msg.orientation.w = reading.orientation(3);
  } else {
    msg.orientation.w = 1;
    msg.orientation_covariance[0] = -1;  // REP 145: no orientation estimate
  }
  const auto& w = reading.angular_velocity();
  const auto& a = reading.linear_acceleration();
  if (w.size() != 3 || a.size() != 3)
    throw std::invalid_argument(
        "Imu: angular_velocity and linear_acceleration need 3 values, got " +
        std::to_string(w.size()) + " and " + std::to_string(a.size()));
  msg.angular_velocity.x = w[0];
  msg.angular_velocity.y = w[1];
  msg.angular_velocity.z = w[2];
  msg.linear_acceleration.x = a[0];
  msg.linear_acceleration.y = a[1];
  msg.linear_acceleration.z = a[2];
  return msg;  // covariances 0: unknown
}

sensor_msgs::NavSatFix navsat_fix(const data::NavSat& fix, const SensorFrames& frames) {
  sensor_msgs::NavSatFix msg;
  msg.header.stamp = stamp_of(fix.time_ns());
  msg.header.frame_id = sensor_frame(fix.frame(), frames);
  msg.status.status = sensor_msgs::NavSatStatus::STATUS_FIX;
  msg.status.service = sensor_msgs::NavSatStatus::SERVICE_GPS;
  msg.latitude = fix.latitude_deg();
  msg.longitude = fix.longitude_deg();
  msg.altitude = fix.altitude();
  msg.position_covariance_type = sensor_msgs::NavSatFix::COVARIANCE_TYPE_UNKNOWN;
  return msg;
}

}  // namespace convoy::ros_bridge
