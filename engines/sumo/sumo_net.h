// The SUMO network of a `sumo` engine, and the conversions between SUMO's frame and the map's.
//
// SUMO keeps positions in net coordinates: the map's (the .xodr's) shifted by the net's
// `<location netOffset="x,y">`, which netconvert chooses so that the network starts near the
// origin. A SUMO vehicle's position is the centre of its front bumper and its angle is in
// degrees clockwise from north; a road user's (proto/convoy/road_users.proto) is the centre
// of the rear axle and its yaw in radians counter-clockwise from +x.
#pragma once

#include <filesystem>
#include <string>

namespace convoy::engines::sumo {

// Where the rear axle sits, as a fraction of the length from the rear bumper. SUMO's vTypes
// have no wheelbase; a quarter of the length is a typical rear overhang (1.1 m for a 4.5 m
// car, 3 m for a 12 m bus).
inline constexpr double kRearAxleFraction = 0.25;

struct NetOffset {
  double x = 0, y = 0;
};

// The netOffset of a .net.xml (0,0 when the file has no <location>).
NetOffset read_net_offset(const std::filesystem::path& net_file);

// The .net.xml made by netconvert from `xodr`, cached as `<cache_dir>/<hash>.net.xml` where
// the hash is that of the .xodr's bytes (and of netconvert's options): an unchanged .xodr is
// converted once. Throws with netconvert's output when it fails.
std::filesystem::path convert_opendrive(const std::filesystem::path& xodr,
                                        const std::filesystem::path& cache_dir);

// $XDG_CACHE_HOME/convoy/sumo, or ~/.cache/convoy/sumo.
std::filesystem::path default_cache_dir();

// SUMO's angle (degrees clockwise from north) <-> yaw (radians, counter-clockwise from +x),
// yaw in (-pi, pi], angle in [0, 360).
double yaw_from_sumo_angle(double angle_deg);
double sumo_angle_from_yaw(double yaw);

}  // namespace convoy::engines::sumo
