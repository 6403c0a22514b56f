// One radar scan from the objects the radar could see (no transport, no scene: the world
// engine finds the targets, their visibility and velocities; radar_targets.h and
// radar_occlusion.h help).
//
// For each target inside the field of view (|azimuth| <= horizontal_fov / 2, |elevation| <=
// vertical_fov / 2 of its centre) and the range limits, with some of it visible: RCS
// rcs_dbsm(class, size) + 10 log10(visible fraction); detected with detection_probability
// (radar_model.h); measured range (to its nearest visible part), azimuth and elevation (of its
// centre), range rate (its velocity relative to the sensor along the line of sight) and RCS,
// each with gaussian noise of the params' standard deviations. Then `clutter` false returns on
// average (a Poisson count): ground or road-side points at random ranges (up to 60 m) and
// azimuths within the field of view, just below the horizon, RCS -15..-5 dBsm, range rate
// that of a standing point as the sensor moves (each past the detection threshold already:
// `clutter` is the mean count reported), with the same noise.
//
// All randomness comes from nav_sensors' counter-based generator keyed by (seed, scan time,
// target id, draw): the same inputs give the same returns bit for bit, whatever the order of
// the targets. Returns by ascending range (ties by id).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "radar/radar_model.h"

namespace convoy::radar {

struct Target {
  uint32_t id = 0;  // ground-truth model id (> 0)
  std::string cls;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();    // sensor frame, m
  Eigen::Vector3d size = Eigen::Vector3d::Ones();      // box extent, m
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // relative to the sensor, sensor frame
  double range = -1;            // to its nearest visible part (< 0: the centre's distance)
  double visible_fraction = 1;  // 0: fully occluded
};

struct Detection {
  double range = 0, azimuth = 0, elevation = 0, range_rate = 0, rcs = 0, snr = 0;
  uint32_t id = 0;  // the target's, 0 for clutter
  bool clutter = false;
};

// Inside the field of view and range limits (before occlusion and detection).
bool in_view(const RadarParams& p, const Eigen::Vector3d& centre);

// `sensor_velocity`: the sensor's own velocity in its frame (for the clutter's range rate).
std::vector<Detection> detect(const RadarParams& p, const std::vector<Target>& targets,
                              const Eigen::Vector3d& sensor_velocity, uint64_t seed,
                              int64_t time_ns);

}  // namespace convoy::radar
