#include "worldgen/height_field.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <stdexcept>
#include <string>

#include "opendrive/sampling.h"
#include "worldgen/world_plan.h"

namespace convoy::worldgen {

namespace odr = opendrive;

double HeightField::min() const {
  return heights.empty() ? 0.0 : *std::min_element(heights.begin(), heights.end());
}

double HeightField::max() const {
  return heights.empty() ? 0.0 : *std::max_element(heights.begin(), heights.end());
}

namespace {

// Spreads known heights into unknown (NaN) neighbours, one ring of cells per pass.
void dilate(HeightField& f, int passes) {
  const int w = f.columns, h = f.rows;
  for (int pass = 0; pass < passes; ++pass) {
    std::vector<float> next = f.heights;
    bool changed = false;
    for (int r = 0; r < h; ++r) {
      for (int c = 0; c < w; ++c) {
        if (!std::isnan(f.heights[r * w + c])) continue;
        double sum = 0;
        int n = 0;
        for (int dr = -1; dr <= 1; ++dr) {
          for (int dc = -1; dc <= 1; ++dc) {
            const int rr = r + dr, cc = c + dc;
            if (rr < 0 || cc < 0 || rr >= h || cc >= w) continue;
            const float v = f.heights[rr * w + cc];
            if (!std::isnan(v)) sum += v, ++n;
          }
        }
        if (n) next[r * w + c] = static_cast<float>(sum / n), changed = true;
      }
    }
    f.heights.swap(next);
    if (!changed) break;
  }
}

}  // namespace

HeightField road_height_field(const odr::Network& net, double ground_z, double cell, double margin,
                              double reach) {
  const odr::Bounds b = odr::network_bounds(net);
  HeightField f;
  f.cell = cell;
  f.x0 = b.min[0] - margin + 0.5 * cell;
  f.y0 = b.min[1] - margin + 0.5 * cell;
  f.columns = static_cast<int>(std::ceil((b.max[0] - b.min[0] + 2 * margin) / cell));
  f.rows = static_cast<int>(std::ceil((b.max[1] - b.min[1] + 2 * margin) / cell));
  if (static_cast<double>(f.columns) * f.rows > 3e7) {
    throw std::runtime_error("the map is too large for a height field (" +
                             std::to_string(f.columns) + " x " + std::to_string(f.rows) +
                             " cells)");
  }
  f.heights.assign(static_cast<size_t>(f.columns) * f.rows, std::nanf(""));
  odr::SamplingOptions fine;
  fine.max_curve_segment = 0.5 * cell;
  fine.max_straight_segment = 0.5 * cell;
  fine.max_varying_segment = 0.5 * cell;
  for (const odr::Road& road : net.roads) {
    for (size_t k = 0; k < road.sections.size(); ++k) {
      const odr::LaneSection& sec = road.sections[k];
      if (sec.s_end - sec.s < 1e-3) continue;
      for (double s : odr::road_stations(road, sec.s, sec.s_end, fine)) {
        double lo = road.lane_offset(s), hi = lo;
        for (const odr::Lane& lane : sec.lanes) {
          if (lane.id == 0 || lane.type == "none") continue;
          const odr::LaneBorders lb = road.lane_borders(k, s, lane.id);
          lo = std::min({lo, lb.inner, lb.outer});
          hi = std::max({hi, lb.inner, lb.outer});
        }
        const double h = road.reference(s).heading, ch = std::cos(h), sh = std::sin(h);
        for (double t = lo; t <= hi + 1e-9; t += 0.5 * cell) {
          const double tt = std::min(t, hi);
          const opendrive::Pose2 p = road.offset_point(s, tt);
          const int c = static_cast<int>(std::floor((p.x - f.x0) / cell + 0.5));
          const int r = static_cast<int>(std::floor((p.y - f.y0) / cell + 0.5));
          if (c < 0 || r < 0 || c >= f.columns || r >= f.rows) continue;
          // the surface at the cell's centre, through the road's frame at this sample
          const double dx = f.x0 + c * cell - p.x, dy = f.y0 + r * cell - p.y;
          const double z = road.surface_z(std::clamp(s + dx * ch + dy * sh, 0.0, road.length),
                                          tt - dx * sh + dy * ch);
          float& v = f.heights[static_cast<size_t>(r) * f.columns + c];
          if (std::isnan(v) || z > v) v = static_cast<float>(z);
        }
      }
    }
  }
  dilate(f, static_cast<int>(std::ceil(reach / cell)));
  for (float& v : f.heights) {
    if (std::isnan(v)) v = static_cast<float>(ground_z);
  }
  return f;
}

void write_pgm(const HeightField& f, const std::filesystem::path& file) {
  const double lo = f.min(), span = std::max(1e-6, f.max() - lo);
  std::string out = "P5\n" + std::to_string(f.columns) + " " + std::to_string(f.rows) + "\n65535\n";
  out.reserve(out.size() + 2 * f.heights.size());
  for (int r = f.rows - 1; r >= 0; --r) {  // the image's first row: the largest y
    for (int c = 0; c < f.columns; ++c) {
      const double v = (f.heights[static_cast<size_t>(r) * f.columns + c] - lo) / span;
      const auto q = static_cast<uint16_t>(std::lround(std::clamp(v, 0.0, 1.0) * 65535));
      out.push_back(static_cast<char>(q >> 8));
      out.push_back(static_cast<char>(q & 0xff));
    }
  }
  std::ofstream o(file, std::ios::binary);
  o.write(out.data(), static_cast<std::streamsize>(out.size()));
  if (!o.flush()) throw std::runtime_error(file.string() + ": write failed");
}

}  // namespace convoy::worldgen
