// A radar's parameters and its physics in numbers: the radar cross-section (RCS) of an object
// by class and size, and the probability of detecting it at a range.
//
// Declared in SDF as a custom sensor carrying Convoy's radar plugin (sdformat 12 keeps a
// <plugin>'s children as written; docs/radar.md):
//   <sensor name="radar" type="custom"><update_rate>20</update_rate>
//     <plugin filename="convoy_radar" name="front_radar">
//       <horizontal_fov>1.2</horizontal_fov> <vertical_fov>0.2</vertical_fov>   (rad)
//       <min_range>0.5</min_range> <max_range>150</max_range>                  (m)
//       <range_stddev>0.1</range_stddev> <azimuth_stddev>0.005</azimuth_stddev>
//       <elevation_stddev>0.01</elevation_stddev>
//       <range_rate_stddev>0.1</range_rate_stddev> <rcs_stddev>1</rcs_stddev>
//       <detection_range>150</detection_range>  (m: a 10 dBsm target's 50 % range)
//       <clutter>2</clutter>                    (mean false returns per scan)
//     </plugin></sensor>
// Every element is optional (these are the defaults, detection_range: max_range).
//
// Detection: snr = rcs - 10 + 40 log10(detection_range / range) + kThresholdDb (dB; the
// radar equation's R^-4), P_d = 1 / (1 + exp(-(snr - kThresholdDb) / kSlopeDb)): 0.5 for a
// 10 dBsm car at detection_range, ~1 well inside it, falling fast beyond.
// RCS: the class's typical value (car 10 dBsm, truck and bus 20, pedestrian -3, cyclist 0,
// scenery by kind) scaled by size, + 10 log10((V / V_ref)^(2/3)) within +-10 dB, V the
// object's box volume and V_ref its class's typical one.
#pragma once

#include <sdf/Element.hh>
#include <string>

namespace convoy::radar {

struct RadarParams {
  double horizontal_fov = 1.2, vertical_fov = 0.2;  // rad, full widths about +x
  double min_range = 0.5, max_range = 150;          // m
  double range_stddev = 0.1, azimuth_stddev = 0.005, elevation_stddev = 0.01;  // m, rad
  double range_rate_stddev = 0.1, rcs_stddev = 1.0;                            // m/s, dB
  double detection_range = 0;                                                  // m; 0: max_range
  double clutter = 2;      // mean false returns per scan
  double update_rate = 0;  // Hz; 0: every step

  // Throws std::invalid_argument naming the element, e.g. "<max_range>: must be above
  // <min_range> (0.5 m), got 0".
  void validate() const;
  double reference_range() const { return detection_range > 0 ? detection_range : max_range; }
};

constexpr double kThresholdDb = 13, kSlopeDb = 1.5;

// Reads the radar plugin element's children (the sensor's <update_rate> is set by the
// caller) and validates. Throws std::invalid_argument naming the element for a bad value.
RadarParams parse_radar(const sdf::ElementPtr& plugin);
// True for a <plugin filename> of the radar: "convoy_radar" (lib...so accepted).
bool is_radar_plugin(const std::string& filename);

// dBsm of an object of class `cls` whose box is sx x sy x sz metres.
double rcs_dbsm(const std::string& cls, double sx, double sy, double sz);
double snr_db(const RadarParams& p, double rcs, double range);
double detection_probability(double snr);

}  // namespace convoy::radar
