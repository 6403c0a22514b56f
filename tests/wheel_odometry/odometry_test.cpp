// Wheel odometry: straight and circular driving integrate to the right pose, the steering
// angle's yaw rate, scale error and slip noise, determinism, bad parameters.
#include <gtest/gtest.h>

#include <cmath>

#include "wheel_odometry/odometry_model.h"

using namespace convoy::wheel_odometry;

TEST(WheelOdometry, StraightAndCircle) {
  OdometryParams p;
  p.wheel_radius = 0.3;
  p.track = 1.5;
  OdometryModel straight(p, 1);
  for (int i = 0; i < 100; ++i) straight.update(10 / 0.3, 10 / 0.3, 0, 0.01);  // 10 m/s, 1 s
  EXPECT_NEAR(straight.state().x, 10, 1e-9);
  EXPECT_NEAR(straight.state().y, 0, 1e-12);
  EXPECT_NEAR(straight.state().speed, 10, 1e-12);
  EXPECT_NEAR(straight.state().distance, 10, 1e-9);
  // a circle of radius 10 m at 5 m/s: the rear wheels at 10 -+ 0.75 m
  OdometryModel circle(p, 1);
  const double w = 5.0 / 10, left = w * (10 - 0.75) / 0.3, right = w * (10 + 0.75) / 0.3;
  const int steps = static_cast<int>(std::round(M_PI / w / 0.001));  // half a turn
  for (int i = 0; i < steps; ++i) circle.update(left, right, 0, 0.001);
  EXPECT_NEAR(circle.state().yaw_rate, 0.5, 1e-9);
  EXPECT_NEAR(std::abs(circle.state().yaw), M_PI, 1e-3);
  EXPECT_NEAR(circle.state().x, 0, 1e-3);
  EXPECT_NEAR(circle.state().y, 20, 1e-3);
}

TEST(WheelOdometry, SteeringGivesTheYawRateWithAWheelbase) {
  OdometryParams p;
  p.wheelbase = 2.7;
  OdometryModel m(p, 1);
  m.update(10 / 0.3, 10 / 0.3, 0.1, 0.01);
  EXPECT_NEAR(m.state().yaw_rate, 10 * std::tan(0.1) / 2.7, 1e-12);
  EXPECT_DOUBLE_EQ(m.state().steering, 0.1);
}

TEST(WheelOdometry, ScaleErrorAndSlipAreSeeded) {
  OdometryParams p;
  p.scale_stddev = 0.01;
  p.slip_stddev = 0.05;
  OdometryModel a(p, 7), b(p, 7), c(p, 8);
  EXPECT_NE(a.scale(0), 1.0);
  EXPECT_NE(a.scale(0), a.scale(1));
  EXPECT_EQ(a.scale(0), b.scale(0));
  EXPECT_NE(a.scale(0), c.scale(0));
  double err = 0;
  for (int i = 0; i < 1000; ++i) {
    a.update(10, 10, 0, 0.01);
    b.update(10, 10, 0, 0.01);
    c.update(10, 10, 0, 0.01);
    err += std::pow(a.state().speed - 3 * 0.5 * (a.scale(0) + a.scale(1)), 2);
  }
  EXPECT_EQ(a.state().x, b.state().x);
  EXPECT_NE(a.state().x, c.state().x);
  EXPECT_NEAR(std::sqrt(err / 1000), 0.05 / std::sqrt(2.0), 0.005);  // mean of two wheels
  a.reset();
  EXPECT_EQ(a.state().x, 0);
  EXPECT_EQ(a.scale(0), b.scale(0));
}

TEST(WheelOdometry, BadParametersNameTheField) {
  OdometryParams p;
  p.wheel_radius = 0;
  EXPECT_THROW(OdometryModel(p, 1), std::invalid_argument);
  try {
    p.validate();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("wheel_radius: must be > 0 m"), std::string::npos);
  }
}
