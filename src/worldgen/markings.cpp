#include "worldgen/markings.h"

#include <algorithm>
#include <cmath>

namespace convoy::worldgen {

namespace odr = opendrive;

Part& white_paint(WorldPlan& plan) {
  return plan.road.part(odr::surface_kind_name(odr::SurfaceKind::kMarkWhite),
                        {odr::surface_kind_colour(odr::SurfaceKind::kMarkWhite), 0.2, ""});
}

std::pair<double, double> lane_span(const odr::Road& road, double s, int from_lane, int to_lane) {
  const odr::LaneSection& sec = road.sections[road.section_index(s)];
  double lo = 1e300, hi = -1e300;
  for (int id = std::min(from_lane, to_lane); id <= std::max(from_lane, to_lane); ++id) {
    if (id == 0 || !sec.find_lane(id)) continue;
    const odr::LaneBorders b = road.lane_borders(s, id);
    lo = std::min({lo, b.inner, b.outer});
    hi = std::max({hi, b.inner, b.outer});
  }
  if (lo > hi) lo = hi = road.lane_offset(s);
  return {lo, hi};
}

std::pair<double, double> signal_span(const odr::Road& road, const odr::Signal& sig) {
  const double s = std::clamp(sig.s, 0.0, road.length);
  if (!sig.validity.empty()) {
    return lane_span(road, s, sig.validity.front().first, sig.validity.front().second);
  }
  const odr::LaneSection& sec = road.sections[road.section_index(s)];
  // the carriageway: lanes that are not sidewalks, on the signal's side
  const bool right_first = road.rule == "RHT";
  const bool plus = sig.orientation == "+";
  const bool minus = sig.orientation == "-";
  int lo_id = 0, hi_id = 0;
  for (const odr::Lane& lane : sec.lanes) {
    if (lane.id == 0 || lane.type == "sidewalk" || lane.type == "none") continue;
    const bool right = lane.id < 0;
    if ((plus && right != right_first) || (minus && right == right_first)) continue;
    lo_id = std::min(lo_id, lane.id);
    hi_id = std::max(hi_id, lane.id);
  }
  return lane_span(road, s, lo_id, hi_id);
}

void paint_band(Part& paint, const odr::Road& road, double s0, double s1, double t0, double t1) {
  s0 = std::clamp(s0, 0.0, road.length);
  s1 = std::clamp(s1, 0.0, road.length);
  if (s1 - s0 < 1e-3 || t1 - t0 < 1e-3) return;
  const int n = std::max(1, static_cast<int>(std::ceil((s1 - s0) / 0.5)));
  for (int i = 0; i < n; ++i) {
    const double a = s0 + (s1 - s0) * i / n, b = s0 + (s1 - s0) * (i + 1) / n;
    MeshSet::add_quad(paint, road_point(road, a, t0, kPaintHeight),
                      road_point(road, b, t0, kPaintHeight), road_point(road, b, t1, kPaintHeight),
                      road_point(road, a, t1, kPaintHeight));
  }
}

void paint_zebra(Part& paint, const odr::Road& road, double s0, double s1, double t0, double t1,
                 double bar, double gap) {
  const double width = t1 - t0;
  if (width <= bar) return;
  const int bars = static_cast<int>(std::floor((width + gap) / (bar + gap)));
  const double margin = 0.5 * (width - (bars * bar + (bars - 1) * gap));
  for (int k = 0; k < bars; ++k) {
    const double a = t0 + margin + k * (bar + gap);
    paint_band(paint, road, s0, s1, a, a + bar);
  }
}

void paint_outline(Part& paint, const std::vector<Vec3>& corners, double width) {
  for (size_t i = 0; i < corners.size(); ++i) {
    const Vec3& a = corners[i];
    const Vec3& b = corners[(i + 1) % corners.size()];
    const double dx = b[0] - a[0], dy = b[1] - a[1], len = std::hypot(dx, dy);
    if (len < 1e-6) continue;
    const double nx = -dy / len * 0.5 * width, ny = dx / len * 0.5 * width;
    const double z = kPaintHeight;
    MeshSet::add_quad(paint, {a[0] - nx, a[1] - ny, a[2] + z}, {b[0] - nx, b[1] - ny, b[2] + z},
                      {b[0] + nx, b[1] + ny, b[2] + z}, {a[0] + nx, a[1] + ny, a[2] + z});
  }
}

}  // namespace convoy::worldgen
