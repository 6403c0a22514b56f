#include "scene/scene_map.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "opendrive/lane_graph.h"
#include "opendrive/parser.h"
#include "opendrive/sampling.h"

namespace convoy::scene {

namespace {

using opendrive::Lane;
using opendrive::LaneSection;
using opendrive::Road;

// A point at lateral offset t of the reference line at s, at the surface's height.
Point3 at(const Road& road, double s, double t) {
  const opendrive::Pose2 p = road.offset_point(s, t);
  return {p.x, p.y, road.surface_z(s, t)};
}

// The stations of one lane section, both ends included.
std::vector<double> stations(const Road& road, const LaneSection& sec, const MapOptions& o) {
  opendrive::SamplingOptions so;
  so.max_curve_segment = o.step_m;
  so.max_varying_segment = o.step_m;
  so.max_straight_segment = o.straight_step_m;
  so.chord_tolerance = 0.02 * o.step_m;
  std::vector<double> s = opendrive::road_stations(road, sec.s, sec.s_end, so);
  if (s.empty() || s.back() < sec.s_end - 1e-6) s.push_back(sec.s_end);
  return s;
}

// The line across lanes at t_fraction of `lane_id` (0: the lane-offset line).
MapLine lane_line(const Road& road, size_t section, const std::vector<double>& ss, int lane_id,
                  double t_fraction, LineKind kind) {
  MapLine line;
  line.kind = kind;
  line.points.reserve(ss.size());
  for (double s : ss) {
    const opendrive::LaneBorders b = road.lane_borders(section, s, lane_id);
    line.points.push_back(at(road, s, b.inner + t_fraction * (b.outer - b.inner)));
  }
  return line;
}

void add_road(const Road& road, const MapOptions& o, std::vector<MapLine>& out) {
  if (road.plan_view.empty()) return;
  const bool in_junction = road.junction != "-1";
  for (size_t i = 0; i < road.sections.size(); ++i) {
    const LaneSection& sec = road.sections[i];
    if (sec.s_end - sec.s < 1e-6) continue;
    const std::vector<double> ss = stations(road, sec, o);
    if (!in_junction) out.push_back(lane_line(road, i, ss, 0, 0.0, LineKind::kBorder));
    for (const Lane& lane : sec.lanes) {
      if (lane.id == 0) continue;
      if (!in_junction && lane.type != "none") {
        const LineKind kind =
            lane.type == "driving" ? LineKind::kBorder : LineKind::kSidewalkBorder;
        out.push_back(lane_line(road, i, ss, lane.id, 1.0, kind));
      }
      if (lane.type == "driving")
        out.push_back(lane_line(road, i, ss, lane.id, 0.5, LineKind::kCentre));
    }
  }
}

std::vector<MapSignal> signals_of(const opendrive::Network& network) {
  std::vector<MapSignal> out;
  try {
    const opendrive::LaneGraph graph(network);
    for (const opendrive::SignalInfo& g : graph.signals()) {
      if (!g.traffic_light && !g.pedestrian_light) continue;
      const double z = g.pose.z + g.signal->z_offset + std::max(g.signal->height, 0.0);
      out.push_back({g.signal->id, {g.pose.x, g.pose.y, z}, g.pedestrian_light});
    }
  } catch (const std::exception&) {
    // A graph that cannot be built (links it cannot follow) leaves the lines without signals.
  }
  return out;
}

}  // namespace

size_t SceneMap::points() const {
  size_t n = 0;
  for (const MapLine& l : lines) n += l.points.size();
  return n;
}

SceneMap build_scene_map(const opendrive::Network& network, const MapOptions& options) {
  SceneMap map;
  map.source = network.source;
  // Every step_m first; over the budget, straight lines as coarse as straight_step_m; then
  // both twice as coarse each time.
  MapOptions o = options;
  o.straight_step_m = o.step_m;
  for (int attempt = 0; attempt < 8; ++attempt) {
    map.lines.clear();
    for (const Road& road : network.roads) add_road(road, o, map.lines);
    if (map.points() <= o.max_points) break;
    if (o.straight_step_m < options.straight_step_m) {
      o.straight_step_m = options.straight_step_m;
    } else {
      o.step_m *= 2;
      o.straight_step_m *= 2;
    }
  }
  map.signals = signals_of(network);
  return map;
}

SceneMap load_scene_map(const std::string& xodr, const MapOptions& options) {
  opendrive::LoadOptions lo;
  lo.skip_bad_roads = true;
  return build_scene_map(opendrive::load(xodr, lo), options);
}

}  // namespace convoy::scene
