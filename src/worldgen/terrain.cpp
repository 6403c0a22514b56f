#include "worldgen/terrain.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <stdexcept>
#include <string>

#include "opendrive/sampling.h"

namespace convoy::worldgen {
namespace {

namespace odr = opendrive;

odr::SamplingOptions coarse() {
  odr::SamplingOptions o;
  o.max_curve_segment = 2.0;
  o.max_straight_segment = 4.0;
  o.max_varying_segment = 2.0;
  o.chord_tolerance = 0.02;
  return o;
}

}  // namespace

bool is_flat(const odr::Network& net, double tolerance) {
  for (const odr::Road& road : net.roads) {
    for (double s : odr::road_stations(road, 0, road.length, coarse())) {
      if (std::abs(road.elevation(s)) > tolerance || std::abs(road.superelevation_at(s)) > 1e-4) {
        return false;
      }
    }
  }
  return true;
}

void add_embankments(const odr::Network& net, double ground_z, MeshSet& road) {
  Part& part = road.part("embankment", {{0.3, 0.42, 0.2}, 0.02, ""});
  for (const odr::Road& r : net.roads) {
    if (r.junction != "-1") continue;
    for (size_t k = 0; k < r.sections.size(); ++k) {
      const odr::LaneSection& sec = r.sections[k];
      if (sec.s_end - sec.s < 1e-3) continue;
      const auto st = odr::road_stations(r, sec.s, sec.s_end, coarse());
      for (int side : {-1, 1}) {
        std::vector<Vec3> top, bottom;
        for (double s : st) {
          double edge = r.lane_offset(s);
          for (const odr::Lane& lane : sec.lanes) {
            if (lane.id == 0 || lane.type == "none" || (lane.id > 0) != (side > 0)) continue;
            const odr::LaneBorders b = r.lane_borders(k, s, lane.id);
            edge = side > 0 ? std::max({edge, b.outer}) : std::min({edge, b.outer});
          }
          const Vec3 t = road_point(r, s, edge);
          const double h = std::max(0.0, t[2] - ground_z);
          top.push_back(t);
          bottom.push_back(road_point(r, s, edge + side * 1.5 * h));
          bottom.back()[2] = std::min(ground_z, t[2]);
        }
        for (size_t i = 0; i + 1 < st.size(); ++i) {
          if (top[i][2] - ground_z < 0.1 && top[i + 1][2] - ground_z < 0.1) continue;
          // the slope faces away from the road: counter-clockwise seen from outside
          if (side > 0) {
            MeshSet::add_quad(part, top[i + 1], bottom[i + 1], bottom[i], top[i]);
          } else {
            MeshSet::add_quad(part, top[i], bottom[i], bottom[i + 1], top[i + 1]);
          }
        }
      }
    }
  }
}

}  // namespace convoy::worldgen
