#include "worldgen/objects.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <optional>

#include "worldgen/markings.h"
#include "worldgen/shapes.h"

namespace convoy::worldgen {
namespace {

namespace odr = opendrive;

const MaterialDesc kWall{{0.74, 0.68, 0.58}, 0.05, ""};
const MaterialDesc kRoof{{0.36, 0.3, 0.29}, 0.05, ""};
const MaterialDesc kConcrete{{0.62, 0.62, 0.6}, 0.05, ""};
const MaterialDesc kMetal{{0.7, 0.72, 0.75}, 0.4, ""};
const MaterialDesc kHedge{{0.16, 0.34, 0.12}, 0.02, ""};
const MaterialDesc kObstacle{{0.85, 0.4, 0.1}, 0.1, ""};

// One instance of an object: where it stands and its size, after a repeat's overrides.
struct Instance {
  double s = 0, t = 0, z = 0;
  double length = 0, width = 0, height = 0;
  std::string suffix;  // "" or "_k" for the k-th repetition
};

// FNV-1a: the same choice of model on every machine.
uint64_t stable_hash(const std::string& s) {
  uint64_t h = 1469598103934665603ull;
  for (unsigned char c : s) h = (h ^ c) * 1099511628211ull;
  return h;
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

class ObjectBuilder {
 public:
  ObjectBuilder(const odr::Road& road, const odr::RoadObject& o, const Catalog& catalog,
                WorldPlan& plan)
      : road_(road),
        o_(o),
        catalog_(catalog),
        plan_(plan),
        type_(lower(o.type)),
        where_("road " + road.id + " object " + o.id + " (" + o.type + ")") {}

  void build() {
    if (!(std::abs(o_.s) < 1e6 && std::abs(o_.t) < 1e4)) {
      return plan_.warn(where_ + ": position is off the road; skipped");
    }
    if (o_.repeats.empty()) {
      single({o_.s, o_.t, o_.z_offset, o_.length, o_.width, o_.height, ""});
      return;
    }
    for (const odr::ObjectRepeat& r : o_.repeats) repeat(r);
  }

 private:
  static double lerp(double a, double b, double u) { return a + (b - a) * u; }
  double or_object(double v, double fallback) const { return std::isfinite(v) ? v : fallback; }

  void repeat(const odr::ObjectRepeat& r) {
    if (!(r.length >= 0 && r.length < 1e5 && r.distance >= 0)) {
      return plan_.warn(where_ + ": repeat with length " + std::to_string(r.length) +
                        " and distance " + std::to_string(r.distance) + "; skipped");
    }
    const double w0 = or_object(r.width_start, o_.width), w1 = or_object(r.width_end, w0);
    const double h0 = or_object(r.height_start, o_.height), h1 = or_object(r.height_end, h0);
    if (r.distance <= 0) return sweep(r, w0, w1, h0, h1);
    const int n = static_cast<int>(std::floor(r.length / r.distance + 1e-9)) + 1;
    if (n > 5000)
      return plan_.warn(where_ + ": repeat makes " + std::to_string(n) + " objects; skipped");
    if (n > 12 && is_post()) return posts(r, n, h0, h1);
    for (int k = 0; k < n; ++k) {
      const double u = r.length > 0 ? k * r.distance / r.length : 0;
      single({r.s + k * r.distance, lerp(r.t_start, r.t_end, u), lerp(r.z_start, r.z_end, u),
              o_.length, lerp(w0, w1, u), lerp(h0, h1, u), "_" + std::to_string(k)});
    }
  }

  // A continuous object along the road (distance 0): a wall, barrier, railing or hedge.
  void sweep(const odr::ObjectRepeat& r, double w0, double w1, double h0, double h1) {
    const double s0 = std::clamp(r.s, 0.0, road_.length);
    const double s1 = std::clamp(r.s + r.length, 0.0, road_.length);
    if (s1 - s0 < 0.05) return;
    std::vector<RibbonStation> st;
    const int n = std::max(1, static_cast<int>(std::ceil((s1 - s0) / 2.0)));
    for (int i = 0; i <= n; ++i) {
      const double s = s0 + (s1 - s0) * i / n, u = (s - r.s) / std::max(r.length, 1e-9);
      const double heading = road_.reference(s).heading;
      st.push_back({road_point(road_, s, lerp(r.t_start, r.t_end, u), lerp(r.z_start, r.z_end, u)),
                    {-std::sin(heading), std::cos(heading)},
                    std::max(0.05, lerp(w0, w1, u) > 0 ? lerp(w0, w1, u) : 0.2),
                    std::max(0.05, lerp(h0, h1, u) > 0 ? lerp(h0, h1, u) : 1.0)});
    }
    MeshModel m = model(type_ == "vegetation" ? "shrub" : sweep_class(), "_sweep");
    add_ribbon(m.mesh.part("solid", material()), st);
    plan_.models.push_back(std::move(m));
  }

  bool is_post() const {
    return type_ == "pole" || type_ == "guide-post" || type_ == "rail-pole" || type_ == "bollard";
  }

  // A long row of small posts (a railing's, guide posts): one model of simple posts rather
  // than a model each, which would cost every start-up and every frame.
  void posts(const odr::ObjectRepeat& r, int n, double h0, double h1) {
    MeshModel m = model("pole", "_posts");
    Part& part = m.mesh.part("post", {{0.82, 0.82, 0.8}, 0.2, ""});
    for (int k = 0; k < n; ++k) {
      const double u = r.length > 0 ? k * r.distance / r.length : 0;
      const double s = std::clamp(r.s + k * r.distance, 0.0, road_.length);
      const double h = std::max(0.3, lerp(h0, h1, u) > 0 ? lerp(h0, h1, u) : 1.0);
      const Vec3 base =
          road_point(road_, s, lerp(r.t_start, r.t_end, u), lerp(r.z_start, r.z_end, u));
      MeshSet::add_box(part, {base[0], base[1], base[2] + 0.5 * h}, {0.12, 0.12, h}, yaw_at(s));
    }
    plan_.models.push_back(std::move(m));
  }

  std::string sweep_class() const { return type_ == "building" ? "building" : "barrier"; }

  MaterialDesc material() const {
    if (type_ == "vegetation" || type_ == "tree") return kHedge;
    if (type_ == "railing" || type_ == "guardrail" || type_ == "fence") return kMetal;
    if (type_ == "obstacle") return kObstacle;
    if (type_ == "building") return kWall;
    return kConcrete;
  }

  MeshModel model(const std::string& cls, const std::string& suffix) const {
    MeshModel m;
    m.name = "object_" + road_.id + "_" + o_.id + suffix;
    m.cls = cls;
    return m;
  }

  double yaw_at(double s) const {
    return road_.reference(std::clamp(s, 0.0, road_.length)).heading + o_.hdg;
  }

  void single(const Instance& in);
  void outline(const Instance& in, const odr::Outline& ol, size_t k);
  void catalog_model(const Instance& in, const std::string& kind, double natural_height);
  void box(const Instance& in, const std::string& cls);

  const odr::Road& road_;
  const odr::RoadObject& o_;
  const Catalog& catalog_;
  WorldPlan& plan_;
  std::string type_;
  std::string where_;
};

void ObjectBuilder::single(const Instance& in) {
  if (!o_.outlines.empty()) {
    for (size_t k = 0; k < o_.outlines.size(); ++k) outline(in, o_.outlines[k], k);
    return;
  }
  const double tall = in.height;
  if (type_ == "crosswalk") {
    const double half = 0.5 * std::max(in.width, 3.0);
    const auto [t0, t1] =
        lane_span(road_, std::clamp(in.s, 0.0, road_.length), road_.sections.front().min_lane_id(),
                  road_.sections.front().max_lane_id());
    paint_zebra(white_paint(plan_), road_, in.s - half, in.s + half, t0, t1);
  } else if (type_ == "tree") {
    catalog_model(in, "tree", tall);
  } else if (type_ == "vegetation" || type_ == "bush") {
    if (in.length > 2.5 || in.width > 2.5) return box(in, "shrub");
    catalog_model(in, "shrub", tall);
  } else if (type_ == "streetlamp" || ((type_ == "pole") && tall >= 4)) {
    catalog_model(in, "street_light", tall);
  } else if (type_ == "pole" || type_ == "guide-post" || type_ == "rail-pole" ||
             type_ == "trafficislandpole") {
    catalog_model(in, "bollard", tall > 0 ? tall : 1.0);
  } else if (type_ == "building" || type_ == "barrier" || type_ == "railing" ||
             type_ == "guardrail" || type_ == "fence" || type_ == "obstacle" || type_ == "wall" ||
             type_ == "noisebarrier" || type_ == "soundbarrier") {
    box(in, type_ == "building" ? "building" : (type_ == "obstacle" ? "other" : "barrier"));
  } else if (type_ == "parkingspace") {
    const double l = in.length > 0 ? in.length : 5.0, w = in.width > 0 ? in.width : 2.5;
    const double yaw = yaw_at(in.s), c = std::cos(yaw), s = std::sin(yaw);
    const Vec3 o = road_point(road_, std::clamp(in.s, 0.0, road_.length), in.t, 0);
    std::vector<Vec3> corners;
    for (auto [u, v] : {std::pair{-0.5, -0.5}, {0.5, -0.5}, {0.5, 0.5}, {-0.5, 0.5}}) {
      corners.push_back({o[0] + c * u * l - s * v * w, o[1] + s * u * l + c * v * w, o[2]});
    }
    paint_outline(white_paint(plan_), corners, 0.12);
  } else if (in.length > 0 && in.width > 0 && in.height > 0) {
    plan_.warn(where_ + ": unknown object type; drawn as a box");
    box(in, "other");
  } else {
    plan_.warn(where_ + ": unknown object type without a size; skipped");
  }
}

void ObjectBuilder::catalog_model(const Instance& in, const std::string& kind,
                                  double natural_height) {
  const auto models = catalog_.of_kind(kind);
  if (models.empty())
    return plan_.warn(where_ + ": no " + kind + " model in the scenery catalog; skipped");
  const CatalogModel* m = models[stable_hash(road_.id + "/" + o_.id) % models.size()];
  Placement p;
  p.name = "object_" + road_.id + "_" + o_.id + in.suffix;
  p.model = m;
  const double s = std::clamp(in.s, 0.0, road_.length);
  p.position = road_point(road_, s, in.t, in.z);
  p.yaw = yaw_at(s);
  if (natural_height > 0.2 && m->size[2] > 0) {
    const double k = std::clamp(natural_height / m->size[2], 0.3, 3.0);
    p.scale = {k, k, k};
  }
  plan_.placements.push_back(std::move(p));
}

void ObjectBuilder::box(const Instance& in, const std::string& cls) {
  const double l = in.length > 0 ? in.length : 1.0, w = in.width > 0 ? in.width : 0.5;
  const double h = in.height > 0 ? in.height : 1.0;
  const double s = std::clamp(in.s, 0.0, road_.length);
  MeshModel m = model(cls, in.suffix);
  const Vec3 base = road_point(road_, s, in.t, in.z);
  const double yaw = yaw_at(s);
  if (cls == "building") {
    const double c = std::cos(yaw), sn = std::sin(yaw);
    std::vector<Vec3> corners;
    for (auto [u, v] : {std::pair{-0.5, -0.5}, {0.5, -0.5}, {0.5, 0.5}, {-0.5, 0.5}}) {
      corners.push_back(
          {base[0] + c * u * l - sn * v * w, base[1] + sn * u * l + c * v * w, base[2]});
    }
    add_prism(m.mesh.part("wall", kWall), m.mesh.part("roof", kRoof), corners,
              std::vector<double>(4, h));
  } else {
    MeshSet::add_box(m.mesh.part("solid", material()), {base[0], base[1], base[2] + 0.5 * h},
                     {l, w, h}, yaw);
  }
  m.collisions.push_back({{base[0], base[1], base[2] + 0.5 * h}, {l, w, h}, yaw});
  plan_.models.push_back(std::move(m));
}

void ObjectBuilder::outline(const Instance& in, const odr::Outline& ol, size_t k) {
  const std::string where = where_ + " outline " + std::to_string(k);
  if (ol.corners.size() < 3) {
    if (type_ != "crosswalk") plan_.warn(where + ": fewer than 3 corners; skipped");
    return;
  }
  // (s, t) of each corner, and its world point
  const double s_in = std::clamp(in.s, 0.0, road_.length);
  const double yaw = yaw_at(s_in), c = std::cos(yaw), sn = std::sin(yaw);
  const Vec3 origin = road_point(road_, s_in, in.t, in.z);
  const double rel = o_.hdg;
  std::vector<Vec2> st, flat;
  std::vector<Vec3> world;
  std::vector<double> heights;
  for (const odr::OutlineCorner& q : ol.corners) {
    if (q.road) {
      const double s = std::clamp(q.a, 0.0, road_.length);
      st.push_back({s, q.b});
      world.push_back(road_point(road_, s, q.b, q.z));
    } else {
      st.push_back({in.s + q.a * std::cos(rel) - q.b * std::sin(rel),
                    in.t + q.a * std::sin(rel) + q.b * std::cos(rel)});
      world.push_back(
          {origin[0] + c * q.a - sn * q.b, origin[1] + sn * q.a + c * q.b, origin[2] + q.z});
    }
    flat.push_back({world.back()[0], world.back()[1]});
    heights.push_back(q.height > 0 ? q.height : in.height);
  }
  if (self_intersects(flat) || std::abs(signed_area2(flat)) < 1e-6) {
    return plan_.warn(where + ": the outline intersects itself or has no area; skipped");
  }
  if (type_ == "crosswalk") {
    double s0 = 1e300, s1 = -1e300, t0 = 1e300, t1 = -1e300;
    for (const Vec2& p : st) {
      s0 = std::min(s0, p[0]), s1 = std::max(s1, p[0]), t0 = std::min(t0, p[1]),
      t1 = std::max(t1, p[1]);
    }
    paint_zebra(white_paint(plan_), road_, s0, s1, t0, t1);
  } else if (type_ == "parkingspace") {
    paint_outline(white_paint(plan_), world, 0.12);
  } else {
    double tallest = 0;
    for (double h : heights) tallest = std::max(tallest, h);
    if (tallest < 0.05) return;  // a flat area (grass, a marking): nothing to stand up
    const bool building = type_ == "building" || (type_ == "none" && tallest >= 2.5);
    MeshModel m = model(building ? "building" : (type_ == "vegetation" ? "shrub" : "barrier"),
                        in.suffix + (k ? "_" + std::to_string(k) : ""));
    if (building) {
      add_prism(m.mesh.part("wall", kWall), m.mesh.part("roof", kRoof), world, heights);
    } else {
      Part& p = m.mesh.part("solid", material());
      add_prism(p, p, world, heights);
    }
    plan_.models.push_back(std::move(m));
  }
}

}  // namespace

void place_objects(const odr::Network& net, const Catalog& catalog, WorldPlan& plan) {
  for (const odr::Road& road : net.roads) {
    for (const odr::RoadObject& o : road.objects) ObjectBuilder(road, o, catalog, plan).build();
  }
}

void build_spans(const odr::Network& net, WorldPlan& plan) {
  for (const odr::Road& road : net.roads) {
    auto span = [&](const odr::RoadSpan& sp, bool tunnel) {
      const double s0 = std::clamp(sp.s, 0.0, road.length);
      const double s1 = std::clamp(sp.s + sp.length, 0.0, road.length);
      if (s1 - s0 < 0.5) return;
      MeshModel m;
      m.name = std::string(tunnel ? "tunnel_" : "bridge_") + road.id + "_" + sp.id;
      m.cls = "other";
      Part& part = m.mesh.part("solid", tunnel ? kConcrete : kConcrete);
      std::vector<RibbonStation> left, right, roof;
      const int n = std::max(1, static_cast<int>(std::ceil((s1 - s0) / 2.0)));
      for (int i = 0; i <= n; ++i) {
        const double s = s0 + (s1 - s0) * i / n;
        const auto [lo, hi] = lane_span(road, s, road.sections[road.section_index(s)].min_lane_id(),
                                        road.sections[road.section_index(s)].max_lane_id());
        const double h = road.reference(s).heading;
        const Vec2 across{-std::sin(h), std::cos(h)};
        if (tunnel) {
          left.push_back({road_point(road, s, hi + 0.4, 0), across, 0.8, 5.6});
          right.push_back({road_point(road, s, lo - 0.4, 0), across, 0.8, 5.6});
          roof.push_back({road_point(road, s, 0.5 * (lo + hi), 5.0), across, hi - lo + 1.6, 0.6});
        } else {
          left.push_back({road_point(road, s, hi + 0.15, 0), across, 0.3, 1.0});
          right.push_back({road_point(road, s, lo - 0.15, 0), across, 0.3, 1.0});
        }
      }
      add_ribbon(part, left);
      add_ribbon(part, right);
      if (tunnel) add_ribbon(part, roof);
      plan.models.push_back(std::move(m));
    };
    for (const auto& t : road.tunnels) span(t, true);
    for (const auto& b : road.bridges) span(b, false);
  }
}

}  // namespace convoy::worldgen
