#include "nav_sensors/geodetic.h"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace convoy::nav_sensors {

namespace {

constexpr double kA = 6378137.0;                 // WGS84 semi-major axis, m
constexpr double kF = 1.0 / 298.257223563;       // flattening
constexpr double kE2 = kF * (2.0 - kF);          // first eccentricity squared
constexpr double kDeg = std::numbers::pi / 180;  // radians per degree

double prime_vertical_radius(double sin_lat) { return kA / std::sqrt(1 - kE2 * sin_lat * sin_lat); }

void require(bool ok, const char* field, double v, const char* what) {
  if (!ok) throw std::invalid_argument(std::string(field) + ": " + std::to_string(v) + " " + what);
}

}  // namespace

void check(const GeoOrigin& o) {
  require(std::isfinite(o.latitude_deg) && std::abs(o.latitude_deg) <= 90, "latitude_deg",
          o.latitude_deg, "is not within [-90, 90]");
  require(std::isfinite(o.longitude_deg) && std::abs(o.longitude_deg) <= 180, "longitude_deg",
          o.longitude_deg, "is not within [-180, 180]");
  require(std::isfinite(o.elevation_m), "elevation", o.elevation_m, "is not finite");
  require(std::isfinite(o.heading_deg), "heading_deg", o.heading_deg, "is not finite");
}

Eigen::Vector3d geodetic_to_ecef(const Geodetic& g) {
  const double lat = g.latitude_deg * kDeg, lon = g.longitude_deg * kDeg;
  const double n = prime_vertical_radius(std::sin(lat));
  const double r = (n + g.altitude_m) * std::cos(lat);
  return {r * std::cos(lon), r * std::sin(lon), (n * (1 - kE2) + g.altitude_m) * std::sin(lat)};
}

Geodetic ecef_to_geodetic(const Eigen::Vector3d& e) {
  const double p = std::hypot(e.x(), e.y());
  double lat = std::atan2(e.z(), p * (1 - kE2));
  for (int i = 0; i < 8; ++i) {  // converges to well under a millimetre in 3-4
    const double s = std::sin(lat);
    const double n = prime_vertical_radius(s);
    lat = std::atan2(e.z() + kE2 * n * s, p);
  }
  const double s = std::sin(lat), c = std::cos(lat);
  const double h = p * c + e.z() * s - kA * std::sqrt(1 - kE2 * s * s);
  return {lat / kDeg, std::atan2(e.y(), e.x()) / kDeg, h};
}

GeoFrame::GeoFrame(const GeoOrigin& origin) : origin_(origin) {
  check(origin_);
  origin_ecef_ = geodetic_to_ecef({origin.latitude_deg, origin.longitude_deg, origin.elevation_m});
  const double lat = origin.latitude_deg * kDeg, lon = origin.longitude_deg * kDeg;
  const double sl = std::sin(lat), cl = std::cos(lat), so = std::sin(lon), co = std::cos(lon);
  enu_to_ecef_.col(0) << -so, co, 0;
  enu_to_ecef_.col(1) << -sl * co, -sl * so, cl;
  enu_to_ecef_.col(2) << cl * co, cl * so, sl;
  // SDF: heading turns the world frame about the downward vertical (north towards east).
  cos_h_ = std::cos(-origin.heading_deg * kDeg);
  sin_h_ = std::sin(-origin.heading_deg * kDeg);
}

Eigen::Vector3d GeoFrame::to_enu(const Eigen::Vector3d& w) const {
  return {cos_h_ * w.x() - sin_h_ * w.y(), sin_h_ * w.x() + cos_h_ * w.y(), w.z()};
}

Eigen::Vector3d GeoFrame::from_enu(const Eigen::Vector3d& e) const {
  return {cos_h_ * e.x() + sin_h_ * e.y(), -sin_h_ * e.x() + cos_h_ * e.y(), e.z()};
}

Geodetic GeoFrame::to_geodetic(const Eigen::Vector3d& world) const {
  return ecef_to_geodetic(origin_ecef_ + enu_to_ecef_ * to_enu(world));
}

Eigen::Vector3d GeoFrame::to_world(const Geodetic& g) const {
  return from_enu(enu_to_ecef_.transpose() * (geodetic_to_ecef(g) - origin_ecef_));
}

}  // namespace convoy::nav_sensors
