// The kinematic bicycle on a straight line and on a circle of radius wheelbase / tan(steer),
// and pure pursuit steering it onto a line.
#include "road_users/bicycle.h"

#include <gtest/gtest.h>

#include <cmath>

#include "road_users/path.h"
#include "road_users/pure_pursuit.h"

namespace convoy::road_users {
namespace {

const KinematicBicycle kCar{2.7};

TEST(Bicycle, StraightAheadWithoutSteering) {
  PlanarPose p{1, 2, 0.3};
  for (int i = 0; i < 100; ++i) {
    const BicycleMotion m = step_bicycle(kCar, p, 10, 0, 0.1);
    EXPECT_EQ(m.yaw_rate, 0);
    p = m.pose;
  }
  EXPECT_NEAR(p.x, 1 + 100 * std::cos(0.3), 1e-9);
  EXPECT_NEAR(p.y, 2 + 100 * std::sin(0.3), 1e-9);
  EXPECT_DOUBLE_EQ(p.yaw, 0.3);
}

TEST(Bicycle, ConstantSteerDrivesACircle) {
  // steer 0.2 rad: R = 2.7 / tan(0.2) = 13.3195 m, yaw rate v / R. Each step is a chord of
  // v dt along the heading at mid-step, so the poses lie exactly on the circle of radius
  // R' = v dt / (2 sin(w dt / 2)) = 13.31971 m through the start, centred to its left.
  const double v = 5, dt = 0.05, steer = 0.2;
  const double radius = 2.7 / std::tan(steer);
  EXPECT_NEAR(radius, 13.319518, 1e-6);
  const double w = v / radius;
  const double chord_radius = v * dt / (2 * std::sin(w * dt / 2));
  EXPECT_NEAR(chord_radius, 13.319714, 1e-6);
  PlanarPose p{0, 0, 0};
  double turned = 0;
  for (int i = 0; i < 1000; ++i) {
    const BicycleMotion m = step_bicycle(kCar, p, v, steer, dt);
    EXPECT_NEAR(m.yaw_rate, w, 1e-12);
    turned += m.yaw_rate * dt;
    p = m.pose;
    ASSERT_NEAR(std::hypot(p.x, p.y - chord_radius), chord_radius, 1e-9) << "step " << i;
    ASSERT_NEAR(std::remainder(p.yaw - turned, 2 * M_PI), 0, 1e-9);
  }
  // 50 s at 0.37539 rad/s: 2.99 turns; the heading wraps to [-pi, pi].
  EXPECT_NEAR(turned, 50 * w, 1e-9);
  EXPECT_LE(std::abs(p.yaw), M_PI);
  // Steering right: the mirror image.
  const BicycleMotion right = step_bicycle(kCar, {0, 0, 0}, v, -steer, dt);
  EXPECT_NEAR(right.yaw_rate, -w, 1e-12);
  EXPECT_NEAR(right.pose.y, -v * dt * std::sin(w * dt / 2), 1e-12);
}

TEST(PurePursuit, LookaheadGrowsWithSpeed) {
  const PurePursuit pp;
  EXPECT_DOUBLE_EQ(pp.lookahead(0), 4.0);  // the minimum
  EXPECT_DOUBLE_EQ(pp.lookahead(2.5), 4.0);
  EXPECT_DOUBLE_EQ(pp.lookahead(10), 10.0);  // 0.8 * 10 + 2
}

TEST(PurePursuit, SteersOnAnArcThroughTheTarget) {
  const PurePursuit pp;
  // Target (10, 2) from the origin heading +x: alpha = atan(0.2), ld = sqrt(104);
  // steer = atan(2 * 2.7 sin(alpha) / ld) = atan(0.103846) = 0.103475.
  const double alpha = std::atan2(2.0, 10.0);
  EXPECT_NEAR(pp.steer({0, 0, 0}, 10, 2, 2.7),
              std::atan(2 * 2.7 * std::sin(alpha) / std::sqrt(104.0)), 1e-12);
  EXPECT_NEAR(pp.steer({0, 0, 0}, 10, 2, 2.7), 0.103475, 1e-6);
  EXPECT_NEAR(pp.steer({0, 0, 0}, 10, -2, 2.7), -0.103475, 1e-6);
  // Straight ahead: none. Right beside it: as far as it goes.
  EXPECT_NEAR(pp.steer({3, 4, 0.5}, 3 + 10 * std::cos(0.5), 4 + 10 * std::sin(0.5), 2.7), 0, 1e-12);
  EXPECT_DOUBLE_EQ(pp.steer({0, 0, 0}, 0, 5, 2.7), 0.6);
  EXPECT_DOUBLE_EQ(pp.steer({0, 0, 0}, 0, -5, 2.7), -0.6);
}

TEST(PurePursuit, TargetPastThePathsEnd) {
  const Path line = polyline_path({{0, 0}, {10, 0}}, 0.5, 0, 0);
  const auto on = pursuit_target(line, 15, true);
  EXPECT_NEAR(on.x, 15, 1e-12);
  EXPECT_NEAR(on.y, 0, 1e-12);
  const auto held = pursuit_target(line, 15, false);
  EXPECT_NEAR(held.x, 10, 1e-12);
  EXPECT_NEAR(pursuit_target(line, 4.25, true).x, 4.25, 1e-12);
}

TEST(PurePursuit, ConvergesOntoALine) {
  // 2 m left of a line along +x, parallel to it, at 10 m/s, steps of 50 ms.
  const Path line = polyline_path({{-10, 0}, {500, 0}}, 0.5, 0, 0);
  const PurePursuit pp;
  PlanarPose p{0, 2, 0};
  double lowest = 0;
  for (int i = 1; i <= 400; ++i) {
    const double arc = line.project(p.x, p.y).arc;
    const double steer = pursue(pp, kCar, line, arc, p, 10, false);
    p = step_bicycle(kCar, p, 10, steer, 0.05).pose;
    lowest = std::min(lowest, p.y);
    if (i == 20) {
      EXPECT_NEAR(p.y, 1.2774, 1e-3);  // halfway after 1 s
      EXPECT_NEAR(p.yaw, -0.1030, 1e-3);
    }
    if (i == 200) {
      EXPECT_LT(std::abs(p.y), 1e-3);  // on it after 10 s
    }
  }
  EXPECT_GT(lowest, -0.1);  // overshoots by 8.6 cm at most
  EXPECT_LT(lowest, -0.05);
  EXPECT_LT(std::abs(p.y), 1e-5);
  EXPECT_LT(std::abs(p.yaw), 1e-6);
  EXPECT_NEAR(p.x, 199.92, 0.01);  // 20 s at 10 m/s, 8 cm of it sideways
}

}  // namespace
}  // namespace convoy::road_users
