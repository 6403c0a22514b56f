#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "opendrive/network.h"

namespace convoy::opendrive {
namespace {

// Index of the last element whose start (by `key`) is <= s; 0 if none.
template <typename T, typename Key>
size_t last_at_or_before(const std::vector<T>& items, double s, Key key) {
  const auto it = std::upper_bound(items.begin(), items.end(), s,
                                   [&key](double v, const T& item) { return v < key(item); });
  return it == items.begin() ? 0 : static_cast<size_t>(it - items.begin()) - 1;
}

std::string format_s(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", s);
  return buf;
}

}  // namespace

double CubicRecord::value(double s) const {
  const double ds = s - start;
  return a + ds * (b + ds * (c + ds * d));
}

double CubicRecord::slope(double s) const {
  const double ds = s - start;
  return b + ds * (2 * c + ds * 3 * d);
}

double evaluate(const std::vector<CubicRecord>& records, double s, double* slope) {
  if (records.empty()) {
    if (slope) *slope = 0;
    return 0;
  }
  const CubicRecord& r =
      records[last_at_or_before(records, s, [](const CubicRecord& c) { return c.start; })];
  if (slope) *slope = r.slope(s);
  return r.value(s);
}

const Lane* LaneSection::find_lane(int id) const {
  const auto it = std::lower_bound(lanes.begin(), lanes.end(), id,
                                   [](const Lane& lane, int v) { return lane.id < v; });
  return it != lanes.end() && it->id == id ? &*it : nullptr;
}

Pose2 Road::reference(double s) const {
  if (plan_view.empty()) throw std::runtime_error("road " + id + ": no plan view geometry");
  s = std::clamp(s, 0.0, length);
  const Geometry& g =
      plan_view[last_at_or_before(plan_view, s, [](const Geometry& g) { return g.s; })];
  return g.at(s - g.s);
}

double Road::elevation(double s) const { return evaluate(elevation_profile, s); }

double Road::superelevation_at(double s) const { return evaluate(superelevation, s); }

double Road::surface_z(double s, double t) const {
  const double roll = superelevation_at(s);
  return elevation(s) + (roll == 0 ? 0.0 : t * std::tan(roll));
}

double Road::lane_offset(double s, double* slope) const { return evaluate(lane_offsets, s, slope); }

size_t Road::section_index(double s) const {
  return last_at_or_before(sections, s, [](const LaneSection& sec) { return sec.s; });
}

double Road::lane_width(size_t section, int lane_id, double s) const {
  if (section >= sections.size()) {
    throw std::runtime_error("road " + id + ": no lane section " + std::to_string(section));
  }
  const Lane* lane = sections[section].find_lane(lane_id);
  if (!lane) {
    throw std::runtime_error("road " + id + ": no lane " + std::to_string(lane_id) +
                             " in the lane section at s=" + format_s(sections[section].s));
  }
  return lane_id == 0 ? 0.0 : evaluate(lane->widths, s);
}

LaneBorders Road::lane_borders(double s, int lane_id) const {
  return lane_borders(section_index(s), s, lane_id);
}

LaneBorders Road::lane_borders(size_t section, double s, int lane_id) const {
  if (section >= sections.size()) {
    throw std::runtime_error("road " + id + ": no lane section " + std::to_string(section));
  }
  const LaneSection& sec = sections[section];
  double slope = 0;
  double t = lane_offset(s, &slope);
  LaneBorders b{t, t, slope, slope};
  const int step = lane_id > 0 ? 1 : -1;
  for (int lid = step; lane_id != 0 && lid != lane_id + step; lid += step) {
    const Lane* lane = sec.find_lane(lid);
    if (!lane) {
      throw std::runtime_error("road " + id + ": no lane " + std::to_string(lid) +
                               " in the lane section at s=" + format_s(sec.s));
    }
    double width_slope = 0;
    const double width = evaluate(lane->widths, s, &width_slope);
    b.inner = t;
    b.inner_slope = slope;
    t += step * width;
    slope += step * width_slope;
  }
  b.outer = t;
  b.outer_slope = slope;
  return b;
}

Pose2 Road::offset_point(double s, double t) const {
  const Pose2 ref = reference(s);
  return {ref.x - t * std::sin(ref.heading), ref.y + t * std::cos(ref.heading), ref.heading,
          ref.curvature};
}

Pose2 Road::lane_point(double s, int lane_id, double t_fraction) const {
  const LaneBorders b = lane_borders(s, lane_id);
  const double t = b.inner + t_fraction * (b.outer - b.inner);
  const double dt = b.inner_slope + t_fraction * (b.outer_slope - b.inner_slope);
  Pose2 p = offset_point(s, t);
  const double stretch = 1 - p.curvature * t;  // ds along the offset curve per ds of reference
  p.heading += std::atan2(dt, stretch);
  p.curvature = std::abs(stretch) > 1e-9 ? p.curvature / stretch : 0.0;
  return p;
}

const Road* Network::find_road(const std::string& id) const {
  for (const Road& r : roads) {
    if (r.id == id) return &r;
  }
  return nullptr;
}

const Junction* Network::find_junction(const std::string& id) const {
  for (const Junction& j : junctions) {
    if (j.id == id) return &j;
  }
  return nullptr;
}

const Road& Network::road(const std::string& id) const {
  if (const Road* r = find_road(id)) return *r;
  throw std::runtime_error(source + ": no road with id '" + id + "'");
}

double Network::total_length() const {
  double sum = 0;
  for (const Road& r : roads) sum += r.length;
  return sum;
}

}  // namespace convoy::opendrive
