// The world frame placed on the Earth, as SDF's <spherical_coordinates> places it (surface
// model EARTH_WGS84, world_frame_orientation ENU): the world's origin at a latitude,
// longitude and elevation, its axes east, north and up, turned by heading_deg about the
// downward vertical (positive from north towards east, as SDF defines it).
// Positions convert exactly through the WGS84 ellipsoid (earth-centred coordinates), not a
// flat-earth approximation, so a GNSS reading kilometres from the origin is still right.
#pragma once

#include <Eigen/Core>

namespace convoy::nav_sensors {

struct GeoOrigin {
  double latitude_deg = 0, longitude_deg = 0, elevation_m = 0;
  double heading_deg = 0;
};

struct Geodetic {
  double latitude_deg = 0, longitude_deg = 0, altitude_m = 0;  // altitude above the ellipsoid
};

// Throws std::invalid_argument naming the field for a latitude beyond +-90, a longitude
// beyond +-180 or a value that is not finite.
void check(const GeoOrigin& o);

class GeoFrame {
 public:
  explicit GeoFrame(const GeoOrigin& origin);

  // A world-frame vector in east, north, up components (the heading's turn).
  Eigen::Vector3d to_enu(const Eigen::Vector3d& world) const;
  Eigen::Vector3d from_enu(const Eigen::Vector3d& enu) const;
  // A world-frame position on the Earth, and back.
  Geodetic to_geodetic(const Eigen::Vector3d& world) const;
  Eigen::Vector3d to_world(const Geodetic& g) const;

  const GeoOrigin& origin() const { return origin_; }

 private:
  GeoOrigin origin_;
  Eigen::Vector3d origin_ecef_;
  Eigen::Matrix3d enu_to_ecef_;  // columns: east, north, up at the origin
  double cos_h_ = 1, sin_h_ = 0;
};

// WGS84: geodetic (degrees, metres) <-> earth-centred, earth-fixed (metres).
Eigen::Vector3d geodetic_to_ecef(const Geodetic& g);
Geodetic ecef_to_geodetic(const Eigen::Vector3d& ecef);

}  // namespace convoy::nav_sensors
