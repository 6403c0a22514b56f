// The detector's input gain (engines/detector/input_gain.h): the same values as
// tools/detector/gain.py gives (tests/unit/test_detector_training.py, Gain).
#include "input_gain.h"

#include <gtest/gtest.h>

#include "detector.h"

namespace convoy::detector {
namespace {

TEST(InputGain, BrightImageLeftAsItIs) {
  cv::Mat day(20, 30, CV_8UC3, cv::Scalar(120, 120, 120));
  cv::Mat out = brighten_image(day, InputGain{});
  EXPECT_EQ(out.data, day.data);
}

TEST(InputGain, DarkImageRaisedToTheTargetMean) {
  cv::Mat dusk(20, 30, CV_8UC3, cv::Scalar(30, 30, 30));
  dusk.at<cv::Vec3b>(0, 0) = cv::Vec3b(250, 250, 250);
  cv::Mat out = brighten_image(dusk, InputGain{90, 8});
  const cv::Scalar m = cv::mean(out);
  EXPECT_NEAR((m[0] + m[1] + m[2]) / 3, 90.0, 1.5);
  EXPECT_EQ(out.at<cv::Vec3b>(0, 0), cv::Vec3b(255, 255, 255));  // saturated
}

TEST(InputGain, StopsAtTheMostGain) {
  cv::Mat night(20, 30, CV_8UC3, cv::Scalar(5, 5, 5));
  EXPECT_EQ(brighten_image(night, InputGain{90, 8}).at<cv::Vec3b>(3, 3), cv::Vec3b(40, 40, 40));
  cv::Mat black(4, 4, CV_8UC3, cv::Scalar(0, 0, 0));
  double lo = 0, hi = 0;
  cv::minMaxLoc(brighten_image(black, InputGain{90, 8}).reshape(1), &lo, &hi);
  EXPECT_EQ(hi, 0.0);
}

TEST(InputGain, LetterboxBrightensTheImageNotThePadding) {
  cv::Mat img(480, 736, CV_8UC3, cv::Scalar(10, 10, 10));
  Letterbox lb;
  cv::Mat out = letterbox_image(img, 448, &lb, 288, InputGain{90, 8});
  EXPECT_EQ(out.at<cv::Vec3b>(100, 0), cv::Vec3b(114, 114, 114));  // the 3 columns of padding
  EXPECT_EQ(out.at<cv::Vec3b>(100, 200), cv::Vec3b(80, 80, 80));
}

TEST(InputGain, ReadFromModelJson) {
  EXPECT_FALSE(input_gain_from_meta(nlohmann::json{{"input_width", 448}}).has_value());
  auto g = input_gain_from_meta(
      nlohmann::json::parse(R"({"brighten": {"target_mean": 80, "max_gain": 4}})"));
  ASSERT_TRUE(g.has_value());
  EXPECT_DOUBLE_EQ(g->target_mean, 80);
  EXPECT_DOUBLE_EQ(g->max_gain, 4);
}

TEST(InputGain, MalformedEntriesNamed) {
  auto message = [](const char* text) {
    try {
      input_gain_from_meta(nlohmann::json::parse(text));
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(R"({"brighten": 3})").find("brighten"), std::string::npos);
  EXPECT_NE(message(R"({"brighten": {"target_mean": 80}})").find("brighten"), std::string::npos);
  EXPECT_NE(
      message(R"({"brighten": {"target_mean": 300, "max_gain": 4}})").find("brighten.target_mean"),
      std::string::npos);
  EXPECT_NE(
      message(R"({"brighten": {"target_mean": 80, "max_gain": 0.5}})").find("brighten.max_gain"),
      std::string::npos);
}

}  // namespace
}  // namespace convoy::detector
