#include "road_users/command_parts.h"

#include <cmath>
#include <cstdio>

#include "opendrive/network.h"

namespace convoy::road_users {
using nlohmann::json;

namespace command_parts {

void fail(const std::string& key, const std::string& detail) { throw CommandError(key, detail); }

std::string shown(const json& v) { return v.dump().substr(0, 80); }

void check_object(const std::string& key, const json& v, std::initializer_list<const char*> known) {
  if (!v.is_object()) fail(key, "expected an object, got " + shown(v));
  for (const auto& [k, x] : v.items()) {
    bool ok = false;
    std::string list;
    for (const char* n : known) {
      ok = ok || k == n;
      list += std::string(list.empty() ? "" : ", ") + n;
    }
    if (!ok) fail(key + "." + k, "unknown key (" + list + ")");
  }
}

double number(const std::string& key, const json& obj, const char* k) {
  if (!obj.contains(k)) fail(key + "." + k, "missing (a number)");
  const json& v = obj[k];
  if (!v.is_number() || !std::isfinite(v.get<double>()))
    fail(key + "." + k, "expected a number, got " + shown(v));
  return v.get<double>();
}

double speed_of(const std::string& key, const json& v, const std::string& note) {
  const double speed = number(key, v, "speed");
  if (speed < 0) fail(key + ".speed", "must be >= 0 m/s" + note);
  return speed;
}

CommandPose parse_pose(const std::string& key, const json& v, bool speed_needed,
                       const std::string& note) {
  check_object(key, v, {"x", "y", "z", "yaw", "speed"});
  CommandPose p;
  p.x = number(key, v, "x");
  p.y = number(key, v, "y");
  p.yaw = number(key, v, "yaw");
  if (v.contains("z")) number(key, v, "z");
  if (v.contains("speed") || speed_needed) p.speed = speed_of(key, v, note);
  return p;
}

namespace {

// The points of list v (each [x, y] or [x, y, z] of finite numbers).
Points points_of(const std::string& key, const json& v) {
  Points out;
  for (size_t i = 0; i < v.size(); ++i) {
    const json& p = v[i];
    const std::string k = key + "[" + std::to_string(i) + "]";
    if (!p.is_array() || p.size() < 2 || p.size() > 3)
      fail(k, "expected a point [x, y] (or [x, y, z]), got " + shown(p));
    for (const json& x : p) {
      if (!x.is_number() || !std::isfinite(x.get<double>()))
        fail(k, "expected numbers, got " + shown(p));
    }
    out.push_back({p[0].get<double>(), p[1].get<double>()});
  }
  return out;
}

}  // namespace

Points parse_point_list(const std::string& key, const json& v) {
  if (!v.is_array() || v.empty()) fail(key, "expected a list of points [x, y], got " + shown(v));
  return points_of(key, v);
}

Points parse_route(const std::string& key, const json& v, const opendrive::LaneGraph& graph,
                   ListParser list, bool driving) {
  check_object(key, v, {"positions"});
  if (!v.contains("positions")) fail(key + ".positions", "missing (a list of [x, y])");
  Points pts = list(key + ".positions", v["positions"]);
  for (size_t i = 0; i < pts.size(); ++i) {
    const auto loc =
        driving ? graph.locate_if(pts[i][0], pts[i][1], std::nullopt, 20.0,
                                  [](const opendrive::LaneNode& n, double) { return n.drivable(); })
                : graph.locate(pts[i][0], pts[i][1], std::nullopt, 20.0);
    if (loc) continue;
    char what[160];
    std::snprintf(what, sizeof what, "(%.2f, %.2f) is farther than 20 m from any %slane of ",
                  pts[i][0], pts[i][1], driving ? "driving " : "");
    fail(key + ".positions[" + std::to_string(i) + "]", what + graph.network().source);
  }
  return pts;
}

void parse_trajectory(const std::string& key, const json& v, ListParser list,
                      const std::string& note, PathCommand& c) {
  if (!v.is_object()) fail(key, "expected an object, got " + shown(v));
  if (v.contains("polyline")) {
    check_object(key, v, {"polyline", "length"});
    if (v.contains("length")) number(key, v, "length");
    c.polyline = list(key + ".polyline", v["polyline"]);
  } else {
    c.timed = parse_pose(key, v, true, note);
  }
}

void parse_path_command(const json& j, const std::string& where, const opendrive::LaneGraph& graph,
                        const PathParts& how, PathCommand& c, const OtherPart& other) {
  if (!j.is_object()) fail(where, "expected a JSON object of commands, got " + shown(j));
  for (const auto& [k, v] : j.items()) {
    const std::string key = where + "." + k;
    if (k == "time_ns") {
      if (!v.is_number()) fail(key, "expected a number (ns)");
    } else if (k == "route") {
      c.route = parse_route(key, v, graph, how.list, how.driving);
    } else if (k == "trajectory") {
      parse_trajectory(key, v, how.list, how.note, c);
    } else if (k == "teleport") {
      c.teleport = parse_pose(key, v, false, how.note);
    } else {
      other(key, k, v);
    }
  }
}

}  // namespace command_parts

Points parse_points(const std::string& key, const json& v, size_t min_points) {
  if (!v.is_array() || v.size() < min_points)
    command_parts::fail(key, "expected a list of at least " + std::to_string(min_points) +
                                 " points [x, y], got " + command_parts::shown(v));
  return command_parts::points_of(key, v);
}

}  // namespace convoy::road_users
