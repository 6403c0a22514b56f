// LiDAR, IMU and GNSS datapacks as ROS messages (engines/ros_bridge/conversions.h,
// nav_conversions.cpp), and the SensorFrames key.
#include <gtest/gtest.h>

#include <cstring>
#include <stdexcept>

#include "bridge_config.h"
#include "conversions.h"

namespace convoy::ros_bridge {
namespace {

struct Point {  // the record of src/lidar/point_cloud.h
  float x, y, z, intensity;
  uint32_t instance, label;
  uint16_t ring, column;
  uint32_t flags;
};
static_assert(sizeof(Point) == 32);

data::PointCloud cloud_of(const std::vector<Point>& pts, bool with_fields = true) {
  data::PointCloud c;
  c.set_time_ns(1'250'000'000);
  c.set_point_step(32);
  c.set_frame("car::body::lidar");
  if (with_fields) {
    const std::pair<const char*, std::pair<uint32_t, const char*>> fields[] = {
        {"x", {0, "<f4"}},          {"y", {4, "<f4"}},         {"z", {8, "<f4"}},
        {"intensity", {12, "<f4"}}, {"instance", {16, "<u4"}}, {"label", {20, "<u4"}},
        {"ring", {24, "<u2"}},      {"column", {26, "<u2"}},   {"flags", {28, "<u4"}}};
    for (const auto& [name, rest] : fields) {
      auto* f = c.add_fields();
      f->set_name(name);
      f->set_offset(rest.first);
      f->set_dtype(rest.second);
    }
  }
  c.set_points(reinterpret_cast<const char*>(pts.data()), pts.size() * sizeof(Point));
  c.set_count(static_cast<uint32_t>(pts.size()));
  return c;
}

TEST(RosPointCloud, FieldsBytesStampAndFrame) {
  const std::vector<Point> pts = {{1, 2, 3, 0.5f, 7, 1, 4, 100, 0},
                                  {-1, 0, 0.5f, 0.1f, 0, 0, 0, 3, 1}};
  const sensor_msgs::PointCloud2 m = point_cloud2(cloud_of(pts), {});
  EXPECT_EQ(m.header.stamp, ros::Time(1, 250'000'000));
  EXPECT_EQ(m.header.frame_id, "car::body::lidar");
  EXPECT_EQ(m.height, 1u);
  EXPECT_EQ(m.width, 2u);
  EXPECT_EQ(m.point_step, 32u);
  EXPECT_EQ(m.row_step, 64u);
  EXPECT_FALSE(m.is_bigendian);
  ASSERT_EQ(m.fields.size(), 9u);
  EXPECT_EQ(m.fields[3].name, "intensity");
  EXPECT_EQ(m.fields[3].datatype, sensor_msgs::PointField::FLOAT32);
  EXPECT_EQ(m.fields[4].name, "instance");
  EXPECT_EQ(m.fields[4].datatype, sensor_msgs::PointField::UINT32);
  EXPECT_EQ(m.fields[6].name, "ring");
  EXPECT_EQ(m.fields[6].offset, 24u);
  EXPECT_EQ(m.fields[6].datatype, sensor_msgs::PointField::UINT16);
  ASSERT_EQ(m.data.size(), 64u);
  Point back[2];
  std::memcpy(back, m.data.data(), 64);
  EXPECT_EQ(back[0].z, 3.0f);
  EXPECT_EQ(back[0].instance, 7u);
  EXPECT_EQ(back[1].column, 3u);
  EXPECT_EQ(back[1].flags, 1u);
  // without fields: the standard record; SensorFrames renames the frame
  const auto n = point_cloud2(cloud_of(pts, false), {{"car::body::lidar", "velodyne"}});
  EXPECT_EQ(n.fields.size(), 9u);
  EXPECT_EQ(n.header.frame_id, "velodyne");
}

TEST(RosPointCloud, BadCloudsAreRefused) {
  data::PointCloud c = cloud_of({{}});
  c.set_points(std::string(40, '\0'));
  EXPECT_THROW(point_cloud2(c, {}), std::invalid_argument);
  c = cloud_of({{}});
  c.mutable_fields(0)->set_dtype("<c8");
  try {
    point_cloud2(c, {});
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "PointCloud field x: dtype <c8 has no sensor_msgs/PointField type");
  }
}

TEST(RosImu, ReadingsAndNoOrientation) {
  data::Imu r;
  r.set_time_ns(20'000'000);
  r.set_frame("car::body::imu");
  for (double v : {0.0, 0.0, 0.3826834, 0.9238795}) r.add_orientation(v);
  for (double v : {0.1, 0.2, 0.3}) r.add_angular_velocity(v);
  for (double v : {1.0, 0.0, 9.8}) r.add_linear_acceleration(v);
  sensor_msgs::Imu m = imu(r, {});
  EXPECT_EQ(m.header.stamp, ros::Time(0, 20'000'000));
  EXPECT_EQ(m.header.frame_id, "car::body::imu");
  EXPECT_DOUBLE_EQ(m.orientation.z, 0.3826834);
  EXPECT_DOUBLE_EQ(m.orientation_covariance[0], 0);
  EXPECT_DOUBLE_EQ(m.angular_velocity.z, 0.3);
  EXPECT_DOUBLE_EQ(m.linear_acceleration.z, 9.8);
  r.clear_orientation();
  m = imu(r, {});
  EXPECT_DOUBLE_EQ(m.orientation.w, 1);
  EXPECT_DOUBLE_EQ(m.orientation_covariance[0], -1);  // REP 145
  r.clear_angular_velocity();
  EXPECT_THROW(imu(r, {}), std::invalid_argument);
}

TEST(RosNavSat, Fix) {
  data::NavSat f;
  f.set_time_ns(3'000'000'000);
  f.set_frame("car::body::gnss");
  f.set_latitude_deg(48.2);
  f.set_longitude_deg(16.37);
  f.set_altitude(180.5);
  const sensor_msgs::NavSatFix m = navsat_fix(f, {{"car::body::gnss", "gps"}});
  EXPECT_EQ(m.header.stamp, ros::Time(3, 0));
  EXPECT_EQ(m.header.frame_id, "gps");
  EXPECT_EQ(m.status.status, sensor_msgs::NavSatStatus::STATUS_FIX);
  EXPECT_DOUBLE_EQ(m.latitude, 48.2);
  EXPECT_DOUBLE_EQ(m.longitude, 16.37);
  EXPECT_DOUBLE_EQ(m.altitude, 180.5);
  EXPECT_EQ(m.position_covariance_type, sensor_msgs::NavSatFix::COVARIANCE_TYPE_UNKNOWN);
}

TEST(RosBridgeConfig, SensorFrames) {
  nlohmann::json c = {{"NodeName", "convoy"},
                      {"MasterURI", ""},
                      {"StartMaster", true},
                      {"Synchronous", false},
                      {"SyncTopic", "/x"},
                      {"SyncTimeout", 10},
                      {"Subscribe", nlohmann::json::array()},
                      {"PublishClock", true},
                      {"MapFrame", "map"},
                      {"BaseFrame", "base_link"},
                      {"CameraFrame", "camera"},
                      {"CameraHorizontalFov", 1.57},
                      {"SensorFrames", {{"car::body::lidar", "velodyne"}}}};
  EXPECT_EQ(parse_config(c).sensor_frames.at("car::body::lidar"), "velodyne");
  c["SensorFrames"]["car::body::imu"] = "/imu";
  try {
    parse_config(c);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("SensorFrames/car::body::imu"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace convoy::ros_bridge
