// Which message answers which step, and the timeout message (engines/ros_bridge/sync.h).
#include "sync.h"

#include <gtest/gtest.h>

namespace convoy::ros_bridge {
namespace {

constexpr int64_t kStep = 1'500'000'000;  // the step at t = 1.5 s

TEST(RosSync, StampedAtOrAfterTheStepAnswers) {
  EXPECT_EQ(judge(kStep, kStep, false), SyncVerdict::kAnswers);
  EXPECT_EQ(judge(kStep, kStep, true), SyncVerdict::kAnswers);
  EXPECT_EQ(judge(kStep, kStep + 1, false), SyncVerdict::kAnswers);
}

TEST(RosSync, StampedBeforeTheStepIsLate) {
  EXPECT_EQ(judge(kStep, kStep - 1, true), SyncVerdict::kLate);
  EXPECT_EQ(judge(kStep, 1, true), SyncVerdict::kLate);
}

TEST(RosSync, UnstampedAnswersOnlyWhenItArrivedAfterPublishing) {
  EXPECT_EQ(judge(kStep, 0, true), SyncVerdict::kAnswers);
  EXPECT_EQ(judge(kStep, 0, false), SyncVerdict::kEarlier);
}

TEST(RosSync, TheFirstStep) {
  // At t = 0 a stamp of 0 is "unstamped": only a message after publishing answers.
  EXPECT_EQ(judge(0, 0, false), SyncVerdict::kEarlier);
  EXPECT_EQ(judge(0, 0, true), SyncVerdict::kAnswers);
  EXPECT_EQ(judge(0, 1, false), SyncVerdict::kAnswers);
}

TEST(RosSync, TimeoutNamesTopicTimeAndNoPublisher) {
  const std::string text =
      timeout_message("/convoy/control", kStep, 2, "convoy_msgs/Control", {}, 0);
  EXPECT_EQ(text,
            "no message on /convoy/control for the step at t = 1.5 s within 2 s: nothing "
            "publishes /convoy/control");
}

TEST(RosSync, TimeoutNamesPublishersAndLateMessages) {
  const std::string text = timeout_message("/convoy/control", kStep, 10, "convoy_msgs/Control",
                                           {{"/driver", "/other"}, "convoy_msgs/Control", 1}, 3);
  EXPECT_NE(text.find("published by /driver, /other"), std::string::npos) << text;
  EXPECT_NE(text.find("3 messages stamped before t dropped as late"), std::string::npos) << text;
  EXPECT_NE(text.find("did not answer"), std::string::npos) << text;
}

TEST(RosSync, TimeoutNamesPublishersNotConnected) {
  const std::string text = timeout_message("/convoy/control", kStep, 10, "convoy_msgs/Control",
                                           {{"/dead"}, "convoy_msgs/Control", 0}, 0);
  EXPECT_NE(text.find("published by /dead, but the bridge is connected to none"), std::string::npos)
      << text;
}

TEST(RosSync, TimeoutNamesTypeMismatch) {
  const std::string text = timeout_message("/cmd_vel", kStep, 10, "geometry_msgs/Twist",
                                           {{"/driver"}, "geometry_msgs/TwistStamped"}, 0);
  EXPECT_NE(text.find("topic /cmd_vel is geometry_msgs/TwistStamped on the master; the bridge "
                      "expects geometry_msgs/Twist"),
            std::string::npos)
      << text;
}

TEST(RosSync, TypeMismatch) {
  EXPECT_EQ(type_mismatch("/a", "", "convoy_msgs/Control"), "");
  EXPECT_EQ(type_mismatch("/a", "*", "convoy_msgs/Control"), "");
  EXPECT_EQ(type_mismatch("/a", "convoy_msgs/Control", "convoy_msgs/Control"), "");
  EXPECT_EQ(type_mismatch("/a", "std_msgs/String", "convoy_msgs/Control"),
            "topic /a is std_msgs/String on the master; the bridge expects convoy_msgs/Control");
}

}  // namespace
}  // namespace convoy::ros_bridge
