// A LiDAR's parameters as SDF 1.7 declares them: <sensor type="lidar|gpu_lidar|ray|gpu_ray">
// with a <lidar> (or <ray>) element holding <scan><horizontal>, <scan><vertical>, <range> and
// <noise>, and the sensor's <update_rate>. The immutable description of one sensor; the
// scanning lives in lidar_sensor.h.
//
// Ray layout (as gz-sensors): a scan axis of `samples` rays spans [min_angle, max_angle]
// inclusive, ray i at min + i (max - min) / (samples - 1) (one ray: min_angle). Horizontal
// angles are azimuths about the sensor's +z from its +x (counter-clockwise), vertical ones
// elevations above its x-y plane. Ring r of a scan is vertical sample r (ring 0 the lowest).
// `resolution` (SDF: rays per sample for interpolation) is validated and kept; the sensor
// casts one ray per sample, as gz-sensors' range count does.
#pragma once

#include <sdf/Element.hh>
#include <string>

namespace convoy::lidar {

struct ScanAxis {
  int samples = 1;
  double resolution = 1;
  double min_angle = 0, max_angle = 0;  // radians

  // Angle of ray i (0 <= i < samples).
  double angle(int i) const {
    return samples > 1 ? min_angle + i * (max_angle - min_angle) / (samples - 1) : min_angle;
  }
};

struct LidarModel {
  ScanAxis horizontal{640, 1, 0, 0};
  ScanAxis vertical{1, 1, 0, 0};
  double range_min = 0, range_max = 0, range_resolution = 0;  // metres
  bool gaussian_noise = false;              // <noise><type>gaussian</type>: added to each range
  double noise_mean = 0, noise_stddev = 0;  // metres
  double update_rate = 0;                   // Hz; 0: every step

  int rays() const { return horizontal.samples * vertical.samples; }

  // Throws std::invalid_argument naming the offending field and value, e.g.
  // "<lidar><scan><horizontal><samples>: must be at least 1, got 0". The world engine
  // prefixes the model, link and sensor.
  void validate() const;
};

// Reads a <sensor> element of type lidar, gpu_lidar, ray or gpu_ray (its <lidar> or <ray>
// child; SDF's defaults for what is missing) and validates it. Throws std::invalid_argument for
// another sensor type or bad values (the message names the element).
LidarModel parse_lidar(const sdf::ElementPtr& sensor);

// True for the sensor types parse_lidar reads.
bool is_lidar_type(const std::string& type);

}  // namespace convoy::lidar
