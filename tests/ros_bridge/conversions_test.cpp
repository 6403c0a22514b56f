// Datapacks as ROS messages and back (engines/ros_bridge/conversions.h).
#include "conversions.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace convoy::ros_bridge {
namespace {

using nlohmann::json;

ros::Time at(double s) { return ros::Time(s); }

TEST(RosCamera, InfoTopicIsTheSibling) {
  EXPECT_EQ(camera_info_topic("/convoy/camera/image_raw"), "/convoy/camera/camera_info");
  EXPECT_EQ(camera_info_topic("cam/image"), "cam/camera_info");
  EXPECT_EQ(camera_info_topic("image"), "image/camera_info");
  EXPECT_EQ(camera_info_topic("/image"), "/image/camera_info");
}

TEST(RosCamera, Encodings) {
  EXPECT_EQ(image_encoding(1), "mono8");
  EXPECT_EQ(image_encoding(3), "rgb8");
  EXPECT_EQ(image_encoding(4), "rgba8");
  EXPECT_EQ(image_encoding(2), "");
}

TEST(RosCamera, PinholeIntrinsics) {
  // 90 degrees over 640 pixels: f = 320 / tan(45 deg) = 320.
  const sensor_msgs::CameraInfo info = camera_info(640, 480, M_PI / 2);
  EXPECT_EQ(info.width, 640u);
  EXPECT_EQ(info.height, 480u);
  EXPECT_NEAR(info.K[0], 320.0, 1e-9);
  EXPECT_NEAR(info.K[4], 320.0, 1e-9);
  EXPECT_DOUBLE_EQ(info.K[2], 320.0);
  EXPECT_DOUBLE_EQ(info.K[5], 240.0);
  EXPECT_DOUBLE_EQ(info.K[8], 1.0);
  EXPECT_NEAR(info.P[0], 320.0, 1e-9);
  EXPECT_DOUBLE_EQ(info.P[2], 320.0);
  EXPECT_DOUBLE_EQ(info.P[10], 1.0);
  EXPECT_EQ(info.distortion_model, "plumb_bob");
  ASSERT_EQ(info.D.size(), 5u);
  for (double d : info.D) EXPECT_EQ(d, 0.0);
}

TEST(RosLink, TwistIsInTheBodyFrame) {
  data::Link link;
  for (float v : {1.0f, 2.0f, 0.5f}) link.add_position(v);
  // Yaw 90 degrees: body x is world y.
  const float s = std::sqrt(0.5f);
  for (float v : {0.0f, 0.0f, s, s}) link.add_rotation(v);
  for (float v : {0.0f, 3.0f, 0.0f}) link.add_linear_velocity(v);
  for (float v : {0.0f, 0.0f, 0.2f}) link.add_angular_velocity(v);
  const nav_msgs::Odometry odom = odometry(link, Frames{}, at(1.25));
  EXPECT_EQ(odom.header.frame_id, "map");
  EXPECT_EQ(odom.child_frame_id, "base_link");
  EXPECT_EQ(odom.header.stamp, at(1.25));
  EXPECT_DOUBLE_EQ(odom.pose.pose.position.y, 2.0);
  EXPECT_NEAR(odom.twist.twist.linear.x, 3.0, 1e-6);  // forwards
  EXPECT_NEAR(odom.twist.twist.linear.y, 0.0, 1e-6);
  EXPECT_NEAR(odom.twist.twist.angular.z, 0.2, 1e-6);
  const geometry_msgs::TransformStamped tf = transform(odom);
  EXPECT_EQ(tf.child_frame_id, "base_link");
  EXPECT_EQ(tf.header.frame_id, "map");
  EXPECT_DOUBLE_EQ(tf.transform.translation.x, 1.0);
  EXPECT_NEAR(tf.transform.rotation.z, s, 1e-6);
}

TEST(RosLink, MissingFieldsAreZeroAndIdentity) {
  const nav_msgs::Odometry odom = odometry(data::Link{}, Frames{}, at(0));
  EXPECT_EQ(odom.pose.pose.orientation.w, 1.0);
  EXPECT_EQ(odom.twist.twist.linear.x, 0.0);
}

TEST(RosLink, BodyFrameOfAPitchedCar) {
  // Pitched 90 degrees nose down (about y): world -z is body x.
  const geometry_msgs::Quaternion q = quaternion_rpy(0, M_PI / 2, 0);
  geometry_msgs::Vector3 down;
  down.z = -1;
  const geometry_msgs::Vector3 b = to_body_frame(q, down);
  EXPECT_NEAR(b.x, 1.0, 1e-9);
  EXPECT_NEAR(b.z, 0.0, 1e-9);
}

data::RoadUsers two_users() {
  data::RoadUsers users;
  data::RoadUser* car = users.add_users();
  car->set_id("ego");
  car->set_category("car");
  car->set_x(10);
  car->set_y(5);
  car->set_yaw(M_PI / 2);
  car->set_vx(0);
  car->set_vy(4);
  car->set_length(4);
  car->set_width(2);
  car->set_height(1.5);
  car->set_length_offset(1.5);
  data::RoadUser* gone = users.add_users();
  gone->set_id("walker");
  gone->set_category("pedestrian");
  gone->set_absent(true);
  data::RoadUser* walker = users.add_users();
  walker->set_id("p1");
  walker->set_category("pedestrian");
  return users;
}

TEST(RosRoadUsers, PresentOnesWithPoseAndSize) {
  const convoy_msgs::RoadUsers msg = road_users(two_users(), Frames{}, at(2));
  ASSERT_EQ(msg.road_users.size(), 2u);
  EXPECT_EQ(msg.header.frame_id, "map");
  const convoy_msgs::RoadUser& car = msg.road_users[0];
  EXPECT_EQ(car.id, "ego");
  EXPECT_NEAR(car.pose.orientation.z, std::sqrt(0.5), 1e-9);
  EXPECT_DOUBLE_EQ(car.twist.linear.y, 4);
  EXPECT_DOUBLE_EQ(car.size.x, 4);
  EXPECT_EQ(msg.road_users[1].id, "p1");
}

TEST(RosRoadUsers, MarkersAreBoxesColouredByCategory) {
  const visualization_msgs::MarkerArray array = markers(road_users(two_users(), Frames{}, at(2)));
  ASSERT_EQ(array.markers.size(), 3u);
  EXPECT_EQ(array.markers[0].action, visualization_msgs::Marker::DELETEALL);
  const visualization_msgs::Marker& car = array.markers[1];
  EXPECT_EQ(car.type, visualization_msgs::Marker::CUBE);
  EXPECT_EQ(car.ns, "car");
  // Heading +y: the box centre is 1.5 m ahead (y), half its height up.
  EXPECT_NEAR(car.pose.position.x, 10, 1e-9);
  EXPECT_NEAR(car.pose.position.y, 6.5, 1e-9);
  EXPECT_NEAR(car.pose.position.z, 0.75, 1e-9);
  EXPECT_DOUBLE_EQ(car.scale.y, 2);
  EXPECT_FLOAT_EQ(car.color.b, 1.0f);
  EXPECT_FLOAT_EQ(array.markers[2].color.r, 1.0f);
  EXPECT_NE(array.markers[1].id, array.markers[2].id);
}

TEST(RosRoadUsers, ColoursDiffer) {
  const auto car = category_colour("car"), bus = category_colour("bus");
  const auto other = category_colour("spaceship");
  EXPECT_NE(car.r, bus.r);
  EXPECT_FLOAT_EQ(other.r, other.g);
  EXPECT_FLOAT_EQ(car.a, 0.8f);
}

TEST(RosEvents, OnePerItem) {
  const json value = {{"events",
                       {{{"kind", "collision"},
                         {"actor", "ego"},
                         {"other", "p1"},
                         {"severity", 3.5},
                         {"detail", {{"x", 1}}}},
                        {{"kind", "red_light"}, {"actor", "ego"}}}}};
  const auto list = events(value, at(3));
  ASSERT_EQ(list.size(), 2u);
  EXPECT_EQ(list[0].kind, "collision");
  EXPECT_EQ(list[0].other, "p1");
  EXPECT_DOUBLE_EQ(list[0].severity, 3.5);
  EXPECT_EQ(list[0].detail, "{\"x\":1}");
  EXPECT_EQ(list[1].other, "");
  EXPECT_EQ(list[1].header.stamp, at(3));
  EXPECT_THROW(events(json{{"events", {1}}}, at(0)), std::invalid_argument);
  EXPECT_THROW(events(json{{"events", {{{"kind", 1}}}}}, at(0)), std::invalid_argument);
}

TEST(RosPath, PointsWithOptionalHeightAndYaw) {
  const nav_msgs::Path p = path(json{{"path", {{0, 0}, {1, 2, 0.5, M_PI}}}}, Frames{}, at(0));
  ASSERT_EQ(p.poses.size(), 2u);
  EXPECT_EQ(p.header.frame_id, "map");
  EXPECT_DOUBLE_EQ(p.poses[1].pose.position.z, 0.5);
  EXPECT_NEAR(p.poses[1].pose.orientation.z, 1.0, 1e-9);
  EXPECT_THROW(path(json{{"path", {{1}}}}, Frames{}, at(0)), std::invalid_argument);
  EXPECT_THROW(path(json{{"path", {{1, "a"}}}}, Frames{}, at(0)), std::invalid_argument);
}

TEST(RosMessagesAsJson, ControlAndTwists) {
  convoy_msgs::Control c;
  c.throttle = 0.5;
  c.brake = 0.1;
  c.steer = -0.2;
  c.reverse = true;
  c.header.stamp = at(1.5);
  EXPECT_EQ(
      control_json(c),
      (json{
          {"throttle", 0.5}, {"brake", 0.1}, {"steer", -0.2}, {"reverse", true}, {"stamp", 1.5}}));
  geometry_msgs::TwistStamped t;
  t.twist.linear.x = 2;
  t.twist.angular.z = 0.3;
  t.header.stamp = at(0.25);
  EXPECT_EQ(twist_json(t.twist), (json{{"linear", {2.0, 0.0, 0.0}}, {"angular", {0.0, 0.0, 0.3}}}));
  EXPECT_EQ(twist_stamped_json(t)["stamp"], 0.25);
}

}  // namespace
}  // namespace convoy::ros_bridge
