#include "scene/scene_json.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

namespace convoy::scene {

namespace {

using nlohmann::json;
using Rgba = std::array<double, 4>;

constexpr Rgba kBorder{0.62, 0.62, 0.62, 1}, kSidewalk{0.45, 0.45, 0.45, 0.8},
    kCentre{0.9, 0.9, 0.9, 0.25}, kSignalPost{0.15, 0.15, 0.15, 1};
constexpr Rgba kEgo{0.9, 0.12, 0.12, 1}, kCar{0.2, 0.45, 0.95, 1}, kTruck{0.6, 0.3, 0.8, 1},
    kPedestrian{1, 0.55, 0.1, 1}, kCyclist{0.2, 0.75, 0.3, 1}, kOther{0.6, 0.6, 0.6, 1};
constexpr Rgba kRoute{0.9, 0.12, 0.12, 0.35}, kTrail{1, 0.4, 0.4, 0.9};

double round_to(double v, double scale) { return std::round(v * scale) / scale + 0.0; }

json stamp(uint64_t ns) { return {{"sec", ns / 1000000000u}, {"nsec", ns % 1000000000u}}; }
json color(const Rgba& c) { return {{"r", c[0]}, {"g", c[1]}, {"b", c[2]}, {"a", c[3]}}; }
json vec(double x, double y, double z, double scale = 1000) {
  return {{"x", round_to(x, scale)}, {"y", round_to(y, scale)}, {"z", round_to(z, scale)}};
}

// Quaternion of yaw about z, then pitch about y, then roll about x.
json quaternion(double yaw, double pitch = 0, double roll = 0) {
  const double cy = std::cos(yaw / 2), sy = std::sin(yaw / 2), cp = std::cos(pitch / 2),
               sp = std::sin(pitch / 2), cr = std::cos(roll / 2), sr = std::sin(roll / 2);
  const double s = 1e6;
  return {{"x", round_to(sr * cp * cy - cr * sp * sy, s)},
          {"y", round_to(cr * sp * cy + sr * cp * sy, s)},
          {"z", round_to(cr * cp * sy - sr * sp * cy, s)},
          {"w", round_to(cr * cp * cy + sr * sp * sy, s)}};
}

json pose(double x, double y, double z, double yaw = 0, double pitch = 0, double roll = 0) {
  return {{"position", vec(x, y, z)}, {"orientation", quaternion(yaw, pitch, roll)}};
}

json metadata(std::initializer_list<std::pair<std::string, std::string>> kv) {
  json out = json::array();
  for (const auto& [k, v] : kv) out.push_back({{"key", k}, {"value", v}});
  return out;
}

json entity(uint64_t t, const std::string& id, json meta) {
  return {{"timestamp", stamp(t)},      {"frame_id", kMapFrame},  {"id", id},
          {"lifetime", stamp(0)},       {"frame_locked", false},  {"metadata", std::move(meta)},
          {"arrows", json::array()},    {"cubes", json::array()}, {"spheres", json::array()},
          {"cylinders", json::array()}, {"lines", json::array()}, {"triangles", json::array()},
          {"texts", json::array()},     {"models", json::array()}};
}

json line_strip(const std::vector<Point3>& points, double thickness, const Rgba& c, double scale) {
  json pts = json::array();
  for (const Point3& p : points) pts.push_back(vec(p.x, p.y, p.z, scale));
  return {{"type", 0},
          {"pose", pose(0, 0, 0)},
          {"thickness", thickness},
          {"scale_invariant", false},
          {"points", std::move(pts)},
          {"color", color(c)},
          {"colors", json::array()},
          {"indices", json::array()}};
}

json sphere(const Point3& p, double size, const Rgba& c) {
  return {{"pose", pose(p.x, p.y, p.z)}, {"size", vec(size, size, size)}, {"color", color(c)}};
}

Rgba category_color(const SceneUser& u) {
  if (u.ego) return kEgo;
  const std::string& c = u.state.category();
  if (c == "truck" || c == "bus") return kTruck;
  if (c == "pedestrian") return kPedestrian;
  if (c == "cyclist") return kCyclist;
  if (c == "car" || c.empty()) return kCar;
  return kOther;
}

// The box of a road user; a size it does not give is its category's usual one.
std::array<double, 3> box_size(const data::RoadUser& u) {
  std::array<double, 3> d{4.5, 1.8, 1.5};
  const std::string& c = u.category();
  if (c == "truck") d = {8.0, 2.5, 3.2};
  if (c == "bus") d = {12.0, 2.55, 3.2};
  if (c == "pedestrian") d = {0.5, 0.5, 1.75};
  if (c == "cyclist") d = {1.8, 0.6, 1.7};
  return {u.length() > 0 ? u.length() : d[0], u.width() > 0 ? u.width() : d[1],
          u.height() > 0 ? u.height() : d[2]};
}

json user_entity(const SceneUser& su, uint64_t t) {
  const data::RoadUser& u = su.state;
  char speed[32];
  std::snprintf(speed, sizeof speed, "%.2f", u.speed());
  json e = entity(t, u.id(),
                  metadata({{"category", u.category()},
                            {"ego", su.ego ? "true" : "false"},
                            {"speed", speed},
                            {"model", u.model()},
                            {"source", su.source}}));
  const auto [length, width, height] = box_size(u);
  const double cx = u.x() + u.length_offset() * std::cos(u.yaw());
  const double cy = u.y() + u.length_offset() * std::sin(u.yaw());
  e["cubes"].push_back({{"pose", pose(cx, cy, u.z() + height / 2, u.yaw(), u.pitch(), u.roll())},
                        {"size", vec(length, width, height)},
                        {"color", color(category_color(su))}});
  e["texts"].push_back({{"pose", pose(cx, cy, u.z() + height + 0.5)},
                        {"billboard", true},
                        {"font_size", 12},
                        {"scale_invariant", true},
                        {"color", color({1, 1, 1, 0.9})},
                        {"text", u.id()}});
  return e;
}

Rgba signal_color(const std::string& state) {
  if (state == "red") return {1, 0.1, 0.1, 1};
  if (state == "yellow") return {1, 0.85, 0.1, 1};
  if (state == "red_yellow") return {1, 0.5, 0.1, 1};
  if (state == "green") return {0.1, 0.9, 0.3, 1};
  return {0.5, 0.5, 0.5, 1};
}

json signals_entity(const SceneState& state, const SceneMap* map, uint64_t t) {
  json meta = json::array();
  for (const auto& [id, s] : state.signals())
    meta.push_back({{"key", "signal/" + id}, {"value", s}});
  json e = entity(t, "signals", std::move(meta));
  if (!map) return e;
  for (const MapSignal& sig : map->signals) {
    const auto it = state.signals().find(sig.id);
    const std::string s = it == state.signals().end() ? "off" : it->second;
    e["spheres"].push_back(sphere(sig.position, sig.pedestrian ? 0.5 : 0.8, signal_color(s)));
  }
  return e;
}

std::string dump(const json& j) { return j.dump(-1, ' ', false, json::error_handler_t::replace); }

}  // namespace

std::string map_update_json(const SceneMap& map, uint64_t time_ns) {
  json lanes = entity(time_ns, "lanes", metadata({{"kind", "lanes"}, {"source", map.source}}));
  json centres = entity(time_ns, "centres", metadata({{"kind", "centres"}}));
  for (const MapLine& l : map.lines) {
    if (l.kind == LineKind::kCentre) {
      centres["lines"].push_back(line_strip(l.points, 0.05, kCentre, 100));
    } else {
      const bool road = l.kind == LineKind::kBorder;
      lanes["lines"].push_back(
          line_strip(l.points, road ? 0.12 : 0.08, road ? kBorder : kSidewalk, 100));
    }
  }
  json entities = json::array({std::move(lanes), std::move(centres)});
  for (const MapSignal& s : map.signals) {
    json e = entity(time_ns, "signal/" + s.id, metadata({{"kind", "signal"}, {"signal", s.id}}));
    e["spheres"].push_back(sphere(s.position, 0.3, kSignalPost));
    entities.push_back(std::move(e));
  }
  return dump({{"deletions", json::array()}, {"entities", std::move(entities)}});
}

std::string scene_update_json(const SceneState& state, const SceneMap* map, uint64_t time_ns) {
  json deletions = json::array();
  for (const std::string& id : state.deleted())
    deletions.push_back({{"timestamp", stamp(time_ns)}, {"type", 0}, {"id", id}});
  json entities = json::array();
  for (const auto& [id, u] : state.users()) entities.push_back(user_entity(u, time_ns));
  if (!state.route().empty()) {
    json e = entity(time_ns, "ego/route", metadata({{"kind", "route"}}));
    e["lines"].push_back(line_strip(state.route(), 0.4, kRoute, 1000));
    entities.push_back(std::move(e));
  }
  if (state.trail().size() >= 2) {
    std::vector<Point3> pts;
    for (const TrailPoint& p : state.trail()) pts.push_back(p.p);
    json e = entity(time_ns, "ego/trail", metadata({{"kind", "trail"}}));
    e["lines"].push_back(line_strip(pts, 0.25, kTrail, 1000));
    entities.push_back(std::move(e));
  }
  if (!state.signals().empty()) entities.push_back(signals_entity(state, map, time_ns));
  return dump({{"deletions", std::move(deletions)}, {"entities", std::move(entities)}});
}

std::string frame_transforms_json(const SceneState& state, uint64_t time_ns) {
  json transforms = json::array();
  for (const auto& [id, su] : state.users()) {
    if (!su.ego) continue;
    const data::RoadUser& u = su.state;
    transforms.push_back({{"timestamp", stamp(time_ns)},
                          {"parent_frame_id", kMapFrame},
                          {"child_frame_id", id},
                          {"translation", vec(u.x(), u.y(), u.z())},
                          {"rotation", quaternion(u.yaw(), u.pitch(), u.roll())}});
  }
  return dump({{"transforms", std::move(transforms)}});
}

std::string frame_json(std::string_view topic, uint64_t time_ns, double wall_ms) {
  return dump({{"topic", topic}, {"time_ns", time_ns}, {"wall_ms", wall_ms}});
}

}  // namespace convoy::scene
