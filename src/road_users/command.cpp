#include "road_users/command.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <initializer_list>
#include <utility>

#include "opendrive/network.h"

namespace convoy::road_users {
namespace odr = convoy::opendrive;
using nlohmann::json;

namespace {

[[noreturn]] void fail(const std::string& key, const std::string& detail) {
  throw CommandError(key, detail);
}

std::string shown(const json& v) { return v.dump().substr(0, 80); }

// v is an object whose keys are all among `known`.
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

// obj[k], which must be there and a finite number.
double number(const std::string& key, const json& obj, const char* k) {
  if (!obj.contains(k)) fail(key + "." + k, "missing (a number)");
  const json& v = obj[k];
  if (!v.is_number() || !std::isfinite(v.get<double>()))
    fail(key + "." + k, "expected a number, got " + shown(v));
  return v.get<double>();
}

double speed_of(const std::string& key, const json& v) {
  const double speed = number(key, v, "speed");
  if (speed < 0) fail(key + ".speed", "must be >= 0 m/s (reversing is not modelled)");
  return speed;
}

VehicleCommand::Pose parse_pose(const std::string& key, const json& v, bool speed_needed) {
  check_object(key, v, {"x", "y", "z", "yaw", "speed"});
  VehicleCommand::Pose p;
  p.x = number(key, v, "x");
  p.y = number(key, v, "y");
  p.yaw = number(key, v, "yaw");
  if (v.contains("z")) number(key, v, "z");
  if (v.contains("speed") || speed_needed) p.speed = speed_of(key, v);
  return p;
}

VehicleCommand::Speed parse_speed(const std::string& key, const json& v) {
  check_object(key, v, {"speed", "target_speed", "acceleration"});
  VehicleCommand::Speed sp;
  sp.speed = speed_of(key, v);
  if (v.contains("target_speed")) number(key, v, "target_speed");
  if (v.contains("acceleration")) sp.acceleration = number(key, v, "acceleration");
  return sp;
}

// v[n]: a non-zero integer lane id that `road` has in some section.
int lane_id(const std::string& key, const json& v, const char* n, const odr::Road& road) {
  if (!v.contains(n) || !v[n].is_number_integer() || v[n].get<int64_t>() == 0)
    fail(key + "." + n, "expected a non-zero integer lane id, got " +
                            (v.contains(n) ? v[n].dump() : std::string("nothing")));
  const int id = v[n].get<int>();
  bool found = false;
  for (const auto& sec : road.sections) found = found || sec.find_lane(id) != nullptr;
  if (!found) fail(key + "." + n, "road " + road.id + " has no lane " + std::to_string(id));
  return id;
}

VehicleCommand::Lane parse_lane(const std::string& key, const json& v, const odr::Network& net) {
  check_object(key, v, {"road", "lane", "from_lane", "offset", "progress"});
  VehicleCommand::Lane ln;
  if (!v.contains("road") || !v["road"].is_string())
    fail(key + ".road", "expected the road's id as a string");
  ln.road = v["road"].get<std::string>();
  const odr::Road* road = net.find_road(ln.road);
  if (!road) fail(key + ".road", "no road " + ln.road + " in " + net.source);
  ln.lane = lane_id(key, v, "lane", *road);
  ln.from_lane = v.contains("from_lane") ? lane_id(key, v, "from_lane", *road) : ln.lane;
  ln.offset = v.contains("offset") ? number(key, v, "offset") : 0.0;
  ln.progress = v.contains("progress") ? number(key, v, "progress") : 1.0;
  if (ln.progress < 0 || ln.progress > 1)
    fail(key + ".progress", "must be in [0, 1], got " + v["progress"].dump());
  return ln;
}

Points parse_route(const std::string& key, const json& v, const odr::LaneGraph& graph) {
  check_object(key, v, {"positions"});
  if (!v.contains("positions")) fail(key + ".positions", "missing (a list of [x, y])");
  Points pts = parse_points(key + ".positions", v["positions"], 1);
  for (size_t i = 0; i < pts.size(); ++i) {
    const auto loc = graph.locate_if(pts[i][0], pts[i][1], std::nullopt, 20.0,
                                     [](const odr::LaneNode& n, double) { return n.drivable(); });
    if (loc) continue;
    char what[160];
    std::snprintf(what, sizeof what, "(%.2f, %.2f) is farther than 20 m from any driving lane of ",
                  pts[i][0], pts[i][1]);
    fail(key + ".positions[" + std::to_string(i) + "]", what + graph.network().source);
  }
  return pts;
}

void parse_trajectory(const std::string& key, const json& v, VehicleCommand& c) {
  if (!v.is_object()) fail(key, "expected an object, got " + shown(v));
  if (v.contains("polyline")) {
    check_object(key, v, {"polyline", "length"});
    if (v.contains("length")) number(key, v, "length");
    c.polyline = parse_points(key + ".polyline", v["polyline"], 1);
  } else {
    c.timed = parse_pose(key, v, true);
  }
}

// The parts that cannot be given together.
void check_combination(const std::string& where, const VehicleCommand& c) {
  if (c.timed && (c.speed || c.lane))
    fail(where + ".trajectory", "a timed trajectory sets both speed and lane: give it alone");
  if (c.polyline && c.lane)
    fail(where + ".trajectory", "both lane and trajectory steer: give one of them");
  if (c.teleport && (c.timed || c.polyline))
    fail(where + ".teleport", "give teleport or trajectory, not both");
}

}  // namespace

Points parse_points(const std::string& key, const json& v, size_t min_points) {
  if (!v.is_array() || v.size() < min_points)
    fail(key, "expected a list of at least " + std::to_string(min_points) + " points [x, y], got " +
                  shown(v));
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

VehicleCommand parse_vehicle_command(const json& j, const std::string& where,
                                     const odr::LaneGraph& graph) {
  if (!j.is_object()) fail(where, "expected a JSON object of commands, got " + shown(j));
  VehicleCommand c;
  for (const auto& [k, v] : j.items()) {
    const std::string key = where + "." + k;
    if (k == "time_ns") {
      if (!v.is_number()) fail(key, "expected a number (ns)");
    } else if (k == "speed") {
      c.speed = parse_speed(key, v);
    } else if (k == "lane") {
      c.lane = parse_lane(key, v, graph.network());
    } else if (k == "route") {
      c.route = parse_route(key, v, graph);
    } else if (k == "trajectory") {
      parse_trajectory(key, v, c);
    } else if (k == "teleport") {
      c.teleport = parse_pose(key, v, false);
    } else {
      fail(key, "unknown key (time_ns, speed, lane, route, trajectory, teleport)");
    }
  }
  check_combination(where, c);
  return c;
}

}  // namespace convoy::road_users
