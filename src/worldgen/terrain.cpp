#include "worldgen/terrain.h"

#include <algorithm>
#include <cmath>

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

bool level_lane(const odr::Lane& lane) {
  return lane.id != 0 && lane.type != "none" && lane.type != "sidewalk" && lane.type != "curb" &&
         lane.type != "median";
}

// The t range of the level lanes of a section at s, or false when there are none.
bool level_span(const odr::Road& road, size_t k, double s, double& lo, double& hi) {
  lo = 1e300, hi = -1e300;
  for (const odr::Lane& lane : road.sections[k].lanes) {
    if (!level_lane(lane)) continue;
    const odr::LaneBorders b = road.lane_borders(k, s, lane.id);
    lo = std::min({lo, b.inner, b.outer});
    hi = std::max({hi, b.inner, b.outer});
  }
  return hi - lo > 0.05;
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

std::vector<BoxCollision> road_collision_boxes(const odr::Network& net) {
  constexpr double kThickness = 0.6, kOverlap = 0.3;
  std::vector<BoxCollision> out;
  for (const odr::Road& road : net.roads) {
    for (size_t k = 0; k < road.sections.size(); ++k) {
      const odr::LaneSection& sec = road.sections[k];
      if (sec.s_end - sec.s < 1e-3) continue;
      const auto st = odr::road_stations(road, sec.s, sec.s_end, coarse());
      for (size_t i = 0; i + 1 < st.size(); ++i) {
        const double a = st[i], b = st[i + 1], mid = 0.5 * (a + b);
        double lo, hi;
        if (!level_span(road, k, mid, lo, hi)) continue;
        const double tm = 0.5 * (lo + hi);
        const Vec3 pa = road_point(road, a, tm), pb = road_point(road, b, tm);
        const double dx = pb[0] - pa[0], dy = pb[1] - pa[1], dz = pb[2] - pa[2];
        const double flat = std::hypot(dx, dy);
        if (flat < 1e-3) continue;
        BoxCollision box;
        box.yaw = std::atan2(dy, dx);
        box.pitch = -std::atan2(dz, flat);
        box.roll = road.superelevation_at(mid);
        box.size = {std::hypot(flat, dz) + kOverlap, hi - lo, kThickness};
        // the box's centre: half its thickness under the surface, along its own up
        const double cr = std::cos(box.roll), sr = std::sin(box.roll);
        const double cp = std::cos(box.pitch), sp = std::sin(box.pitch);
        const double cy = std::cos(box.yaw), sy = std::sin(box.yaw);
        // R = Rz(yaw) Ry(pitch) Rx(roll); its third column is the box's up
        const Vec3 up = {cy * sp * cr + sy * sr, sy * sp * cr - cy * sr, cp * cr};
        const Vec3 m = road_point(road, mid, tm);
        box.centre = {m[0] - 0.5 * kThickness * up[0], m[1] - 0.5 * kThickness * up[1],
                      m[2] - 0.5 * kThickness * up[2]};
        out.push_back(box);
      }
    }
  }
  return out;
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
