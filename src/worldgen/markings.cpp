#include "worldgen/markings.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

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

namespace {

// Convex pieces of an arrow in its own frame: u forward from its tail (0..5 m), v to its left.
using Piece = std::vector<std::array<double, 2>>;

void add_shaft(std::vector<Piece>& out, double u0, double u1, double half_width) {
  out.push_back({{u0, -half_width}, {u1, -half_width}, {u1, half_width}, {u0, half_width}});
}

// A side arm leaving the shaft at u, its head pointing to side (+1 left, -1 right).
void add_turn(std::vector<Piece>& out, double u, int side) {
  const double w = 0.12, reach = 0.5;
  Piece arm = {{u - w, 0}, {u + w, 0}, {u + w, side * reach}, {u - w, side * reach}};
  Piece head = {{u - 0.4, side * reach}, {u + 0.4, side * reach}, {u, side * (reach + 0.6)}};
  if (side < 0) {  // keep them counter-clockwise
    std::reverse(arm.begin(), arm.end());
    std::reverse(head.begin(), head.end());
  }
  out.push_back(arm);
  out.push_back(head);
}

std::vector<Piece> arrow_pieces(const std::string& directions) {
  const bool straight = directions.find("straight") != std::string::npos;
  const bool left = directions.find("left") != std::string::npos;
  const bool right = directions.find("right") != std::string::npos;
  std::vector<Piece> out;
  if (straight) {
    add_shaft(out, 0, 3.6, 0.12);
    out.push_back({{3.6, -0.4}, {5.0, 0}, {3.6, 0.4}});
  } else {
    add_shaft(out, 0, 3.2, 0.12);
  }
  // Turns leave the shaft near its end, or halfway when the arrow also goes straight on.
  const double at = straight ? 2.0 : 3.0;
  if (left) add_turn(out, at, +1);
  if (right) add_turn(out, at, -1);
  return out;
}

}  // namespace

void paint_arrow(Part& paint, const odr::Road& road, double s, double t, int dir,
                 const std::string& directions) {
  for (const Piece& piece : arrow_pieces(directions)) {
    std::vector<Vec3> corners;
    for (const auto& [u, v] : piece) {
      const double ps = std::clamp(s + dir * (u - 2.5), 0.0, road.length);
      corners.push_back(road_point(road, ps, t + dir * v, kPaintHeight));
    }
    MeshSet::add_convex(paint, corners);
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
