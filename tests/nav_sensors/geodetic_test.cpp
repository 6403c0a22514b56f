// Unit tests of src/nav_sensors/geodetic.* and navsat_model.*: the WGS84 conversions checked
// against ignition-math's SphericalCoordinates (Gazebo's), round trips, the GNSS noise.
#include "nav_sensors/geodetic.h"

#include <gtest/gtest.h>

#include <cmath>
#include <ignition/math/SphericalCoordinates.hh>

#include "nav_sensors/navsat_model.h"

using convoy::nav_sensors::GeoFrame;
using convoy::nav_sensors::GeoOrigin;
using convoy::nav_sensors::NavSatModel;
using convoy::nav_sensors::NavSatParams;
using convoy::nav_sensors::NoiseParams;

namespace {

ignition::math::SphericalCoordinates gazebo(const GeoOrigin& o) {
  using ignition::math::Angle;
  return ignition::math::SphericalCoordinates(
      ignition::math::SphericalCoordinates::EARTH_WGS84, Angle(o.latitude_deg * IGN_PI / 180),
      Angle(o.longitude_deg * IGN_PI / 180), o.elevation_m, Angle(o.heading_deg * IGN_PI / 180));
}

constexpr double kMetresPerDegree = 111320.0;  // roughly, for tolerances in degrees

}  // namespace

TEST(Geodetic, AgreesWithGazebosSphericalCoordinates) {
  for (const GeoOrigin o : {GeoOrigin{48.2082, 16.3738, 171, 0}, GeoOrigin{-33.9, 151.2, 5, 0},
                            GeoOrigin{0, 0, 0, 0}, GeoOrigin{48.2082, 16.3738, 171, 30}}) {
    const GeoFrame frame(o);
    const auto sc = gazebo(o);
    for (const Eigen::Vector3d& p :
         {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1000, 0, 0), Eigen::Vector3d(0, 2500, 12),
          Eigen::Vector3d(-7000, 4000, -3)}) {
      const auto g = frame.to_geodetic(p);
      // ignition-math 6's LOCAL frame has x and y negated (gz-math 7 adds LOCAL2 to fix it).
      const auto ref = sc.SphericalFromLocalPosition({-p.x(), -p.y(), p.z()});
      EXPECT_NEAR(g.latitude_deg, ref.X(), 0.001 / kMetresPerDegree) << p.transpose();
      EXPECT_NEAR(g.longitude_deg, ref.Y(), 0.001 / kMetresPerDegree) << p.transpose();
      EXPECT_NEAR(g.altitude_m, ref.Z(), 0.001) << p.transpose();
    }
  }
}

TEST(Geodetic, RoundTripsToTheMillimetre) {
  const GeoFrame frame({48.2082, 16.3738, 171, -20});
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(3, 4, 5), Eigen::Vector3d(-9000, 12000, 40)})
    EXPECT_LT((frame.to_world(frame.to_geodetic(p)) - p).norm(), 1e-3);
  const auto o = frame.to_geodetic(Eigen::Vector3d::Zero());
  EXPECT_NEAR(o.latitude_deg, 48.2082, 1e-9);
  EXPECT_NEAR(o.altitude_m, 171, 1e-6);
}

TEST(Geodetic, BadOriginNamesTheField) {
  try {
    GeoFrame frame({91, 0, 0, 0});
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()).rfind("latitude_deg", 0), 0u) << e.what();
  }
}

TEST(NavSat, WithoutNoiseReadsTheFramesConversion) {
  const GeoFrame frame({48.2082, 16.3738, 171, 0});
  NavSatModel gnss(NavSatParams{}, frame, 1);
  const auto r = gnss.measure({100, 50, 1}, {3, 4, 0}, 0.1);
  const auto g = frame.to_geodetic({100, 50, 1});
  EXPECT_EQ(r.position.latitude_deg, g.latitude_deg);
  EXPECT_EQ(r.position.longitude_deg, g.longitude_deg);
  EXPECT_LT((r.velocity_enu - Eigen::Vector3d(3, 4, 0)).norm(), 1e-12);
}

TEST(NavSat, PositionNoiseIsInMetres) {
  const GeoFrame frame({48.2082, 16.3738, 171, 0});
  NavSatParams p;
  p.position_horizontal.type = NoiseParams::Type::gaussian;
  p.position_horizontal.stddev = 2.0;
  NavSatModel gnss(p, frame, 9);
  double sum2 = 0, up2 = 0;
  const int n = 4000;
  for (int i = 0; i < n; ++i) {
    const auto r = gnss.measure({10, 20, 0}, Eigen::Vector3d::Zero(), 0.1);
    const Eigen::Vector3d w = frame.to_world(r.position);
    sum2 += (w - Eigen::Vector3d(10, 20, 0)).head<2>().squaredNorm();
    up2 += w.z() * w.z();
  }
  EXPECT_NEAR(std::sqrt(sum2 / (2 * n)), 2.0, 0.08);  // per horizontal axis
  EXPECT_LT(std::sqrt(up2 / n), 1e-3);                // vertical: no noise given
}
