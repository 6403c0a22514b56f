#include "worldgen/scenery.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace convoy::worldgen {
namespace {

namespace odr = opendrive;

// splitmix64: small, fast and the same everywhere.
class Rng {
 public:
  explicit Rng(uint64_t seed) : state_(seed * 0x9E3779B97F4A7C15ull + 0x632BE59BD9B4E5ull) {}
  uint64_t next() {
    uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform(double a, double b) { return a + (b - a) * (next() >> 11) * 0x1.0p-53; }
  bool chance(double p) { return uniform(0, 1) < p; }
  template <typename T>
  const T& pick(const std::vector<T>& v) {
    return v[next() % v.size()];
  }

 private:
  uint64_t state_;
};

// The outer edge (t) of the drawn lanes on one side of a road at s (side +1 left, -1 right).
double road_edge(const odr::Road& road, double s, int side) {
  const size_t k = road.section_index(s);
  const odr::LaneSection& sec = road.sections[k];
  double edge = road.lane_offset(s);
  for (const odr::Lane& lane : sec.lanes) {
    if (lane.id == 0 || lane.type == "none" || (lane.id > 0) != (side > 0)) continue;
    const odr::LaneBorders b = road.lane_borders(k, s, lane.id);
    edge = side > 0 ? std::max({edge, b.inner, b.outer}) : std::min({edge, b.inner, b.outer});
  }
  return edge;
}

class Scatterer {
 public:
  Scatterer(const Catalog& catalog, Scenery kind, uint64_t seed, Occupancy& occ, WorldPlan& plan)
      : catalog_(catalog), kind_(kind), rng_(seed), occ_(occ), plan_(plan) {
    for (const char* k :
         {"building", "tree", "shrub", "street_light", "bench", "bin", "bus_stop"}) {
      models_[k] = catalog.of_kind(k);
    }
  }

  void road(const odr::Road& road) {
    if (road.junction != "-1" || road.length < 5) return;
    for (int side : {-1, 1}) {
      if (kind_ == Scenery::kUrban) {
        urban_side(road, side);
      } else {
        rows(road, side, 2.5, 6.0, 6, 15, 0.4);
        rows(road, side, 9.0, 22.0, 9, 24, 0.3);
      }
    }
  }

 private:
  // Tries to place a model whose front faces the road at (s, t_near) where t_near is the
  // footprint's edge nearest the road; returns the frontage used (0 when it did not fit).
  double place(const odr::Road& road, double s, int side, double offset, const CatalogModel* m,
               double margin = 0.3) {
    if (!m) return 0;
    const double depth = m->size[0], frontage = m->size[1];
    const double edge = road_edge(road, s, side);
    const double t = edge + side * (offset + 0.5 * depth);
    const odr::Pose2 p = road.offset_point(s, t);
    const double yaw = road.reference(s).heading - side * 0.5 * std::numbers::pi;
    if (!occ_.free(p.x, p.y, depth + 2 * margin, frontage + 2 * margin, yaw)) return 0;
    occ_.mark(p.x, p.y, depth + 2 * margin, frontage + 2 * margin, yaw);
    Placement pl;
    pl.name = "scenery_" + std::to_string(++count_);
    pl.model = m;
    pl.position = {p.x, p.y, road.surface_z(s, t)};
    pl.yaw = yaw;
    plan_.placements.push_back(std::move(pl));
    return frontage;
  }

  const CatalogModel* any(const std::string& kind) {
    const auto& v = models_[kind];
    return v.empty() ? nullptr : rng_.pick(v);
  }

  void rows(const odr::Road& road, int side, double t_min, double t_max, double gap_min,
            double gap_max, double bush) {
    for (double s = rng_.uniform(0, gap_max); s < road.length;
         s += rng_.uniform(gap_min, gap_max)) {
      const double offset = rng_.uniform(t_min, t_max);
      place(road, s, side, offset, rng_.chance(bush) ? any("shrub") : any("tree"));
    }
  }

  void urban_side(const odr::Road& road, int side) {
    // street furniture along the edge
    double next_light = rng_.uniform(5, 20), next_stop = rng_.uniform(60, 160);
    for (double s = 2; s < road.length - 2; s += 1) {
      if (s >= next_light) {
        if (place(road, s, side, 0.4, any("street_light"), 0.1) > 0)
          next_light = s + rng_.uniform(24, 34);
        else
          next_light = s + 2;
      } else if (s >= next_stop && side < 0) {
        if (place(road, s, side, 0.5, any("bus_stop"), 0.2) > 0)
          next_stop = s + rng_.uniform(200, 320);
        else
          next_stop = s + 3;
      } else if (rng_.chance(0.03)) {
        place(road, s, side, 0.4, any(rng_.chance(0.5) ? "bench" : "bin"), 0.1);
      }
    }
    // buildings behind, trees in the gaps
    for (double s = rng_.uniform(0, 6); s < road.length;) {
      const CatalogModel* b = any("building");
      const double offset = rng_.uniform(2.5, 4.5);
      const double frontage = b ? b->size[1] : 10;
      const double used = place(road, s + 0.5 * frontage, side, offset, b, 0.5);
      if (used > 0) {
        s += used + rng_.uniform(0.5, 4);
        if (rng_.chance(0.3)) place(road, s, side, 1.5, any("tree"));
        s += 1;
      } else {
        if (rng_.chance(0.4)) place(road, s, side, rng_.uniform(1.5, 4), any("tree"));
        s += 3;
      }
    }
  }

  const Catalog& catalog_;
  Scenery kind_;
  Rng rng_;
  Occupancy& occ_;
  WorldPlan& plan_;
  std::map<std::string, std::vector<const CatalogModel*>> models_;
  int count_ = 0;
};

}  // namespace

void scatter_scenery(const odr::Network& net, const Catalog& catalog, Scenery kind, uint64_t seed,
                     Occupancy& occupancy, WorldPlan& plan) {
  if (kind == Scenery::kNone) return;
  Scatterer scatter(catalog, kind, seed, occupancy, plan);
  for (const odr::Road& road : net.roads) scatter.road(road);
}

}  // namespace convoy::worldgen
