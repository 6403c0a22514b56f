// Paint on the road that is not a lane's road mark: stop lines, crosswalks and parking bays,
// from the map's signals and objects. Drawn into the road's white-mark part.
#pragma once

#include <string>
#include <utility>

#include "opendrive/network.h"
#include "worldgen/world_plan.h"

namespace convoy::worldgen {

inline constexpr double kPaintHeight = 0.013;  // above the surface: over the lanes' marks

Part& white_paint(WorldPlan& plan);

// The t range [lo, hi] covered by lanes from_lane..to_lane (inclusive, any order) at s.
std::pair<double, double> lane_span(const opendrive::Road& road, double s, int from_lane,
                                    int to_lane);
// The t range of the lanes a signal applies to: its <validity>, else the lanes of its
// orientation (+: right lanes under RHT, left under LHT; -: the others; none: all), sidewalks
// left out.
std::pair<double, double> signal_span(const opendrive::Road& road, const opendrive::Signal& sig);

// A painted band over [s0, s1] x [t0, t1], following the road.
void paint_band(Part& paint, const opendrive::Road& road, double s0, double s1, double t0,
                double t1);
// Zebra stripes over [s0, s1] x [t0, t1]: bars along s, `bar` wide with `gap` between them.
void paint_zebra(Part& paint, const opendrive::Road& road, double s0, double s1, double t0,
                 double t1, double bar = 0.5, double gap = 0.5);
// A lane arrow centred at (s, t), 5 m long, pointing along s (dir +1) or against it (-1):
// `directions` names its heads ("straight", "left", "right", or several joined by '_').
void paint_arrow(Part& paint, const opendrive::Road& road, double s, double t, int dir,
                 const std::string& directions);
// The outline of a rectangle in world coordinates (corners counter-clockwise), lines `width`.
void paint_outline(Part& paint, const std::vector<Vec3>& corners, double width);

}  // namespace convoy::worldgen
