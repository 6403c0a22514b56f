// The ros_bridge engine's config (engines/ros_bridge/bridge_config.h).
#include "bridge_config.h"

#include <gtest/gtest.h>

#include <stdexcept>

namespace convoy::ros_bridge {
namespace {

using nlohmann::json;

// The schema's defaults, as the coordinator fills them in.
json defaults() {
  return {{"NodeName", "convoy"},
          {"MasterURI", ""},
          {"StartMaster", true},
          {"Synchronous", true},
          {"SyncTopic", "/convoy/control"},
          {"SyncTimeout", 10},
          {"Subscribe",
           {{{"Topic", "/convoy/control"}, {"Type", "convoy_msgs/Control"}},
            {{"Topic", "/cmd_vel"}, {"Type", "geometry_msgs/Twist"}}}},
          {"PublishClock", true},
          {"MapFrame", "map"},
          {"BaseFrame", "base_link"},
          {"CameraFrame", "camera"},
          {"CameraHorizontalFov", 1.57}};
}

std::string error_of(const json& config) {
  try {
    parse_config(config);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(RosBridgeConfig, Defaults) {
  const BridgeConfig c = parse_config(defaults());
  EXPECT_EQ(c.node_name, "convoy");
  ASSERT_EQ(c.subscribe.size(), 2u);
  EXPECT_EQ(c.subscribe[0].type, InType::kControl);
  EXPECT_EQ(c.subscribe[1].type, InType::kTwist);
  EXPECT_DOUBLE_EQ(c.sync_timeout_s, 10);
  EXPECT_EQ(c.frames.base, "base_link");
}

TEST(RosBridgeConfig, SyncTopicMustBeSubscribed) {
  json c = defaults();
  c["SyncTopic"] = "/other";
  const std::string e = error_of(c);
  EXPECT_EQ(e.rfind("SyncTopic: \"/other\" is not one of the Subscribe topics", 0), 0u) << e;
  c["Synchronous"] = false;
  EXPECT_EQ(error_of(c), "");
}

TEST(RosBridgeConfig, BadValuesNameTheirKey) {
  json c = defaults();
  c["SyncTimeout"] = 0;
  EXPECT_EQ(error_of(c).rfind("SyncTimeout:", 0), 0u);
  c = defaults();
  c["Subscribe"][1]["Type"] = "std_msgs/String";
  EXPECT_EQ(error_of(c).rfind("Subscribe/1/Type: unsupported type \"std_msgs/String\"", 0), 0u);
  c = defaults();
  c["Subscribe"][1]["Topic"] = "/convoy/control";
  EXPECT_EQ(error_of(c).rfind("Subscribe/1/Topic:", 0), 0u);
  c = defaults();
  c["Subscribe"][1]["Topic"] = "/cmd vel";
  EXPECT_EQ(error_of(c).rfind("Subscribe/1/Topic:", 0), 0u);
  c = defaults();
  c["NodeName"] = "a/b";
  EXPECT_EQ(error_of(c).rfind("NodeName:", 0), 0u);
}

TEST(RosBridgeConfig, RosNames) {
  for (const char* good : {"/convoy/control", "cmd_vel", "~private", "/a1/b_2"})
    EXPECT_EQ(name_problem(good), "") << good;
  for (const char* bad : {"", "/", "a//b", "a/", "1abc", "/a/1b", "a b", "a-b"})
    EXPECT_NE(name_problem(bad), "") << bad;
}

}  // namespace
}  // namespace convoy::ros_bridge
