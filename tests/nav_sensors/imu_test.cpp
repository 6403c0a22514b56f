// Unit tests of src/nav_sensors/imu_model.*: what an IMU reads in known motions.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "nav_sensors/imu_model.h"

using convoy::nav_sensors::ImuModel;
using convoy::nav_sensors::ImuParams;
using convoy::nav_sensors::ImuSample;
using convoy::nav_sensors::NoiseParams;
using convoy::nav_sensors::VelocityDifferentiator;

namespace {

const Eigen::Vector3d kGravity(0, 0, -9.8);

void expect_near(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double tol = 1e-12) {
  EXPECT_LT((a - b).norm(), tol) << a.transpose() << " vs " << b.transpose();
}

}  // namespace

TEST(Imu, LevelAtRestReadsGravityUpwards) {
  ImuModel imu(ImuParams{}, kGravity, 1);
  const auto r = imu.measure(ImuSample{}, 0.01);
  expect_near(r.linear_acceleration, {0, 0, 9.8});
  expect_near(r.angular_velocity, {0, 0, 0});
  EXPECT_TRUE(r.has_orientation);
}

TEST(Imu, RolledNinetyDegreesGravityMovesToAnotherAxis) {
  ImuModel imu(ImuParams{}, kGravity, 1);
  ImuSample s;
  s.rotation = Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitX());
  // The sensor's y axis now points up: the reaction to gravity reads on +y.
  expect_near(imu.measure(s, 0.01).linear_acceleration, {0, 9.8, 0}, 1e-9);
}

TEST(Imu, TurningAndBrakingReadInTheSensorsAxes) {
  ImuModel imu(ImuParams{}, kGravity, 1);
  ImuSample s;  // heading north (sensor x = world y), yawing left, braking at 3 m/s^2
  s.rotation = Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitZ());
  s.angular_velocity = {0, 0, 0.4};
  s.linear_acceleration = {0, -3, 0};
  const auto r = imu.measure(s, 0.01);
  expect_near(r.angular_velocity, {0, 0, 0.4}, 1e-12);
  expect_near(r.linear_acceleration, {-3, 0, 9.8}, 1e-9);
  EXPECT_TRUE(r.orientation.isApprox(s.rotation));
}

TEST(Imu, NoiseActsPerAxisAndOrientationCanBeOff) {
  ImuParams p;
  p.orientation = false;
  p.angular_velocity[2].type = NoiseParams::Type::gaussian;
  p.angular_velocity[2].bias_mean = 0.01;
  ImuModel imu(p, kGravity, 3);
  const auto r = imu.measure(ImuSample{}, 0.01);
  EXPECT_FALSE(r.has_orientation);
  EXPECT_EQ(r.angular_velocity.x(), 0.0);
  EXPECT_DOUBLE_EQ(std::abs(r.angular_velocity.z()), 0.01);
}

TEST(Imu, BadNoiseNamesTheChannel) {
  ImuParams p;
  p.linear_acceleration[1].type = NoiseParams::Type::gaussian;
  p.linear_acceleration[1].stddev = -2;
  try {
    ImuModel imu(p, kGravity, 0);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()).rfind("linear_acceleration y: stddev", 0), 0u) << e.what();
  }
}

TEST(Imu, VelocityDifferences) {
  VelocityDifferentiator d;
  expect_near(d.update({1, 0, 0}, 0.01), {0, 0, 0});
  expect_near(d.update({1.02, 0, 0}, 0.01), {2, 0, 0}, 1e-9);
  d.reset();
  expect_near(d.update({5, 0, 0}, 0.01), {0, 0, 0});  // nothing to difference yet
}
