// The "Sensors" keys of a radar and a wheel odometer (src/config/sensor_keys.h): defaults,
// overrides, and each bad value named with the model, link and sensor.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

#include "config/sensor_keys.h"

using namespace convoy::config;
using nlohmann::json;

namespace {

json entry(const std::string& type, json extra = json::object()) {
  json e = {{"Type", type}, {"Name", "s"}, {"Model", "car"}, {"Link", "base_link"}};
  e.update(extra);
  return {{"Sensors", {e}}};
}

}  // namespace

TEST(RadarConfig, DefaultsAndOverrides) {
  Problems problems;
  auto e =
      read_sensor_entries(entry("radar", {{"RangeMax", 80}, {"Clutter", 0}}), 0.01, "", &problems);
  ASSERT_TRUE(problems.empty()) << problems.front().second;
  ASSERT_EQ(e.size(), 1u);
  EXPECT_DOUBLE_EQ(e[0].update_rate, 20);
  EXPECT_DOUBLE_EQ(e[0].range_max, 80);
  EXPECT_DOUBLE_EQ(e[0].range_min, 0.5);
  EXPECT_DOUBLE_EQ(e[0].h_fov, 1.2);
  EXPECT_DOUBLE_EQ(e[0].clutter, 0);
  e = read_sensor_entries(entry("wheel_odometry", {{"SteeringJoint", "steer"}}), 0.01, "",
                          &problems);
  ASSERT_TRUE(problems.empty());
  EXPECT_EQ(e[0].left_joint, "rear_left_wheel_joint");
  EXPECT_EQ(e[0].steering_joint, "steer");
  EXPECT_DOUBLE_EQ(e[0].update_rate, 50);
}

TEST(RadarConfig, BadValuesNameTheSensor) {
  auto problem = [](const std::string& type, json extra, double step = 0.01) {
    Problems problems;
    const auto e = read_sensor_entries(entry(type, extra), step, "/E", &problems);
    EXPECT_TRUE(e.empty());
    return problems.empty() ? std::string("none")
                            : problems.front().first + " " + problems.front().second;
  };
  const std::string who = "model 'car' link 'base_link' sensor 's': ";
  EXPECT_EQ(problem("radar", {{"RangeMax", 0}}),
            "/E/Sensors/0/RangeMax " + who + "must be above RangeMin (0.5 m), got 0");
  EXPECT_EQ(problem("radar", {{"RangeMin", -2}}),
            "/E/Sensors/0/RangeMin " + who + "must be >= 0 m, got -2");
  EXPECT_EQ(problem("radar", {{"HorizontalFov", 7}}),
            "/E/Sensors/0/HorizontalFov " + who + "must be at most 6.28319 rad, got 7");
  EXPECT_EQ(problem("radar", {{"UpdateRate", 200}}),
            "/E/Sensors/0/UpdateRate " + who +
                "200 Hz is above the engine's step rate (1 / EngineTimestep = 100 Hz)");
  EXPECT_EQ(problem("wheel_odometry", {{"WheelRadius", 0}}),
            "/E/Sensors/0/WheelRadius " + who + "must be > 0 m, got 0");
  EXPECT_EQ(problem("wheel_odometry", {{"LeftJoint", ""}}),
            "/E/Sensors/0/LeftJoint " + who + "must be a non-empty string, got \"\"");
}

TEST(RadarConfig, TheCoordinatorLooksTheOdometersJointsUp) {
  const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::string file = ::testing::TempDir() + "radar_config_" + test->name() + ".sdf";
  {
    std::ofstream out(file);
    out << R"(<sdf version="1.7"><world name="w"><model name="car"><link name="base_link"/>
      <link name="w_l"/><link name="w_r"/>
      <joint name="j_l" type="continuous"><parent>base_link</parent><child>w_l</child></joint>
      <joint name="j_r" type="continuous"><parent>base_link</parent><child>w_r</child></joint>
      </model></world></sdf>)";
  }
  auto problems_of = [&](json extra) {
    json engine = entry("wheel_odometry", extra);
    engine["GazeboWorldFile"] = file;
    Problems problems;
    read_sensor_keys(engine, 0.01, "/E", &problems);
    return problems;
  };
  EXPECT_TRUE(problems_of({{"LeftJoint", "j_l"}, {"RightJoint", "j_r"}}).empty());
  const Problems p = problems_of({{"LeftJoint", "j_l"}, {"RightJoint", "j_x"}});
  ASSERT_EQ(p.size(), 1u);
  EXPECT_EQ(p[0].first, "/E/Sensors/0/RightJoint");
  EXPECT_EQ(p[0].second,
            "model 'car' link 'base_link' sensor 's': model 'car' has no joint 'j_x' (joints: "
            "j_l, j_r)");
  std::remove(file.c_str());
}
