// EngineType "vehicle_agent": one road vehicle as its own engine, on an OpenDRIVE lane graph.
//
// Longitudinal: IDM (v0, T, s0, a, b, delta) on the leader ahead on its path (from its
// neighbour input) and, for a red (or stoppable yellow) light, on the light's stop line as a
// standing virtual leader. Lateral: pure pursuit on the route's sampled lane-centre poses,
// moved as a kinematic bicycle (reference point: the rear axle). Lane changes: MOBIL
// (politeness, threshold, b_safe) into a lane the lane graph allows a change to. Inputs are
// acted on ReactionTime late. Deterministic: no wall clock, the only randomness is Seed's.
//
// Config keys (schema.json): Map, Route {from, to} ("ROAD:LANE") or Seed, StartS,
// InitialSpeed, Model, Category, Length, Width, Height, Wheelbase, v0, SpeedLimitFactor, T,
// s0, a, b, delta, MaxDeceleration, politeness, threshold, b_safe, LaneChanges, ReactionTime,
// NeighbourRadius, StateDataPack, NeighboursDataPack, TrafficLightsDataPack, WeatherDataPack,
// WeatherAdaptation.
//
// Datapacks written:
//   <StateDataPack> ("state")  convoy.data.RoadUser: its state after each step, with
//                    road/lane/s/t; BRAKE while decelerating, an indicator while changing
//                    lanes; `absent` once its route has ended.
// Datapacks read:
//   <NeighboursDataPack> ("neighbours")  convoy.data.RoadUsers (or one RoadUser): the road
//                    users around it (its own id is skipped).
//   <TrafficLightsDataPack> ("traffic_lights")  JSON {"time_ns", "signals": {"<signal id>":
//                    "red"|"yellow"|"green"|"red_yellow"|"off"}}; a missing signal is green.
//   <WeatherDataPack> ("weather")  optional: the weather engine's JSON. With WeatherAdaptation
//                    (default on) it drives as people do in bad weather (docs/weather.md):
//                    on a road of friction mu (0.8 dry) its desired speed is
//                    x (1 - 0.4 (1 - mu/0.8)) and its time headway T x (1 + 0.5 (1 - mu/0.8));
//                    a and b are at most 0.5 mu g; in fog (visibility V < 1000 m) T grows by
//                    up to 30 % more and its speed is capped so that it stops within V (1.5 s
//                    of reaction plus braking at 0.5 mu g).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "convoy/road_users.pb.h"
#include "datapack/json.h"
#include "datapack/proto.h"
#include "datapack/registry.h"
#include "engine/engine.h"
#include "opendrive/lane_graph.h"
#include "opendrive/parser.h"

namespace convoy::engines::vehicle_agent {
namespace odr = convoy::opendrive;
using nlohmann::json;

namespace {

constexpr double kSampleDs = 0.5;  // m between the path's poses

struct Idm {
  double v0 = 13.9, T = 1.5, s0 = 2.0, a = 1.5, b = 2.0, delta = 4.0;
  // Acceleration at speed v with a leader `gap` m ahead (bumper to bumper) at speed vl;
  // gap = +inf: free road.
  double accel(double v, double gap, double vl, double v0_here) const {
    const double v0e = std::max(v0_here, 0.1);
    double acc = a * (1.0 - std::pow(std::max(v, 0.0) / v0e, delta));
    if (std::isfinite(gap)) {
      const double dv = v - vl;
      const double s_star = s0 + std::max(0.0, v * T + v * dv / (2.0 * std::sqrt(a * b)));
      const double g = std::max(gap, 0.01);
      acc -= a * (s_star / g) * (s_star / g);
    }
    return acc;
  }
};

struct Path {
  std::vector<odr::Pose2> poses;
  std::vector<double> arc;  // arc length at each pose
  odr::LaneRoute route;
  std::vector<std::pair<double, std::string>> stops;  // (arc of stop line, signal id)
  struct Crossing {
    std::string junction;
    double enter = 0, exit = 0;  // arcs
  };
  std::vector<Crossing> crossings;  // junctions crossed, in order
  double length() const { return arc.empty() ? 0 : arc.back(); }
  // Pose at arc length a (clamped).
  odr::Pose2 at(double a) const {
    if (poses.empty()) return {};
    if (a <= 0) return poses.front();
    if (a >= arc.back()) return poses.back();
    size_t i = std::upper_bound(arc.begin(), arc.end(), a) - arc.begin();
    const odr::Pose2& p = poses[i - 1];
    const odr::Pose2& q = poses[i];
    const double f = (a - arc[i - 1]) / std::max(arc[i] - arc[i - 1], 1e-9);
    odr::Pose2 r = p;
    r.x = p.x + f * (q.x - p.x);
    r.y = p.y + f * (q.y - p.y);
    r.heading = p.heading + f * std::remainder(q.heading - p.heading, 2 * M_PI);
    return r;
  }
  // Projection of (x, y) onto the path among poses [lo, hi): (arc, signed lateral offset,
  // squared distance to the nearest pose).
  struct Proj {
    double arc = 0, lateral = 0, d2 = INFINITY;
    size_t index = 0;
  };
  Proj project(double x, double y, size_t lo = 0, size_t hi = SIZE_MAX) const {
    Proj best;
    hi = std::min(hi, poses.size());
    for (size_t i = lo; i < hi; ++i) {
      const double dx = x - poses[i].x, dy = y - poses[i].y;
      const double d2 = dx * dx + dy * dy;
      if (d2 < best.d2) {
        best.d2 = d2;
        best.index = i;
      }
    }
    if (!std::isfinite(best.d2)) return best;
    const odr::Pose2& p = poses[best.index];
    const double c = std::cos(p.heading), s = std::sin(p.heading);
    const double dx = x - p.x, dy = y - p.y;
    best.arc = arc[best.index] + dx * c + dy * s;
    best.lateral = -dx * s + dy * c;
    return best;
  }
};

struct Snapshot {
  int64_t time_ns = 0;
  std::shared_ptr<const data::RoadUsers> neighbours;
  std::shared_ptr<const json> lights;
};

}  // namespace

class VehicleAgent final : public Engine {
 public:
  std::vector<engine::DataPackId> initialize(const std::string& name, const json& config,
                                             int64_t timestep_ns) override;
  int64_t step(int64_t duration_ns) override;
  void set_datapack(const datapack::View& dp) override;
  void get_datapack(const engine::DataPackId& id, datapack::Builder& out) override;
  void reset() override { start(); }
  std::vector<std::string> take_warnings() override { return std::move(warnings_); }

 private:
  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw std::runtime_error("vehicle_agent '" + name_ + "': " + key + ": " + what);
  }
  void warn_once(const std::string& key, const std::string& text) {
    if (warned_[key]) return;
    warned_[key] = true;
    std::fprintf(stderr, "warning: vehicle_agent '%s': %s\n", name_.c_str(), text.c_str());
    warnings_.push_back(text);
  }
  std::pair<std::string, int> parse_lane(const std::string& key, const json& v) const;
  odr::LaneRoute pick_route(const json& config, uint64_t seed) const;
  Path make_path(const odr::LaneRoute& route) const;
  void start();
  // Respawn: back at its start once its route has ended, RespawnDelay has passed and the
  // start is free (nobody within its length + 6 m of it in its latest view).
  bool start_free() const;
  void restart();
  void publish();
  double desired_speed() const;
  // The leader ahead on `path` from arc `me` (my front bumper's arc): (gap, speed).
  std::pair<double, double> leader_on(const Path& path, double my_arc, size_t cursor) const;
  void consider_lane_change();
  // Gap to the entry of the next junction when it must wait there (first come by arrival
  // time, ties by id; anyone inside blocks), else +inf.
  double junction_wait(double my_front, const Snapshot* snap) const;
  // Whether one whose front is at front_s on `lane` waits at a red light: the lane's light
  // is red and its front has not passed the light's stop line.
  bool red_for(odr::LaneIndex lane, double front_s, const Snapshot* snap) const;
  const Snapshot* perceived() const;

  std::string name_;
  std::unique_ptr<odr::Network> net_;
  std::unique_ptr<odr::LaneGraph> graph_;
  Idm idm_;
  double limit_factor_ = 0, max_decel_ = 9, politeness_ = 0.3, threshold_ = 0.2, b_safe_ = 4;
  bool lane_changes_ = true, yielding_ = true;
  double reaction_s_ = 0, radius_ = 100, start_s_ = 0, initial_speed_ = 0;
  double length_ = 4.5, width_ = 1.8, height_ = 1.5, wheelbase_ = 2.7, rear_overhang_ = 0.9;
  std::string model_, category_;
  std::string state_dp_, neighbours_dp_, lights_dp_, weather_dp_;
  // Weather: the configured IDM, and the factors the weather applies to it (see the header).
  bool weather_adaptation_ = true;
  Idm base_idm_;
  double speed_factor_ = 1.0, visibility_speed_ = INFINITY;
  void adapt_to_weather(double mu, double visibility_m);
  odr::LaneRoute initial_route_;
  odr::LaneIndex dest_lane_ = odr::kNoLane;
  double dest_s_ = 0;

  // State.
  int64_t timestep_ns_ = 0, time_ns_ = 0;
  Path path_;
  size_t cursor_ = 0;  // index of the nearest path pose
  double arc_ = 0;     // rear axle's arc along path_
  double x_ = 0, y_ = 0, yaw_ = 0, v_ = 0, acc_ = 0, yaw_rate_ = 0;
  bool absent_ = false;
  bool respawn_ = false;
  double respawn_delay_s_ = 2.0;
  int64_t absent_since_ns_ = 0;
  odr::Pose2 initial_path_start_{};
  int changing_ = 0;  // +1 left, -1 right while a lane change is under way
  int64_t next_mobil_ns_ = 0;
  std::deque<Snapshot> inputs_;
  std::shared_ptr<const data::RoadUsers> last_neighbours_;
  std::shared_ptr<const json> last_lights_;
  data::RoadUser state_;
  std::map<std::string, bool> warned_;
  std::vector<std::string> warnings_;
};

std::pair<std::string, int> VehicleAgent::parse_lane(const std::string& key, const json& v) const {
  if (!v.is_string()) fail(key, "expected \"ROAD:LANE\"");
  const std::string s = v.get<std::string>();
  const auto colon = s.rfind(':');
  if (colon == std::string::npos || colon == 0)
    fail(key, "expected \"ROAD:LANE\", got \"" + s + "\"");
  try {
    size_t used = 0;
    const int lane = std::stoi(s.substr(colon + 1), &used);
    if (used != s.size() - colon - 1 || lane == 0) throw std::invalid_argument("lane");
    return {s.substr(0, colon), lane};
  } catch (const std::exception&) {
    fail(key, "expected \"ROAD:LANE\" with a non-zero lane id, got \"" + s + "\"");
  }
}

odr::LaneRoute VehicleAgent::pick_route(const json& config, uint64_t seed) const {
  const json& r = config.at("Route");
  const json& pos = config.at("Position");
  if (!pos.is_object()) fail("Position", "expected {\"x\": ..., \"y\": ...}");
  if (!pos.empty()) {
    // Placed at a world point: on a driving lane there, routed to Route.to.
    if (!pos.contains("x") || !pos.contains("y") || !pos["x"].is_number() || !pos["y"].is_number())
      fail("Position", "expected numbers \"x\" and \"y\"");
    const double x = pos["x"].get<double>(), y = pos["y"].get<double>();
    std::optional<double> heading;
    if (pos.contains("yaw")) heading = pos["yaw"].get<double>();
    char where[96];
    std::snprintf(where, sizeof where, "(%.2f, %.2f)", x, y);
    const auto loc = graph_->locate(x, y, heading, 50.0);
    if (!loc || loc->distance > 0 || !graph_->lane(loc->lane).drivable()) {
      std::string near = "no road within 50 m";
      if (loc) {
        char d[160];
        std::snprintf(d, sizeof d, "nearest lane %s:%d (%s) %.2f m away", loc->road_id.c_str(),
                      loc->lane_id, graph_->lane(loc->lane).type.c_str(), loc->distance);
        near = d;
      }
      fail("Position", std::string("placed off-road: ") + where + " is not on a driving lane of " +
                           net_->source + " (" + near + ")");
    }
    if (r.contains("from")) fail("Route.from", "give Route.from or Position, not both");
    if (!r.contains("to")) fail("Route.to", "needed with Position (where to drive)");
    const auto [tr, tl] = parse_lane("Route.to", r["to"]);
    if (!net_->find_road(tr)) fail("Route.to", "road " + tr + " is not in the map " + net_->source);
    odr::LaneIndex dest = odr::kNoLane;
    try {
      dest = graph_->exit_lane(tr, tl);
    } catch (const std::exception& e) {
      fail("Route.to", e.what());
    }
    const odr::LaneNode& dn = graph_->lane(dest);
    auto route = graph_->route(loc->lane, loc->s, dest, dn.forward ? dn.s1 : dn.s0);
    if (!route) {
      fail("Route", std::string("no route from ") + where + " (" + loc->road_id + ":" +
                        std::to_string(loc->lane_id) + ") to " + r["to"].get<std::string>());
    }
    return *route;
  }
  if (r.is_object() && (r.contains("from") || r.contains("to"))) {
    if (!r.contains("from") || !r.contains("to")) fail("Route", "give both \"from\" and \"to\"");
    for (const auto& [k, v] : r.items()) {
      if (k != "from" && k != "to") fail("Route", "unknown key \"" + k + "\" (from, to)");
    }
    const auto [fr, fl] = parse_lane("Route.from", r["from"]);
    const auto [tr, tl] = parse_lane("Route.to", r["to"]);
    for (const auto& [key, road, lane] :
         {std::tuple{"Route.from", fr, fl}, std::tuple{"Route.to", tr, tl}}) {
      if (!net_->find_road(road)) fail(key, "road " + road + " is not in the map " + net_->source);
      odr::LaneIndex li = odr::kNoLane;
      try {
        li = graph_->entry_lane(road, lane);
      } catch (const std::exception& e) {
        fail(key, e.what());
      }
      if (li == odr::kNoLane)
        fail(key, "road " + road + " has no lane " + std::to_string(lane) + " (in " + net_->source +
                      ")");
      if (!graph_->lane(li).drivable())
        fail(key, "lane " + road + ":" + std::to_string(lane) + " is a " + graph_->lane(li).type +
                      " lane, not a driving lane");
    }
    auto route = graph_->route(fr, fl, tr, tl);
    if (!route) {
      fail("Route", "no route from " + r["from"].get<std::string>() + " to " +
                        r["to"].get<std::string>() + " on the lane graph of " + net_->source);
    }
    return *route;
  }
  if (!r.is_object() || !r.empty())
    fail("Route", "expected {\"from\": \"ROAD:LANE\", \"to\": \"ROAD:LANE\"}");
  // Drawn from the seed: a random driving lane outside junctions to another one.
  std::vector<odr::LaneIndex> lanes;
  for (const auto& l : graph_->lanes()) {
    if (l.drivable() && l.junction == "-1") lanes.push_back(l.index);
  }
  if (lanes.empty()) fail("Map", "no driving lane outside junctions in " + net_->source);
  std::mt19937_64 rng(seed);
  for (int attempt = 0; attempt < 200; ++attempt) {
    const auto& a = graph_->lane(lanes[rng() % lanes.size()]);
    const auto& b = graph_->lane(lanes[rng() % lanes.size()]);
    if (a.road == b.road) continue;
    auto route = graph_->route(a.road->id, a.lane_id, b.road->id, b.lane_id);
    if (route && route->length > 50 && !route->junctions.empty()) return *route;
  }
  fail("Route", "none given, and no route through a junction could be drawn from Seed " +
                    std::to_string(seed) + " on " + net_->source);
}

Path VehicleAgent::make_path(const odr::LaneRoute& route) const {
  Path p;
  p.route = route;
  p.poses = graph_->sample(route, kSampleDs);
  p.arc.resize(p.poses.size());
  for (size_t i = 1; i < p.poses.size(); ++i) {
    p.arc[i] =
        p.arc[i - 1] + std::hypot(p.poses[i].x - p.poses[i - 1].x, p.poses[i].y - p.poses[i - 1].y);
  }
  // Stop lines: each traffic light that applies to a lane of the route, where the route
  // passes its s.
  for (const auto& sig : graph_->signals()) {
    if (!sig.traffic_light || !sig.signal) continue;
    for (const auto& seg : route.segments) {
      if (seg.road_id != sig.road_id) continue;
      if (std::find(sig.lanes.begin(), sig.lanes.end(), seg.lane) == sig.lanes.end()) continue;
      const double lo = std::min(seg.s_from, seg.s_to), hi = std::max(seg.s_from, seg.s_to);
      const double s = sig.signal->s;
      if (s < lo - 1e-6 || s > hi + 1e-6) continue;
      const odr::WorldPose w = graph_->world_pose(seg.road_id, seg.lane_id, s);
      const auto pr = p.project(w.x, w.y);
      if (pr.d2 < 4.0) p.stops.emplace_back(pr.arc, sig.signal->id);
    }
  }
  std::sort(p.stops.begin(), p.stops.end());
  // Junction crossings: runs of segments in one junction, from the first one's start to the
  // last one's end.
  const auto& segs = route.segments;
  for (size_t i = 0; i < segs.size();) {
    if (segs[i].junction == "-1") {
      ++i;
      continue;
    }
    size_t j = i;
    while (j + 1 < segs.size() && segs[j + 1].junction == segs[i].junction) ++j;
    const odr::WorldPose a = graph_->world_pose(segs[i].road_id, segs[i].lane_id, segs[i].s_from);
    const odr::WorldPose b = graph_->world_pose(segs[j].road_id, segs[j].lane_id, segs[j].s_to);
    const auto pa = p.project(a.x, a.y), pb = p.project(b.x, b.y);
    p.crossings.push_back({segs[i].junction, std::max(0.0, pa.arc), pb.arc});
    i = j + 1;
  }
  return p;
}

std::vector<engine::DataPackId> VehicleAgent::initialize(const std::string& name,
                                                         const json& config, int64_t timestep_ns) {
  name_ = name;
  timestep_ns_ = timestep_ns;
  if (!config.contains("Map") || !config["Map"].is_string())
    fail("Map", "no map given (an OpenDRIVE .xodr file)");
  try {
    net_ = std::make_unique<odr::Network>(odr::load(config["Map"].get<std::string>()));
    graph_ = std::make_unique<odr::LaneGraph>(*net_);
  } catch (const std::exception& e) {
    fail("Map", e.what());
  }
  idm_.v0 = config.at("v0").get<double>();
  idm_.T = config.at("T").get<double>();
  idm_.s0 = config.at("s0").get<double>();
  idm_.a = config.at("a").get<double>();
  idm_.b = config.at("b").get<double>();
  idm_.delta = config.at("delta").get<double>();
  limit_factor_ = config.at("SpeedLimitFactor").get<double>();
  max_decel_ = config.at("MaxDeceleration").get<double>();
  politeness_ = config.at("politeness").get<double>();
  threshold_ = config.at("threshold").get<double>();
  b_safe_ = config.at("b_safe").get<double>();
  lane_changes_ = config.at("LaneChanges").get<bool>();
  yielding_ = config.at("JunctionYielding").get<bool>();
  reaction_s_ = config.at("ReactionTime").get<double>();
  radius_ = config.at("NeighbourRadius").get<double>();
  start_s_ = config.at("StartS").get<double>();
  initial_speed_ = config.at("InitialSpeed").get<double>();
  respawn_ = config.at("Respawn").get<bool>();
  respawn_delay_s_ = config.at("RespawnDelay").get<double>();
  model_ = config.at("Model").get<std::string>();
  category_ = config.at("Category").get<std::string>();
  length_ = config.at("Length").get<double>();
  width_ = config.at("Width").get<double>();
  height_ = config.at("Height").get<double>();
  wheelbase_ = config.at("Wheelbase").get<double>();
  if (wheelbase_ >= length_) fail("Wheelbase", "must be shorter than Length");
  rear_overhang_ = 0.5 * (length_ - wheelbase_);
  state_dp_ = config.at("StateDataPack").get<std::string>();
  neighbours_dp_ = config.at("NeighboursDataPack").get<std::string>();
  lights_dp_ = config.at("TrafficLightsDataPack").get<std::string>();
  weather_dp_ = config.at("WeatherDataPack").get<std::string>();
  weather_adaptation_ = config.at("WeatherAdaptation").get<bool>();
  base_idm_ = idm_;

  initial_route_ = pick_route(config, config.at("Seed").get<uint64_t>());
  const auto& last = initial_route_.segments.back();
  dest_lane_ = last.lane;
  dest_s_ = last.s_to;
  {
    Path p = make_path(initial_route_);
    if (p.poses.size() < 2) fail("Route", "the route is empty");
    if (start_s_ >= p.length())
      fail("StartS", "placed off its route: " + std::to_string(start_s_) +
                         " m is beyond the route's end (" + std::to_string(p.length()) + " m)");
  }
  start();

  std::vector<engine::DataPackId> ids(1);
  ids[0].set_name(state_dp_);
  ids[0].set_type(std::string(datapack::type_name<data::RoadUser>()));
  ids[0].set_engine_name(name);
  return ids;
}

bool VehicleAgent::start_free() const {
  const Snapshot* snap = perceived();
  if (!snap || !snap->neighbours) return false;
  const odr::Pose2 p = initial_path_start_;
  for (const auto& u : snap->neighbours->users()) {
    if (u.absent() || u.id() == name_) continue;
    if (std::hypot(u.x() - p.x, u.y() - p.y) < length_ + 6.0) return false;
  }
  return true;
}

void VehicleAgent::restart() {
  path_ = make_path(initial_route_);
  arc_ = start_s_;
  const odr::Pose2 p = path_.at(arc_);
  x_ = p.x;
  y_ = p.y;
  yaw_ = p.heading;
  v_ = initial_speed_;
  acc_ = 0;
  yaw_rate_ = 0;
  absent_ = false;
  changing_ = 0;
  next_mobil_ns_ = time_ns_;
  cursor_ = path_.project(x_, y_).index;
}

void VehicleAgent::start() {
  path_ = make_path(initial_route_);
  time_ns_ = 0;
  arc_ = start_s_;
  const odr::Pose2 p = path_.at(arc_);
  initial_path_start_ = p;
  x_ = p.x;
  y_ = p.y;
  yaw_ = p.heading;
  v_ = initial_speed_;
  acc_ = 0;
  yaw_rate_ = 0;
  absent_ = false;
  absent_since_ns_ = 0;
  changing_ = 0;
  next_mobil_ns_ = 0;
  inputs_.clear();
  last_neighbours_.reset();
  last_lights_.reset();
  cursor_ = path_.project(x_, y_).index;
  state_.Clear();
  state_.set_id(name_);
  state_.set_category(category_);
  state_.set_model(model_);
  state_.set_length(length_);
  state_.set_width(width_);
  state_.set_height(height_);
  state_.set_length_offset(0.5 * length_ - rear_overhang_);
  publish();
}

double VehicleAgent::desired_speed() const {
  double v = idm_.v0;
  if (limit_factor_ > 0 && !path_.route.segments.empty()) {
    if (const auto loc = graph_->locate(x_, y_, yaw_)) {
      const odr::SpeedLimit lim = graph_->speed_limit(loc->lane, loc->s);
      if (lim.known && std::isfinite(lim.mps)) v = limit_factor_ * lim.mps * speed_factor_;
    }
  }
  return std::min(v, visibility_speed_);
}

void VehicleAgent::adapt_to_weather(double mu, double visibility_m) {
  idm_ = base_idm_;
  speed_factor_ = 1.0;
  visibility_speed_ = INFINITY;
  if (!weather_adaptation_) return;
  const double loss = std::clamp(1.0 - mu / 0.8, 0.0, 1.0);  // 0 dry .. 1 no grip
  const double grip = std::max(0.5 * mu * 9.81, 0.3);        // comfortable use of the grip
  speed_factor_ = 1.0 - 0.4 * loss;
  idm_.v0 = base_idm_.v0 * speed_factor_;
  idm_.T = base_idm_.T * (1.0 + 0.5 * loss);
  idm_.a = std::min(base_idm_.a, grip);
  idm_.b = std::min(base_idm_.b, grip);
  if (visibility_m < 1000.0) {
    idm_.T *= 1.0 + 0.3 * std::clamp((1000.0 - visibility_m) / 900.0, 0.0, 1.0);
    // Stop within the visibility: 1.5 s v + v^2 / (2 grip) = V.
    const double tr = 1.5;
    visibility_speed_ = grip * (-tr + std::sqrt(tr * tr + 2.0 * visibility_m / grip));
  }
}

const Snapshot* VehicleAgent::perceived() const {
  // The newest input at least ReactionTime old.
  const int64_t limit = time_ns_ - static_cast<int64_t>(std::llround(reaction_s_ * 1e9));
  const Snapshot* best = nullptr;
  for (const auto& s : inputs_) {
    if (s.time_ns <= limit) best = &s;
  }
  return best;
}

std::pair<double, double> VehicleAgent::leader_on(const Path& path, double my_front,
                                                  size_t cursor) const {
  double gap = INFINITY, speed = 0;
  const Snapshot* snap = perceived();
  if (!snap || !snap->neighbours) return {gap, speed};
  const size_t hi = cursor + static_cast<size_t>(radius_ / kSampleDs) + 2;
  const size_t lo = cursor > 10 ? cursor - 10 : 0;
  for (const auto& u : snap->neighbours->users()) {
    if (u.absent() || u.id() == name_) continue;
    if (std::hypot(u.x() - x_, u.y() - y_) > radius_) continue;
    const auto pr = path.project(u.x(), u.y(), lo, hi);
    if (!std::isfinite(pr.d2)) continue;
    const double half_w = 0.5 * (u.width() > 0 ? u.width() : 1.8);
    if (std::abs(pr.lateral) > 1.0 + half_w) continue;  // not in my lane
    const double rear = pr.arc + u.length_offset() - 0.5 * u.length();
    const double front = pr.arc + u.length_offset() + 0.5 * u.length();
    if (front <= my_front) continue;  // behind (or beside) me
    const double g = rear - my_front;
    if (g < gap) {
      gap = g;
      speed = u.speed();
    }
  }
  return {gap, speed};
}

void VehicleAgent::consider_lane_change() {
  // MOBIL, in the local frame at the agent: neighbours by longitudinal (along my heading)
  // and lateral offset, each lane a band around its centre.
  const auto loc = graph_->locate(x_, y_, yaw_);
  if (!loc || loc->lane == odr::kNoLane) return;
  const odr::LaneNode& lane = graph_->lane(loc->lane);
  if (lane.junction != "-1") return;
  const Snapshot* snap = perceived();
  const double c = std::cos(yaw_), s = std::sin(yaw_);
  const double my_front = 0.5 * length_ + (0.5 * length_ - rear_overhang_);
  const double my_rear = -rear_overhang_;
  const double v0 = desired_speed();
  struct Near {
    double gap = INFINITY;
    double speed = 0;
    double gap_to_next = INFINITY;  // follower: its gap to my leader position (filled later)
    bool found = false;
    double lon = 0;
  };
  // Leader / follower in the band with centre offset `centre` (lateral, m) and half width hw.
  auto scan = [&](double centre, double hw, Near& lead, Near& follow) {
    if (!snap || !snap->neighbours) return;
    for (const auto& u : snap->neighbours->users()) {
      if (u.absent() || u.id() == name_) continue;
      const double dx = u.x() - x_, dy = u.y() - y_;
      const double lon = dx * c + dy * s, lat = -dx * s + dy * c;
      if (std::abs(lon) > radius_ || std::abs(lat - centre) > hw) continue;
      const double u_front = lon + u.length_offset() + 0.5 * u.length();
      const double u_rear = lon + u.length_offset() - 0.5 * u.length();
      if (u_front > my_front && u_rear > my_rear) {
        const double g = u_rear - my_front;
        if (g < lead.gap) lead = {g, u.speed(), INFINITY, true, lon};
      } else {
        const double g = my_rear - u_front;
        if (g < follow.gap) follow = {g, u.speed(), INFINITY, true, lon};
      }
    }
  };
  for (int side : {+1, -1}) {
    const odr::LaneIndex target = side > 0 ? lane.left() : lane.right();
    const bool allowed = side > 0 ? lane.change_left() : lane.change_right();
    if (target == odr::kNoLane || !allowed || !graph_->lane(target).drivable()) continue;
    const odr::LaneNode& tl = graph_->lane(target);
    // Lateral offset of the target lane's centre in my frame.
    const odr::WorldPose wc = graph_->world_pose(lane.road->id, lane.lane_id, loc->s);
    const odr::WorldPose wt = graph_->world_pose(tl.road->id, tl.lane_id, loc->s);
    const double centre = -(wt.x - x_) * s + (wt.y - y_) * c;
    const double own = -(wc.x - x_) * s + (wc.y - y_) * c;
    const double w = std::abs(centre - own);
    if (w < 1.0) continue;
    Near cl, cf, nl, nf;
    scan(own, 0.5 * w, cl, cf);
    scan(centre, 0.5 * w, nl, nf);
    if (nl.found && nl.gap < 0) continue;  // someone beside me
    if (nf.found && nf.gap < 0) continue;
    const double a_c = idm_.accel(v_, cl.gap, cl.speed, v0);
    const double a_c2 = idm_.accel(v_, nl.gap, nl.speed, v0);
    // New follower: now behind the new leader, then behind me.
    double a_n = 0, a_n2 = 0;
    if (nf.found) {
      const double gap_now =
          nl.found ? nl.gap + nf.gap + length_ : INFINITY;  // its gap to the new leader
      a_n = idm_.accel(nf.speed, gap_now, nl.speed, idm_.v0);
      a_n2 = idm_.accel(nf.speed, nf.gap, v_, idm_.v0);
      if (a_n2 < -b_safe_) continue;  // unsafe for the new follower
    }
    double a_o = 0, a_o2 = 0;
    if (cf.found) {
      a_o = idm_.accel(cf.speed, cf.gap, v_, idm_.v0);
      a_o2 =
          idm_.accel(cf.speed, cl.found ? cl.gap + cf.gap + length_ : INFINITY, cl.speed, idm_.v0);
    }
    const double incentive = a_c2 - a_c + politeness_ * ((a_n2 - a_n) + (a_o2 - a_o));
    if (incentive <= threshold_) continue;
    // The route on from the target lane: keep that lane to the destination road if it can,
    // else any route there.
    odr::RouteOptions keep;
    keep.lane_changes = false;
    const odr::LaneNode& dest = graph_->lane(dest_lane_);
    std::optional<odr::LaneRoute> route;
    const int dest_id = dest.lane_id + (tl.lane_id - lane.lane_id);
    const odr::LaneIndex dest2 = graph_->find(dest.road->id, dest_id, dest_s_);
    if (dest2 != odr::kNoLane) route = graph_->route(target, loc->s, dest2, dest_s_, keep);
    if (!route) route = graph_->route(target, loc->s, dest_lane_, dest_s_);
    if (!route || route->segments.empty()) continue;
    Path p = make_path(*route);
    if (p.poses.size() < 2) continue;
    path_ = std::move(p);
    const auto pr = path_.project(x_, y_);
    cursor_ = pr.index;
    arc_ = pr.arc;
    changing_ = side;
    return;
  }
}

namespace {
constexpr double kCommitReaction = 1.0;  // s
constexpr double kCommitDecel = 2.0;     // m/s^2

// Time to cover d m from speed v accelerating at a up to v0.
double eta(double d, double v, double a, double v0) {
  if (d <= 0) return 0;
  v = std::max(v, 0.0);
  const double t_up = std::max(v0 - v, 0.0) / a;
  const double d_up = v * t_up + 0.5 * a * t_up * t_up;
  if (d <= d_up) return (-v + std::sqrt(v * v + 2 * a * d)) / a;
  return t_up + (d - d_up) / std::max({v0, v, 0.1});  // one faster than v0 keeps its speed
}
}  // namespace

bool VehicleAgent::red_for(odr::LaneIndex lane, double front_s, const Snapshot* snap) const {
  if (!snap || !snap->lights) return false;
  const json& sig = snap->lights->contains("signals") ? (*snap->lights)["signals"] : *snap->lights;
  const bool forward = graph_->lane(lane).forward;
  for (const auto& info : graph_->signals()) {
    if (!info.traffic_light || !info.signal) continue;
    if (std::find(info.lanes.begin(), info.lanes.end(), lane) == info.lanes.end()) continue;
    auto it = sig.find(info.signal->id);
    if (it == sig.end() || !it->is_string() || (*it != "red" && *it != "red_yellow")) continue;
    // Past its stop line (it went on yellow, or waits for the junction): not held by it.
    const double stop_s = info.signal->s;
    if (forward ? front_s > stop_s + 0.5 : front_s < stop_s - 0.5) continue;
    return true;
  }
  return false;
}

double VehicleAgent::junction_wait(double my_front, const Snapshot* snap) const {
  const Path::Crossing* next = nullptr;
  for (const auto& c : path_.crossings) {
    if (c.exit > my_front - length_) {
      next = &c;
      break;
    }
  }
  if (!next) return INFINITY;
  const double g = next->enter - my_front;
  if (g < 0 || g > radius_) return INFINITY;            // inside already, or far
  if (g < v_ * v_ / (2 * max_decel_)) return INFINITY;  // cannot stop before it: committed
  if (!snap || !snap->neighbours) return INFINITY;
  const double my_eta = eta(g, v_, idm_.a, idm_.v0);
  // Until my rear has left the junction.
  const double my_clear = eta(g + (next->exit - next->enter) + length_, v_, idm_.a, idm_.v0);
  const size_t lo = cursor_ > 40 ? cursor_ - 40 : 0;
  for (const auto& u : snap->neighbours->users()) {
    if (u.absent() || u.id() == name_) continue;
    if (std::hypot(u.x() - x_, u.y() - y_) > radius_) continue;
    // On my own path (a leader or follower): IDM's business.
    const auto pr = path_.project(u.x(), u.y(), lo);
    if (std::isfinite(pr.d2) && std::abs(pr.lateral) < 1.2 &&
        std::abs(std::remainder(u.yaw() - path_.at(pr.arc).heading, 2 * M_PI)) < 0.5)
      continue;
    const auto loc = graph_->locate(u.x(), u.y(), u.yaw());
    if (!loc) continue;
    const odr::LaneNode& ln = graph_->lane(loc->lane);
    const double u_front = u.length_offset() + 0.5 * u.length();
    if (ln.junction == next->junction) {
      // Inside; blocking unless its back has nearly left (it is leaving).
      return std::max(g, 0.0);
    }
    // Approaching: its lane leads into the junction.
    bool leads = false;
    for (odr::LaneIndex nx : graph_->successors(loc->lane)) {
      if (graph_->lane(nx).junction == next->junction) leads = true;
    }
    if (!leads) continue;
    const double front_s = ln.forward ? loc->s + u_front : loc->s - u_front;
    if (red_for(loc->lane, front_s, snap)) continue;  // it waits at its light
    const double remaining = (ln.forward ? ln.s1 - loc->s : loc->s - ln.s0) - u_front;
    if (remaining < 0) return std::max(g, 0.0);  // its front is in
    const double other_eta = eta(remaining, u.speed(), idm_.a, idm_.v0);
    if (other_eta < my_eta - 0.05 || (other_eta <= my_eta + 0.05 && u.id() < name_))
      return std::max(g, 0.0);
    // I would be first, but one that cannot stop comfortably before the junction any more
    // (1 s to react, then 2 m/s^2) and arrives before I have cleared it does not yield,
    // whoever drives it (SUMO's vehicles keep their right of way): wait for it.
    const double v = std::max(u.speed(), 0.0);
    if (remaining < v * kCommitReaction + v * v / (2 * kCommitDecel) && other_eta < my_clear + 0.5)
      return std::max(g, 0.0);
  }
  return INFINITY;
}

int64_t VehicleAgent::step(int64_t duration_ns) {
  const double dt = duration_ns * 1e-9;
  time_ns_ += duration_ns;
  // Drop inputs no longer needed (keep the newest one old enough).
  const int64_t limit = time_ns_ - static_cast<int64_t>(std::llround(reaction_s_ * 1e9));
  while (inputs_.size() > 1 && inputs_[1].time_ns <= limit) inputs_.pop_front();
  if (absent_) {
    if (!respawn_ || time_ns_ - absent_since_ns_ < std::llround(respawn_delay_s_ * 1e9) ||
        !start_free())
      return time_ns_;
    restart();
    publish();
    return time_ns_;
  }

  const double my_front_off = 0.5 * length_ + (0.5 * length_ - rear_overhang_);
  const double my_front = arc_ + my_front_off;
  const double v0 = desired_speed();
  auto [gap, vl] = leader_on(path_, my_front, cursor_);
  // Red lights: a standing virtual leader at the stop line.
  const Snapshot* snap = perceived();
  if (snap && snap->lights) {
    const json& sig =
        snap->lights->contains("signals") ? (*snap->lights)["signals"] : *snap->lights;
    for (const auto& [stop_arc, id] : path_.stops) {
      const double g = stop_arc - my_front;
      if (g < -0.5) continue;  // passed
      if (g > radius_) break;
      auto it = sig.find(id);
      if (it == sig.end() || !it->is_string()) break;  // green (or unknown): the next one counts
      const std::string st = it->get<std::string>();
      bool stop = st == "red" || st == "red_yellow";
      if (st == "yellow") stop = g > v_ * v_ / (2 * idm_.b);  // stop only if it comfortably can
      if (stop && g < gap) {
        gap = std::max(g, 0.0);
        vl = 0;
      }
      break;  // only the next light counts
    }
  }
  if (yielding_) {
    const double g = junction_wait(my_front, snap);
    if (g < gap) {
      gap = g;
      vl = 0;
    }
  }
  double acc = idm_.accel(v_, gap, vl, v0);
  acc = std::clamp(acc, -max_decel_, idm_.a);
  // Pure pursuit on the path.
  const double lookahead = std::max(4.0, 0.8 * v_ + 2.0);
  const odr::Pose2 target = path_.at(arc_ + wheelbase_ + lookahead);
  const double dx = target.x - x_, dy = target.y - y_;
  const double alpha = std::atan2(dy, dx) - yaw_;
  const double ld = std::max(std::hypot(dx, dy), 1.0);
  double steer = std::atan2(2.0 * wheelbase_ * std::sin(alpha), ld);
  steer = std::clamp(steer, -0.6, 0.6);
  // Kinematic bicycle (rear axle), semi-implicit Euler.
  double v_new = v_ + acc * dt;
  if (v_new < 0) {
    v_new = 0;
    acc = -v_ / dt;
  }
  yaw_rate_ = v_new * std::tan(steer) / wheelbase_;
  const double yaw_mid = yaw_ + 0.5 * yaw_rate_ * dt;
  x_ += v_new * std::cos(yaw_mid) * dt;
  y_ += v_new * std::sin(yaw_mid) * dt;
  yaw_ = std::remainder(yaw_ + yaw_rate_ * dt, 2 * M_PI);
  v_ = v_new;
  acc_ = acc;
  // Where it is on the path now.
  const size_t lo = cursor_ > 20 ? cursor_ - 20 : 0;
  const auto pr =
      path_.project(x_, y_, lo, cursor_ + 40 + static_cast<size_t>(v_ * dt / kSampleDs));
  cursor_ = pr.index;
  arc_ = pr.arc;
  if (changing_ != 0 && std::abs(pr.lateral) < 0.2) changing_ = 0;
  if (arc_ >= path_.length() - 0.25) {
    absent_ = true;
    absent_since_ns_ = time_ns_;
    if (respawn_) {  // absent, it waits at its start: its view is around there
      x_ = initial_path_start_.x;
      y_ = initial_path_start_.y;
      yaw_ = initial_path_start_.heading;
    }
    v_ = 0;
    acc_ = 0;
    yaw_rate_ = 0;
  }
  if (!absent_ && lane_changes_ && changing_ == 0 && time_ns_ >= next_mobil_ns_) {
    next_mobil_ns_ = time_ns_ + 500000000;  // every 0.5 s
    consider_lane_change();
  }
  publish();
  return time_ns_;
}

void VehicleAgent::publish() {
  state_.set_absent(absent_);
  state_.set_x(x_);
  state_.set_y(y_);
  state_.set_yaw(yaw_);
  state_.set_speed(v_);
  state_.set_acceleration(acc_);
  state_.set_yaw_rate(yaw_rate_);
  state_.set_vx(v_ * std::cos(yaw_));
  state_.set_vy(v_ * std::sin(yaw_));
  uint32_t lights = 0;
  if (acc_ < -0.3 || (v_ < 0.1 && !absent_)) lights |= data::RoadUser::BRAKE;
  if (changing_ > 0) lights |= data::RoadUser::INDICATOR_LEFT;
  if (changing_ < 0) lights |= data::RoadUser::INDICATOR_RIGHT;
  state_.set_lights(lights);
  const auto loc = graph_->locate(x_, y_, yaw_);
  if (loc) {
    state_.set_road(loc->road_id);
    state_.set_lane(loc->lane_id);
    state_.set_s(loc->s);
    state_.set_t(loc->road_t);
    const odr::WorldPose w = graph_->world_pose(loc->road_id, loc->lane_id, loc->s, loc->t);
    state_.set_z(w.z);
  }
  state_.set_time_ns(time_ns_);
}

void VehicleAgent::set_datapack(const datapack::View& dp) {
  if (dp.empty()) return;
  const std::string& name = dp.id().name();
  if (name == neighbours_dp_) {
    auto users = std::make_shared<data::RoadUsers>();
    if (dp.is_proto() && dp.proto_type() == datapack::type_name<data::RoadUsers>()) {
      datapack::read_proto(dp, users.get());
    } else if (dp.is_proto() && dp.proto_type() == datapack::type_name<data::RoadUser>()) {
      datapack::read_proto(dp, users->add_users());
    } else {
      fail(name, std::string("expected convoy.data.RoadUsers or RoadUser, got ") +
                     (dp.is_proto() ? dp.proto_type() : std::string("JSON")));
    }
    last_neighbours_ = std::move(users);
  } else if (name == weather_dp_) {
    if (!dp.is_json()) fail(name, "expected the weather engine's JSON datapack");
    const json w = datapack::read_json(dp);
    const auto num = [&](const char* key, double fallback) {
      if (!w.is_object() || !w.contains(key)) return fallback;
      if (!w[key].is_number()) fail(name, std::string(key) + ": expected a number");
      return w[key].get<double>();
    };
    const double mu = num("mu", 0.8), visibility = num("visibility_m", INFINITY);
    if (!(mu >= 0)) fail(name, "mu: must be >= 0");
    if (!(visibility > 0)) fail(name, "visibility_m: must be > 0");
    adapt_to_weather(mu, visibility);
    return;
  } else if (name == lights_dp_) {
    if (!dp.is_json()) fail(name, "expected a JSON datapack {\"signals\": {id: state}}");
    auto j = std::make_shared<json>(datapack::read_json(dp));
    if (!j->is_object()) fail(name, "expected a JSON object {\"signals\": {id: state}}");
    last_lights_ = std::move(j);
  } else {
    warn_once("dp:" + name, "datapack '" + name + "' is not one it reads (" + neighbours_dp_ +
                                ", " + lights_dp_ + ", " + weather_dp_ + "); ignored");
    return;
  }
  // Stamped with the time it arrived (the state the TF saw).
  if (!inputs_.empty() && inputs_.back().time_ns == time_ns_) {
    inputs_.back().neighbours = last_neighbours_;
    inputs_.back().lights = last_lights_;
  } else {
    inputs_.push_back({time_ns_, last_neighbours_, last_lights_});
  }
}

void VehicleAgent::get_datapack(const engine::DataPackId& id, datapack::Builder& out) {
  if (id.name() == state_dp_) datapack::write_proto(out, state_);
}

CONVOY_REGISTER_ENGINE("vehicle_agent", VehicleAgent);

}  // namespace convoy::engines::vehicle_agent
