#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "opendrive/sampling.h"
#include "worldgen/scenery.h"

namespace convoy::worldgen {

namespace odr = opendrive;

Scenery parse_scenery(const std::string& name) {
  if (name == "none") return Scenery::kNone;
  if (name == "roadside") return Scenery::kRoadside;
  if (name == "urban") return Scenery::kUrban;
  throw std::invalid_argument("--scenery must be none, roadside or urban, got '" + name + "'");
}

Occupancy::Occupancy(const odr::Bounds& b, double margin, double cell)
    : x0_(b.min[0] - margin), y0_(b.min[1] - margin), cell_(cell) {
  nx_ = std::max(1, static_cast<int>(std::ceil((b.max[0] - b.min[0] + 2 * margin) / cell)));
  ny_ = std::max(1, static_cast<int>(std::ceil((b.max[1] - b.min[1] + 2 * margin) / cell)));
  if (static_cast<double>(nx_) * ny_ > 4e8) {
    throw std::runtime_error("the map is too large for scenery (" + std::to_string(nx_) + " x " +
                             std::to_string(ny_) + " m)");
  }
  cells_.assign(static_cast<size_t>(nx_) * ny_, 0);
}

template <typename F>
void Occupancy::for_cells(double x, double y, double length, double width, double yaw,
                          F&& f) const {
  // Sample the rectangle every half cell; conservative enough for 1 m cells.
  const double c = std::cos(yaw), s = std::sin(yaw), step = 0.5 * cell_;
  const int nu = std::max(1, static_cast<int>(std::ceil(length / step)));
  const int nv = std::max(1, static_cast<int>(std::ceil(width / step)));
  for (int i = 0; i <= nu; ++i) {
    for (int j = 0; j <= nv; ++j) {
      const double u = -0.5 * length + length * i / nu, v = -0.5 * width + width * j / nv;
      const int ix = static_cast<int>(std::floor((x + c * u - s * v - x0_) / cell_));
      const int iy = static_cast<int>(std::floor((y + s * u + c * v - y0_) / cell_));
      if (!f(ix, iy)) return;
    }
  }
}

bool Occupancy::taken(double x, double y) const {
  const int ix = static_cast<int>(std::floor((x - x0_) / cell_));
  const int iy = static_cast<int>(std::floor((y - y0_) / cell_));
  if (ix < 0 || iy < 0 || ix >= nx_ || iy >= ny_) return true;  // off the grid: not ours
  return cells_[static_cast<size_t>(iy) * nx_ + ix] != 0;
}

bool Occupancy::free(double x, double y, double length, double width, double yaw) const {
  bool ok = true;
  for_cells(x, y, length, width, yaw, [&](int ix, int iy) {
    if (ix < 0 || iy < 0 || ix >= nx_ || iy >= ny_ || cells_[static_cast<size_t>(iy) * nx_ + ix]) {
      ok = false;
    }
    return ok;
  });
  return ok;
}

void Occupancy::mark(double x, double y, double length, double width, double yaw) {
  for_cells(x, y, length, width, yaw, [&](int ix, int iy) {
    if (ix >= 0 && iy >= 0 && ix < nx_ && iy < ny_) cells_[static_cast<size_t>(iy) * nx_ + ix] = 1;
    return true;
  });
}

void Occupancy::mark_roads(const odr::Network& net, double grow) {
  odr::SamplingOptions coarse;
  coarse.max_straight_segment = 1.0;
  for (const odr::Road& road : net.roads) {
    for (size_t k = 0; k < road.sections.size(); ++k) {
      const odr::LaneSection& sec = road.sections[k];
      if (sec.s_end - sec.s < 1e-6) continue;
      const auto stations = odr::road_stations(road, sec.s, sec.s_end, coarse);
      for (size_t i = 0; i + 1 < stations.size(); ++i) {
        const double a = stations[i], b = stations[i + 1], mid = 0.5 * (a + b);
        const odr::Pose2 ref = road.reference(mid);
        for (const odr::Lane& lane : sec.lanes) {
          if (lane.id == 0 || lane.type == "none") continue;
          const odr::LaneBorders lb = road.lane_borders(k, mid, lane.id);
          const double t = 0.5 * (lb.inner + lb.outer), w = std::abs(lb.outer - lb.inner);
          if (w < 1e-3) continue;
          const odr::Pose2 p = road.offset_point(mid, t);
          mark(p.x, p.y, b - a + 2 * grow, w + 2 * grow, ref.heading);
        }
      }
    }
  }
}

}  // namespace convoy::worldgen
