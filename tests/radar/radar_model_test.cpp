// The radar's model without a scene: RCS by class and size, detection probability, one scan's
// returns (geometry, range rate, field of view, noise, clutter), determinism, SDF parameters.
#include "radar/radar_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <sdf/Link.hh>
#include <sdf/Model.hh>
#include <sdf/Root.hh>
#include <sdf/Sensor.hh>

#include "radar/radar_detect.h"

using namespace convoy::radar;

namespace {

RadarParams quiet() {  // no noise, no clutter
  RadarParams p;
  p.range_stddev = p.azimuth_stddev = p.elevation_stddev = p.range_rate_stddev = 0;
  p.rcs_stddev = 0;
  p.clutter = 0;
  return p;
}

Target car(uint32_t id, Eigen::Vector3d centre, Eigen::Vector3d velocity = {0, 0, 0}) {
  Target t;
  t.id = id;
  t.cls = "car";
  t.centre = centre;
  t.size = {4.5, 1.8, 1.5};
  t.velocity = velocity;
  return t;
}

}  // namespace

TEST(RadarModel, RcsByClassAndSize) {
  EXPECT_NEAR(rcs_dbsm("car", 4.5, 1.8, 1.5), 10, 1e-9);
  EXPECT_NEAR(rcs_dbsm("bus", 12, 2.5, 3.2), 20, 1e-9);
  EXPECT_NEAR(rcs_dbsm("truck", 8, 2.5, 3.2), 20, 1e-9);
  const double walker = rcs_dbsm("pedestrian", 0.5, 0.4, 1.7),
               child = rcs_dbsm("pedestrian", 0.4, 0.3, 1.1);
  EXPECT_GE(walker, -5);
  EXPECT_LE(walker, 0);
  EXPECT_LT(child, walker);
  EXPECT_GT(rcs_dbsm("car", 5.2, 2.0, 1.8), 10);         // a larger car reflects more
  EXPECT_LE(rcs_dbsm("car", 100, 100, 100), 20 + 1e-9);  // within +-10 dB of the class
}

TEST(RadarModel, DetectionProbabilityFallsWithRangeAndRcs) {
  RadarParams p;
  p.max_range = 150;
  EXPECT_NEAR(detection_probability(snr_db(p, 10, 150)), 0.5, 1e-9);  // a car at the reference
  EXPECT_GT(detection_probability(snr_db(p, 10, 50)), 0.999);
  EXPECT_LT(detection_probability(snr_db(p, 10, 200)), 0.05);
  EXPECT_LT(detection_probability(snr_db(p, -3, 100)), detection_probability(snr_db(p, 10, 100)));
}

TEST(RadarDetect, GeometryAndRangeRateOfACar) {
  const RadarParams p = quiet();
  // 20 m ahead, 5 m left, closing at 10 m/s along x
  Target t = car(7, {20, 5, 0}, {-10, 0, 0});
  t.range = 18.5;
  const auto d = detect(p, {t}, Eigen::Vector3d::Zero(), 1, 0);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].id, 7u);
  EXPECT_FALSE(d[0].clutter);
  EXPECT_DOUBLE_EQ(d[0].range, 18.5);
  EXPECT_NEAR(d[0].azimuth, std::atan2(5, 20), 1e-12);
  EXPECT_NEAR(d[0].elevation, 0, 1e-12);
  EXPECT_NEAR(d[0].range_rate, -10 * 20 / std::hypot(20, 5), 1e-12);
  EXPECT_NEAR(d[0].rcs, 10, 1e-9);
}

TEST(RadarDetect, FieldOfViewRangeAndOcclusion) {
  RadarParams p = quiet();
  p.horizontal_fov = 1.0;
  p.max_range = 100;
  Target hidden = car(4, {30, 0, 0});
  hidden.visible_fraction = 0;
  Target half = car(5, {40, 0, 0});
  half.visible_fraction = 0.4;
  const auto d =
      detect(p,
             {car(1, {10, 10, 0}) /* 45 deg: outside */, car(2, {120, 0, 0}) /* far */,
              car(3, {10, 0, 5}) /* above the vertical fov */, hidden, half, car(6, {20, -2, 0})},
             Eigen::Vector3d::Zero(), 1, 0);
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(d[0].id, 6u);  // by range
  EXPECT_EQ(d[1].id, 5u);
  EXPECT_NEAR(d[1].rcs, 10 + 10 * std::log10(0.4), 1e-9);
}

TEST(RadarDetect, NoiseHasTheStandardDeviationsAndIsDeterministic) {
  RadarParams p;
  p.clutter = 0;
  const Target t = car(3, {30, 0, 0}, {2, 0, 0});
  double sr = 0, srr = 0, saz = 0;
  const int n = 4000;
  for (int k = 0; k < n; ++k) {
    const auto d = detect(p, {t}, Eigen::Vector3d::Zero(), 11, k * 50'000'000LL);
    ASSERT_EQ(d.size(), 1u);
    sr += std::pow(d[0].range - 30, 2);
    srr += std::pow(d[0].range_rate - 2, 2);
    saz += std::pow(d[0].azimuth, 2);
  }
  EXPECT_NEAR(std::sqrt(sr / n), p.range_stddev, 0.1 * p.range_stddev);
  EXPECT_NEAR(std::sqrt(srr / n), p.range_rate_stddev, 0.1 * p.range_rate_stddev);
  EXPECT_NEAR(std::sqrt(saz / n), p.azimuth_stddev, 0.1 * p.azimuth_stddev);
  const auto a = detect(p, {t}, Eigen::Vector3d::Zero(), 11, 123);
  const auto b = detect(p, {t}, Eigen::Vector3d::Zero(), 11, 123);
  const auto c = detect(p, {t}, Eigen::Vector3d::Zero(), 12, 123);
  EXPECT_EQ(a[0].range, b[0].range);
  EXPECT_EQ(a[0].range_rate, b[0].range_rate);
  EXPECT_NE(a[0].range, c[0].range);
  // another target in the scan changes nothing of this one's
  const auto with = detect(p, {car(9, {50, 3, 0}), t}, Eigen::Vector3d::Zero(), 11, 123);
  ASSERT_EQ(with.size(), 2u);
  EXPECT_EQ(with[0].range, a[0].range);
}

TEST(RadarDetect, HalfTheCarsAtTheReferenceRange) {
  RadarParams p = quiet();
  p.max_range = 200;
  p.detection_range = 100;
  int seen = 0;
  const int n = 2000;
  for (int k = 0; k < n; ++k) seen += detect(p, {car(1, {100, 0, 0})}, {0, 0, 0}, 5, k).size();
  EXPECT_NEAR(seen / double(n), 0.5, 0.05);
}

TEST(RadarDetect, ClutterIsSeededStandingAndInView) {
  RadarParams p;
  p.clutter = 3;
  const Eigen::Vector3d v(15, 0, 0);  // the sensor drives forward
  size_t count = 0;
  const int n = 1000;
  for (int k = 0; k < n; ++k) {
    const auto d = detect(p, {}, v, 2, k * 1000);
    count += d.size();
    for (const auto& r : d) {
      EXPECT_TRUE(r.clutter);
      EXPECT_EQ(r.id, 0u);
      EXPECT_LE(std::abs(r.azimuth), 0.5 * p.horizontal_fov + 0.03);
      EXPECT_LT(r.range_rate, 0);  // standing ground ahead closes in
      EXPECT_LE(r.range, 60.5);
    }
  }
  EXPECT_NEAR(count / double(n), 3, 0.3);
  const auto a = detect(p, {}, v, 2, 77), b = detect(p, {}, v, 2, 77);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i].range, b[i].range);
  p.clutter = 0;
  EXPECT_TRUE(detect(p, {}, v, 2, 77).empty());
}

namespace {

sdf::ElementPtr plugin(const std::string& body) {
  static std::vector<std::unique_ptr<sdf::Root>> roots;
  roots.push_back(std::make_unique<sdf::Root>());
  const std::string text =
      "<?xml version=\"1.0\"?><sdf version=\"1.7\"><model name=\"m\"><link name=\"l\">"
      "<sensor name=\"radar\" type=\"custom\"><plugin filename=\"convoy_radar\" name=\"r\">" +
      body + "</plugin></sensor></link></model></sdf>";
  EXPECT_TRUE(roots.back()->LoadSdfString(text).empty());
  return roots.back()->Model()->LinkByIndex(0)->SensorByIndex(0)->Element()->GetElement("plugin");
}

}  // namespace

TEST(RadarModel, ParsesThePluginsElements) {
  const RadarParams p = parse_radar(
      plugin("<horizontal_fov>0.8</horizontal_fov><max_range>80</max_range><clutter>0</clutter>"
             "<range_rate_stddev>0.2</range_rate_stddev>"));
  EXPECT_DOUBLE_EQ(p.horizontal_fov, 0.8);
  EXPECT_DOUBLE_EQ(p.max_range, 80);
  EXPECT_DOUBLE_EQ(p.clutter, 0);
  EXPECT_DOUBLE_EQ(p.range_rate_stddev, 0.2);
  EXPECT_DOUBLE_EQ(p.vertical_fov, RadarParams{}.vertical_fov);
  EXPECT_TRUE(is_radar_plugin("convoy_radar"));
  EXPECT_FALSE(is_radar_plugin("libgazebo_ros_camera.so"));
}

TEST(RadarModel, BadValuesNameTheElement) {
  auto message = [](const std::string& body) {
    try {
      parse_radar(plugin(body));
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message("<max_range>0</max_range>"),
            "<max_range>: must be above <min_range> (0.5 m), got 0");
  EXPECT_EQ(message("<horizontal_fov>7</horizontal_fov>"),
            "<horizontal_fov>: must be in (0, 2 pi] rad, got 7");
  EXPECT_EQ(message("<min_range>-1</min_range>"), "<min_range>: must be >= 0 m, got -1");
  EXPECT_EQ(message("<clutter>lots</clutter>"), "<clutter>: must be a number, got 'lots'");
}
