// EngineType "vehicle_agent": one road vehicle as its own engine, on an OpenDRIVE lane graph.
//
// Longitudinal: IDM (v0, T, s0, a, b, delta) on the leader ahead on its path (from its
// neighbour input) and, for a red (or stoppable yellow) light, on the light's stop line as a
// standing virtual leader. Lateral: pure pursuit on the route's sampled lane-centre poses,
// moved as a kinematic bicycle (reference point: the rear axle). Lane changes: MOBIL
// (politeness, threshold, b_safe) into a lane the lane graph allows a change to. Inputs are
// acted on ReactionTime late. Deterministic: no wall clock, the only randomness is Seed's.
// The models themselves (IDM, MOBIL, pure pursuit, the bicycle, paths on the lane graph, the
// leader and the lane neighbours, lights, junction yielding, the weather, the command
// contract) are in src/road_users; this engine turns its datapacks into their inputs, plans
// the routes and carries out commands.
//
// Config keys (schema.json): Map, Route {from, to} ("ROAD:LANE") or Seed, StartS, Position,
// StartPose, InitialSpeed, Model, Category, Length, Width, Height, Wheelbase, v0,
// SpeedLimitFactor, T, s0, a, b, delta, MaxDeceleration, politeness, threshold, b_safe,
// JunctionYielding, LaneChanges, Respawn, RespawnDelay, ReactionTime, NeighbourRadius,
// StateDataPack, NeighboursDataPack, TrafficLightsDataPack, WeatherDataPack,
// WeatherAdaptation, CommandDataPack.
//
// StartPose {x, y, yaw}: it starts exactly there and localises on the nearest driving lane
// whose direction is within 60 degrees of yaw (docs/road_users.md, "Commands"); with Route.to
// it is routed there, without a Route it follows the lane graph onward, choosing at each fork
// by Seed, for as long as the lane graph goes on.
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
//   <CommandDataPack> ("command")  optional JSON, the scenario engine's commands for this
//                    step (docs/road_users.md, "Commands"): speed, lane, route, trajectory,
//                    teleport. Each overrides its control domain (longitudinal, lateral) of
//                    the AI for the step it is given in, at once (no ReactionTime); when a
//                    command stops coming the AI takes over from the present state.
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
#include "road_users/bicycle.h"
#include "road_users/command.h"
#include "road_users/idm.h"
#include "road_users/junction.h"
#include "road_users/lights.h"
#include "road_users/mobil.h"
#include "road_users/neighbours.h"
#include "road_users/path.h"
#include "road_users/pure_pursuit.h"
#include "road_users/routing.h"
#include "road_users/weather.h"

namespace convoy::engines::vehicle_agent {
namespace odr = convoy::opendrive;
namespace ru = convoy::road_users;
using nlohmann::json;

namespace {

constexpr double kSampleDs = 0.5;      // m between the path's poses
constexpr double kOnwardLength = 600;  // m of lane graph planned ahead when following it onward
constexpr double kHeadingTolerance = 60.0 * M_PI / 180.0;  // localising: lane direction vs yaw

using ru::Idm;
using ru::Path;
using Points = ru::Points;
using Goal = ru::Goal;  // a point its route passes

struct Snapshot {
  int64_t time_ns = 0;
  std::shared_ptr<const ru::Neighbours> neighbours;  // null: none received yet
  std::shared_ptr<const ru::LightStates> lights;
};

// The road users in a neighbours datapack but `self` and the absent, in the order received.
ru::Neighbours neighbours_of(const data::RoadUsers& users, const std::string& self) {
  ru::Neighbours out;
  out.reserve(users.users_size());
  for (const data::RoadUser& u : users.users()) {
    if (u.absent() || u.id() == self) continue;
    out.push_back(
        {u.id(), u.x(), u.y(), u.yaw(), u.speed(), u.length(), u.width(), u.length_offset()});
  }
  return out;
}

// The signals' states of the lights datapack ({"signals": {id: state}}, or the map itself);
// a state that is not a string is left out (green).
ru::LightStates light_states(const json& j) {
  ru::LightStates out;
  const json& sig = j.contains("signals") ? j["signals"] : j;
  if (!sig.is_object()) return out;
  for (const auto& [id, v] : sig.items()) {
    if (!v.is_string()) continue;
    const std::string& st = v.get_ref<const std::string&>();
    const ru::Light light = st == "red"          ? ru::Light::kRed
                            : st == "red_yellow" ? ru::Light::kRedYellow
                            : st == "yellow"     ? ru::Light::kYellow
                            : st == "green"      ? ru::Light::kGreen
                                                 : ru::Light::kOff;
    out.emplace(id, light);
  }
  return out;
}

using Command = ru::VehicleCommand;

// A lane command under way: the path is the target lane's, the agent `lateral` m left of it.
struct LaneRun {
  bool active = false;
  std::string road;
  int lane = 0, from_lane = 0;
  double d_from = 0;  // the from lane's centre, left of the target lane's (m)
  double e0 = 0;      // the agent's offset from the from lane's centre when it began
  double progress = 0, lateral = 0;
  int side = 0;  // +1 to the left, -1 to the right
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
  Path make_path(const odr::LaneRoute& route) const {
    return ru::make_path(*graph_, route, kSampleDs);
  }
  void start();
  // Respawn: back at its start once its route has ended, RespawnDelay has passed and the
  // start is free (nobody within its length + 6 m of it in its latest view).
  bool start_free() const {
    const Snapshot* snap = perceived();
    return snap && snap->neighbours &&
           ru::start_free(*snap->neighbours, initial_path_start_.x, initial_path_start_.y,
                          length_ + 6.0);
  }
  void restart();
  void publish();
  double desired_speed() const;
  ru::Observer observer() const { return {name_, x_, y_, yaw_, v_, radius_}; }
  // The gap to where it must stop on `drive` (cursor, front: its front bumper's arc there)
  // and the speed of what it stops behind: the leader, a red light, a junction to wait at.
  std::pair<double, double> stop_ahead(const Path& drive, size_t cursor, double front,
                                       bool on_poly) const;
  void consider_lane_change();
  const Snapshot* perceived() const;
  // Localisation after a command (docs/road_users.md, "Commands"; the command itself is
  // checked by road_users/command.h).
  std::optional<odr::LanePosition> locate_drivable(double x, double y, double yaw,
                                                   double max_distance) const;
  // Routing on the lane graph (road_users/routing.h) with its goals_, onward_, open_end_ and
  // rng_ (the onward choices, drawn from Seed).
  ru::RoutePlan plan() { return {*graph_, kOnwardLength, rng_}; }
  // A route from (lane, s) through goals_[first..] and then, when onward_, onward. nullopt
  // with *failed = the index of the goal it cannot reach.
  std::optional<odr::LaneRoute> route_from(odr::LaneIndex lane, double s, size_t first,
                                           size_t* failed) {
    return ru::route_from(plan(), goals_, onward_, lane, s, first, &open_end_, failed);
  }
  // The route on from (lane, s): through its goals when it can still reach them, else
  // onward (its goals given up).
  odr::LaneRoute plan_from(odr::LaneIndex lane, double s) {
    return ru::plan_from(plan(), goals_, onward_, lane, s, &open_end_);
  }
  // After a change into `target` (lane ids `shift` from its own): the route keeping that
  // lane to its next goal's road when it can (else to the goal), then on; onward without
  // goals; nullopt when there is none.
  std::optional<odr::LaneRoute> route_keeping(odr::LaneIndex target, double s, int shift) {
    return ru::route_keeping(plan(), goals_, onward_, target, s, shift, &open_end_);
  }
  void set_path(const odr::LaneRoute& route);
  void compute_goal_arcs() { goal_arcs_ = ru::goal_arcs(*graph_, path_, goals_); }
  // Onto the nearest lane from its present pose and a route on from there; false when no
  // driving lane is near (it stops where it is).
  bool relocalise();
  void apply_route(const Points& positions);
  void begin_lane(const Command::Lane& c);
  void set_polyline(const Points& points);
  // Onward: the route from 30 m behind it on, plus the lane graph onward from its end.
  void extend();

  std::string name_;
  std::unique_ptr<odr::Network> net_;
  std::unique_ptr<odr::LaneGraph> graph_;
  ru::Mobil mobil_;
  double limit_factor_ = 0, max_decel_ = 9;
  bool lane_changes_ = true, yielding_ = true;
  double reaction_s_ = 0, radius_ = 100, start_s_ = 0, initial_speed_ = 0;
  double length_ = 4.5, width_ = 1.8, height_ = 1.5, wheelbase_ = 2.7, rear_overhang_ = 0.9;
  std::string model_, category_;
  std::string state_dp_, neighbours_dp_, lights_dp_, weather_dp_;
  // Weather: the configured IDM, and what the weather makes of it (see the header).
  bool weather_adaptation_ = true;
  Idm base_idm_;
  ru::Driving driving_;  // the IDM it drives with
  odr::LaneRoute initial_route_;
  std::vector<Goal> initial_goals_;
  bool initial_onward_ = false;
  std::optional<odr::Pose2> start_pose_;
  std::string command_dp_;
  uint64_t seed_ = 0;
  std::mt19937_64 initial_rng_;  // after the initial route's choices

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
  std::shared_ptr<const ru::Neighbours> last_neighbours_;
  std::shared_ptr<const ru::LightStates> last_lights_;
  data::RoadUser state_;
  std::map<std::string, bool> warned_;
  std::vector<std::string> warnings_;
  // Route state: the points still to pass (with their arcs on path_), and whether the route
  // goes on along the lane graph after them (else it ends: absent).
  std::vector<Goal> goals_;
  std::vector<double> goal_arcs_;
  bool onward_ = false;
  bool open_end_ = false;  // path_ ends where the lane graph goes on (onward: extend it)
  bool initial_open_end_ = false;
  std::mt19937_64 rng_;  // onward choices
  // Commands.
  std::optional<Command> command_;  // for the coming step
  std::optional<double> commanded_acc_;
  LaneRun lane_run_;
  Points last_route_;
  Points polyline_;
  Path traj_path_;
  bool off_path_ = false;  // a command moved it off path_: relocalise when the AI takes over
  bool lost_ = false;      // no driving lane near: it stops and looks again every second
  int64_t next_look_ns_ = 0;
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
  base_idm_.v0 = config.at("v0").get<double>();
  base_idm_.T = config.at("T").get<double>();
  base_idm_.s0 = config.at("s0").get<double>();
  base_idm_.a = config.at("a").get<double>();
  base_idm_.b = config.at("b").get<double>();
  base_idm_.delta = config.at("delta").get<double>();
  driving_ = ru::Driving{base_idm_};
  limit_factor_ = config.at("SpeedLimitFactor").get<double>();
  max_decel_ = config.at("MaxDeceleration").get<double>();
  mobil_.politeness = config.at("politeness").get<double>();
  mobil_.threshold = config.at("threshold").get<double>();
  mobil_.b_safe = config.at("b_safe").get<double>();
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
  command_dp_ = config.at("CommandDataPack").get<std::string>();
  seed_ = config.at("Seed").get<uint64_t>();
  rng_.seed(seed_ * 0x9E3779B97F4A7C15ull + 0x0A7Eull);

  const json& sp = config.at("StartPose");
  if (!sp.is_object()) fail("StartPose", "expected {\"x\": ..., \"y\": ..., \"yaw\": ...}");
  if (!sp.empty()) {
    for (const auto& [k, v] : sp.items()) {
      if (k != "x" && k != "y" && k != "yaw")
        fail("StartPose", "unknown key \"" + k + "\" (x, y, yaw)");
      if (!v.is_number() || !std::isfinite(v.get<double>()))
        fail("StartPose." + k, "expected a number");
    }
    if (!sp.contains("x") || !sp.contains("y") || !sp.contains("yaw"))
      fail("StartPose", "expected numbers \"x\", \"y\" and \"yaw\"");
    const json& r = config.at("Route");
    if (!r.is_object()) fail("Route", "expected {\"to\": \"ROAD:LANE\"} with StartPose");
    for (const auto& [k, v] : r.items()) {
      if (k != "to")
        fail("Route." + k, "give StartPose or Route.from, not both (Route: {\"to\"} only)");
    }
    if (config.at("Position").is_object() && !config.at("Position").empty())
      fail("StartPose", "give Position or StartPose, not both");
    if (start_s_ > 0) fail("StartS", "give StartS or StartPose, not both");
    odr::Pose2 pose;
    pose.x = sp["x"].get<double>();
    pose.y = sp["y"].get<double>();
    pose.heading = sp["yaw"].get<double>();
    start_pose_ = pose;
    char where[96];
    std::snprintf(where, sizeof where, "(%.2f, %.2f)", pose.x, pose.y);
    const auto loc = locate_drivable(pose.x, pose.y, pose.heading, 50.0);
    if (!loc)
      fail("StartPose",
           std::string(where) + " is not within 50 m of a driving lane of " + net_->source);
    goals_.clear();
    onward_ = !r.contains("to");
    if (r.contains("to")) {
      const auto [tr, tl] = parse_lane("Route.to", r["to"]);
      if (!net_->find_road(tr))
        fail("Route.to", "road " + tr + " is not in the map " + net_->source);
      odr::LaneIndex dest = odr::kNoLane;
      try {
        dest = graph_->exit_lane(tr, tl);
      } catch (const std::exception& e) {
        fail("Route.to", e.what());
      }
      const odr::LaneNode& dn = graph_->lane(dest);
      if (!dn.drivable())
        fail("Route.to", "lane " + tr + ":" + std::to_string(tl) + " is a " + dn.type +
                             " lane, not a driving lane");
      goals_.push_back({dest, dn.forward ? dn.s1 : dn.s0});
    }
    size_t failed = 0;
    auto route = route_from(loc->lane, loc->s, 0, &failed);
    if (!route) {
      fail("Route", std::string("no route from StartPose ") + where + " (" + loc->road_id + ":" +
                        std::to_string(loc->lane_id) + ") to " + r["to"].get<std::string>());
    }
    initial_route_ = *route;
  } else {
    initial_route_ = pick_route(config, seed_);
    const auto& last = initial_route_.segments.back();
    goals_ = {{last.lane, last.s_to}};
    onward_ = false;
    open_end_ = false;
  }
  initial_goals_ = goals_;
  initial_onward_ = onward_;
  initial_open_end_ = open_end_;
  initial_rng_ = rng_;
  {
    Path p = make_path(initial_route_);
    if (p.poses.size() < 2)
      fail(start_pose_ ? "StartPose" : "Route", "the route is empty (a dead end there)");
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

void VehicleAgent::restart() {
  path_ = make_path(initial_route_);
  goals_ = initial_goals_;
  onward_ = initial_onward_;
  open_end_ = initial_open_end_;
  arc_ = start_s_;
  const odr::Pose2 p = start_pose_ ? *start_pose_ : path_.at(arc_);
  x_ = p.x;
  y_ = p.y;
  yaw_ = p.heading;
  if (start_pose_) arc_ = path_.project(x_, y_).arc;
  v_ = initial_speed_;
  acc_ = 0;
  yaw_rate_ = 0;
  absent_ = false;
  changing_ = 0;
  next_mobil_ns_ = time_ns_;
  cursor_ = path_.project(x_, y_).index;
  compute_goal_arcs();
  lane_run_ = {};
  off_path_ = lost_ = false;
  commanded_acc_.reset();
}

void VehicleAgent::start() {
  path_ = make_path(initial_route_);
  goals_ = initial_goals_;
  onward_ = initial_onward_;
  open_end_ = initial_open_end_;
  rng_ = initial_rng_;
  time_ns_ = 0;
  arc_ = start_s_;
  const odr::Pose2 p = start_pose_ ? *start_pose_ : path_.at(arc_);
  initial_path_start_ = p;
  x_ = p.x;
  y_ = p.y;
  yaw_ = p.heading;
  if (start_pose_) arc_ = path_.project(x_, y_).arc;
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
  compute_goal_arcs();
  command_.reset();
  commanded_acc_.reset();
  lane_run_ = {};
  last_route_.clear();
  polyline_.clear();
  off_path_ = lost_ = false;
  next_look_ns_ = 0;
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
  std::optional<double> limit;
  if (limit_factor_ > 0 && !path_.route.segments.empty()) {
    if (const auto loc = graph_->locate(x_, y_, yaw_)) {
      const odr::SpeedLimit lim = graph_->speed_limit(loc->lane, loc->s);
      if (lim.known) limit = lim.mps;
    }
  }
  return ru::desired_speed(driving_, limit_factor_, limit);
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

std::pair<double, double> VehicleAgent::stop_ahead(const Path& drive, size_t cursor, double front,
                                                   bool on_poly) const {
  const Snapshot* snap = perceived();
  if (!snap) return {INFINITY, 0};
  const ru::Observer me = observer();
  const Idm& idm = driving_.idm;
  ru::LaneNeighbour leader;
  if (snap->neighbours)
    leader = ru::leader_on(drive, cursor, front, kSampleDs, me, *snap->neighbours);
  double gap = leader.gap, vl = leader.speed;
  // Red lights: a standing virtual leader at the stop line.
  if (!on_poly && snap->lights) {
    const double g = ru::stop_line_gap(path_, *snap->lights, front, v_, idm.b, radius_);
    if (g < gap) {
      gap = std::max(g, 0.0);
      vl = 0;
    }
  }
  if (yielding_ && !on_poly && snap->neighbours) {
    const ru::Approach at{&path_, cursor_, front, length_, max_decel_, idm};
    const double g = ru::junction_wait(*graph_, at, me, *snap->neighbours, snap->lights.get());
    if (g < gap) {
      gap = g;
      vl = 0;
    }
  }
  return {gap, vl};
}

void VehicleAgent::consider_lane_change() {
  // MOBIL, in the local frame at the agent: neighbours by longitudinal (along my heading)
  // and lateral offset, each lane a band around its centre.
  const auto loc = graph_->locate(x_, y_, yaw_);
  if (!loc || loc->lane == odr::kNoLane) return;
  const odr::LaneNode& lane = graph_->lane(loc->lane);
  if (lane.junction != "-1") return;
  const Snapshot* snap = perceived();
  const ru::Neighbours none;
  const ru::Neighbours& around = snap && snap->neighbours ? *snap->neighbours : none;
  const ru::Observer me = observer();
  const double c = std::cos(yaw_), s = std::sin(yaw_);
  const double my_front = 0.5 * length_ + (0.5 * length_ - rear_overhang_);
  const double my_rear = -rear_overhang_;
  const double v0 = desired_speed();
  const bool open_before = open_end_;  // (planning a change that is not taken sets it)
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
    const ru::LaneNeighbours here =
        ru::lane_neighbours(me, around, own, 0.5 * w, my_front, my_rear);
    const ru::LaneNeighbours there =
        ru::lane_neighbours(me, around, centre, 0.5 * w, my_front, my_rear);
    const ru::MobilDecision d =
        ru::decide_lane_change(driving_.idm, mobil_, v_, v0, length_, here, there);
    if (d.outcome != ru::LaneChange::kChange) continue;
    // The route on from the target lane: keep that lane to the destination road if it can,
    // else any route there.
    const std::optional<odr::LaneRoute> route =
        route_keeping(target, loc->s, tl.lane_id - lane.lane_id);
    if (!route || route->segments.empty()) continue;
    Path p = make_path(*route);
    if (p.poses.size() < 2) continue;
    path_ = std::move(p);
    const auto pr = path_.project(x_, y_);
    cursor_ = pr.index;
    arc_ = pr.arc;
    compute_goal_arcs();
    changing_ = side;
    return;
  }
  open_end_ = open_before;
}

std::optional<odr::LanePosition> VehicleAgent::locate_drivable(double x, double y, double yaw,
                                                               double max_distance) const {
  // A driving lane whose direction is within kHeadingTolerance of yaw; else any driving lane
  // (it turns towards it).
  auto loc = graph_->locate_if(x, y, yaw, max_distance, [&](const odr::LaneNode& n, double h) {
    return n.drivable() && std::abs(std::remainder(h - yaw, 2 * M_PI)) <= kHeadingTolerance;
  });
  if (loc) return loc;
  return graph_->locate_if(x, y, yaw, max_distance,
                           [](const odr::LaneNode& n, double) { return n.drivable(); });
}

void VehicleAgent::set_path(const odr::LaneRoute& route) {
  path_ = make_path(route);
  const auto pr = path_.project(x_, y_);
  cursor_ = pr.index;
  arc_ = pr.arc;
  compute_goal_arcs();
  changing_ = 0;
}

bool VehicleAgent::relocalise() {
  const auto loc = locate_drivable(x_, y_, yaw_, 50.0);
  if (!loc) {
    char where[96];
    std::snprintf(where, sizeof where, "(%.2f, %.2f)", x_, y_);
    warn_once("lost", std::string("no driving lane within 50 m of ") + where +
                          " after a command: it stops there");
    lost_ = true;
    next_look_ns_ = time_ns_ + 1000000000;
    return false;
  }
  lost_ = false;
  set_path(plan_from(loc->lane, loc->s));
  return true;
}

void VehicleAgent::apply_route(const Points& positions) {
  const auto here = locate_drivable(x_, y_, yaw_, 50.0);
  if (!here) fail(command_dp_ + ".route", "the agent is not within 50 m of a driving lane");
  std::vector<Goal> goals;
  std::vector<size_t> index;
  for (size_t i = 0; i < positions.size(); ++i) {
    const auto [px, py] = positions[i];
    const auto loc = graph_->locate_if(px, py, std::nullopt, 20.0,
                                       [](const odr::LaneNode& n, double) { return n.drivable(); });
    if (!loc) continue;  // checked when it arrived
    // A point at the agent, or behind it on its own lane, is passed already.
    if (std::hypot(px - x_, py - y_) < 3.0) continue;
    if (goals.empty() && loc->lane == here->lane) {
      const bool fwd = graph_->lane(here->lane).forward;
      if (fwd ? loc->s <= here->s + 1.0 : loc->s >= here->s - 1.0) continue;
    }
    goals.push_back({loc->lane, loc->s});
    index.push_back(i);
  }
  goals_ = goals;
  onward_ = true;
  size_t failed = 0;
  auto route = route_from(here->lane, here->s, 0, &failed);
  if (!route) {
    const auto [px, py] = positions[index[failed]];
    const odr::LaneNode& n = graph_->lane(goals_[failed].lane);
    char what[200];
    std::snprintf(what, sizeof what, "no route on the lane graph to (%.2f, %.2f) (lane %s:%d)", px,
                  py, n.road->id.c_str(), n.lane_id);
    fail(command_dp_ + ".route.positions[" + std::to_string(index[failed]) + "]", what);
  }
  set_path(*route);
  lane_run_ = {};
}

void VehicleAgent::begin_lane(const Command::Lane& c) {
  const bool same = lane_run_.active && lane_run_.road == c.road && lane_run_.lane == c.lane &&
                    lane_run_.from_lane == c.from_lane && c.progress >= lane_run_.progress - 1e-9;
  if (same) {
    lane_run_.progress = c.progress;
    return;
  }
  const std::string key = command_dp_ + ".lane";
  const auto loc = locate_drivable(x_, y_, yaw_, 50.0);
  if (!loc) fail(key, "the agent is not within 50 m of a driving lane");
  std::string road = c.road;
  int lane = c.lane, from = c.from_lane;
  if (loc->road_id != c.road) {
    // Not on that road (it has just left it, say): the same change relative to its lane.
    warn_once("lane-road", key + ".road: the agent is on road " + loc->road_id + ", not " + c.road +
                               ": lanes taken relative to its own");
    // Lanes between (ids, lane 0 skipped), applied to its own lane.
    int steps = c.lane - c.from_lane;
    if ((c.lane > 0) != (c.from_lane > 0)) steps -= steps > 0 ? 1 : -1;
    road = loc->road_id;
    from = loc->lane_id;
    lane = from;
    for (int k = 0; k < std::abs(steps); ++k) {
      lane += steps > 0 ? 1 : -1;
      if (lane == 0) lane += steps > 0 ? 1 : -1;
    }
  }
  const odr::LaneIndex tgt = graph_->find(road, lane, loc->s);
  const odr::LaneIndex frm = graph_->find(road, from, loc->s);
  char at[48];
  std::snprintf(at, sizeof at, " at s = %.1f", loc->s);
  if (tgt == odr::kNoLane)
    fail(key + ".lane", "road " + road + " has no lane " + std::to_string(lane) + at);
  if (frm == odr::kNoLane)
    fail(key + ".from_lane", "road " + road + " has no lane " + std::to_string(from) + at);
  if (!graph_->lane(tgt).drivable())
    fail(key + ".lane", "lane " + road + ":" + std::to_string(lane) + " is a " +
                            graph_->lane(tgt).type + " lane, not a driving lane");
  const odr::WorldPose wt = graph_->world_pose(road, lane, loc->s);
  const odr::WorldPose wf = graph_->world_pose(road, from, loc->s);
  const double h = wt.heading;
  lane_run_.active = true;
  lane_run_.road = c.road;
  lane_run_.lane = c.lane;
  lane_run_.from_lane = c.from_lane;
  lane_run_.progress = c.progress;
  lane_run_.d_from = -(wf.x - wt.x) * std::sin(h) + (wf.y - wt.y) * std::cos(h);
  // The route on from the target lane: keeping it to its next goal's road if it can, else
  // through its goals, else onward.
  auto route = route_keeping(tgt, loc->s, lane - from);
  set_path(route && !route->segments.empty() ? *route : plan_from(tgt, loc->s));
  lane_run_.lateral = path_.project(x_, y_).lateral;
  lane_run_.e0 = lane_run_.lateral - lane_run_.d_from;
  lane_run_.side = lane_run_.d_from + lane_run_.e0 < -0.5  ? 1
                   : lane_run_.d_from + lane_run_.e0 > 0.5 ? -1
                                                           : 0;
}

void VehicleAgent::set_polyline(const Points& points) {
  if (points == polyline_) return;
  polyline_ = points;
  traj_path_ = ru::polyline_path(points, kSampleDs, x_, y_);
}

void VehicleAgent::extend() {
  bool open = false;
  const odr::LaneRoute route = ru::extended(plan(), path_, arc_, &open);
  open_end_ = open;
  path_ = make_path(route);
  const auto pr = path_.project(x_, y_);
  cursor_ = pr.index;
  arc_ = pr.arc;
  compute_goal_arcs();
}

int64_t VehicleAgent::step(int64_t duration_ns) {
  const double dt = duration_ns * 1e-9;
  time_ns_ += duration_ns;
  // Drop inputs no longer needed (keep the newest one old enough).
  const int64_t limit = time_ns_ - static_cast<int64_t>(std::llround(reaction_s_ * 1e9));
  while (inputs_.size() > 1 && inputs_[1].time_ns <= limit) inputs_.pop_front();
  // This step's command (it applies to this step only).
  std::optional<Command> cmd;
  cmd.swap(command_);
  commanded_acc_.reset();
  const bool placed = cmd && (cmd->teleport || cmd->timed);
  if (absent_ && !placed) {
    if (!respawn_ || time_ns_ - absent_since_ns_ < std::llround(respawn_delay_s_ * 1e9) ||
        !start_free())
      return time_ns_;
    restart();
    publish();
    return time_ns_;
  }
  absent_ = false;
  if (cmd && cmd->teleport) {
    // Put there once, then on from the nearest lane.
    const Command::Pose& p = *cmd->teleport;
    x_ = p.x;
    y_ = p.y;
    yaw_ = std::remainder(p.yaw, 2 * M_PI);
    if (p.speed) v_ = *p.speed;
    acc_ = yaw_rate_ = 0;
    lane_run_ = {};
    off_path_ = false;
    polyline_.clear();
    relocalise();
    publish();
    return time_ns_;
  }
  if (cmd && cmd->timed) {
    // Exactly this pose and speed (both domains).
    const Command::Pose& p = *cmd->timed;
    const double v = p.speed.value_or(0.0);
    const double yaw = std::remainder(p.yaw, 2 * M_PI);
    yaw_rate_ = std::remainder(yaw - yaw_, 2 * M_PI) / dt;
    acc_ = (v - v_) / dt;
    x_ = p.x;
    y_ = p.y;
    yaw_ = yaw;
    v_ = v;
    lane_run_ = {};
    off_path_ = true;
    changing_ = 0;
    publish();
    return time_ns_;
  }
  if (cmd && cmd->route && *cmd->route != last_route_) {
    last_route_ = *cmd->route;
    if (off_path_ && !cmd->polyline) off_path_ = false;  // re-planned from here
    apply_route(*cmd->route);
  }
  const bool on_poly = cmd && cmd->polyline;
  if (on_poly) {
    set_polyline(*cmd->polyline);
    off_path_ = true;
    lane_run_ = {};
    changing_ = 0;
  } else if (off_path_) {
    // Back to the AI from where the command left it.
    off_path_ = false;
    polyline_.clear();
    relocalise();
  }
  if (lost_ && !on_poly && time_ns_ >= next_look_ns_) relocalise();
  if (cmd && cmd->lane && !lost_) {
    begin_lane(*cmd->lane);
  } else if (lane_run_.active) {
    lane_run_ = {};
    changing_ = 0;
  }

  // Longitudinal: the speed command, else IDM along the path it follows.
  const Path& drive = on_poly ? traj_path_ : path_;
  size_t dcursor = cursor_;
  double darc = arc_;
  if (on_poly) {
    const auto pr = traj_path_.project(x_, y_);
    dcursor = pr.index;
    darc = pr.arc;
  }
  const double my_front_off = 0.5 * length_ + (0.5 * length_ - rear_overhang_);
  double acc = 0, v_new = v_;
  if (cmd && cmd->speed) {
    v_new = cmd->speed->speed;
    acc = cmd->speed->acceleration ? *cmd->speed->acceleration : (v_new - v_) / dt;
    commanded_acc_ = acc;
  } else if (lost_) {
    acc = -std::min(driving_.idm.b, v_ / dt);
    v_new = std::max(0.0, v_ + acc * dt);
  } else {
    const double my_front = darc + my_front_off;
    const double v0 = desired_speed();
    const auto [gap, vl] = stop_ahead(drive, dcursor, my_front, on_poly);
    acc = driving_.idm.accel(v_, gap, vl, v0);
    acc = std::clamp(acc, -max_decel_, driving_.idm.a);
    v_new = v_ + acc * dt;
    if (v_new < 0) {
      v_new = 0;
      acc = -v_ / dt;
    }
  }

  // Lateral: the lane command, else pure pursuit on the path it follows.
  if (lane_run_.active) {
    const double p = std::clamp(lane_run_.progress, 0.0, 1.0);
    const double d =
        (1.0 - p) * (lane_run_.d_from + lane_run_.e0) + p * (cmd->lane ? cmd->lane->offset : 0.0);
    const double ds = v_new * dt;
    const odr::Pose2 q = path_.at(arc_ + ds);
    // Along its motion; at the end (progress 1) along the lane, as a driver straightens up.
    const double yaw =
        ds > 1e-6 && p < 1.0
            ? std::remainder(q.heading + std::atan2(d - lane_run_.lateral, ds), 2 * M_PI)
            : q.heading;
    x_ = q.x - d * std::sin(q.heading);
    y_ = q.y + d * std::cos(q.heading);
    yaw_rate_ = std::remainder(yaw - yaw_, 2 * M_PI) / dt;
    yaw_ = yaw;
    lane_run_.lateral = d;
    changing_ = p < 1.0 ? lane_run_.side : 0;
  } else if (lost_) {
    x_ += v_new * std::cos(yaw_) * dt;
    y_ += v_new * std::sin(yaw_) * dt;
    yaw_rate_ = 0;
  } else {
    const ru::KinematicBicycle bicycle{wheelbase_};
    const ru::PlanarPose pose{x_, y_, yaw_};
    const double steer = ru::pursue(ru::PurePursuit{}, bicycle, drive, darc, pose, v_, on_poly);
    const ru::BicycleMotion moved = ru::step_bicycle(bicycle, pose, v_new, steer, dt);
    x_ = moved.pose.x;
    y_ = moved.pose.y;
    yaw_ = moved.pose.yaw;
    yaw_rate_ = moved.yaw_rate;
  }
  v_ = v_new;
  acc_ = acc;
  if (!on_poly && !lost_) {
    // Where it is on the path now.
    const size_t lo = cursor_ > 20 ? cursor_ - 20 : 0;
    const auto pr =
        path_.project(x_, y_, lo, cursor_ + 40 + static_cast<size_t>(v_ * dt / kSampleDs));
    cursor_ = pr.index;
    arc_ = pr.arc;
    if (!lane_run_.active && changing_ != 0 && std::abs(pr.lateral) < 0.2) changing_ = 0;
    while (onward_ && !goals_.empty() && arc_ >= goal_arcs_.front() - 1.0) {
      goals_.erase(goals_.begin());
      goal_arcs_.erase(goal_arcs_.begin());
    }
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
      lane_run_ = {};
    }
  }
  const bool ai_lateral = !absent_ && !on_poly && !lost_ && !lane_run_.active;
  if (ai_lateral && lane_changes_ && changing_ == 0 && time_ns_ >= next_mobil_ns_) {
    next_mobil_ns_ = time_ns_ + 500000000;  // every 0.5 s
    consider_lane_change();
  }
  if (ai_lateral && onward_ && goals_.empty() && open_end_ && changing_ == 0 &&
      path_.length() - arc_ < std::max(200.0, 10.0 * v_))
    extend();
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
  const bool braking = commanded_acc_ ? *commanded_acc_ < 0 : acc_ < -0.3;
  if (braking || (v_ < 0.1 && !absent_)) lights |= data::RoadUser::BRAKE;
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
    data::RoadUsers users;
    if (dp.is_proto() && dp.proto_type() == datapack::type_name<data::RoadUsers>()) {
      datapack::read_proto(dp, &users);
    } else if (dp.is_proto() && dp.proto_type() == datapack::type_name<data::RoadUser>()) {
      datapack::read_proto(dp, users.add_users());
    } else {
      fail(name, std::string("expected convoy.data.RoadUsers or RoadUser, got ") +
                     (dp.is_proto() ? dp.proto_type() : std::string("JSON")));
    }
    last_neighbours_ = std::make_shared<const ru::Neighbours>(neighbours_of(users, name_));
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
    driving_ = weather_adaptation_ ? ru::adapt_to_weather(base_idm_, {mu, visibility})
                                   : ru::Driving{base_idm_};
    return;
  } else if (name == command_dp_) {
    if (!dp.is_json()) fail(name, "expected a JSON datapack of commands");
    const json j = datapack::read_json(dp);
    if (j.is_object() && j.empty()) {
      command_.reset();  // on its own AI
    } else {
      try {
        command_ = ru::parse_vehicle_command(j, name, *graph_);
      } catch (const ru::CommandError& e) {
        fail(e.key(), e.detail());
      }
    }
    return;
  } else if (name == lights_dp_) {
    if (!dp.is_json()) fail(name, "expected a JSON datapack {\"signals\": {id: state}}");
    const json j = datapack::read_json(dp);
    if (!j.is_object()) fail(name, "expected a JSON object {\"signals\": {id: state}}");
    last_lights_ = std::make_shared<const ru::LightStates>(light_states(j));
  } else {
    warn_once("dp:" + name, "datapack '" + name + "' is not one it reads (" + neighbours_dp_ +
                                ", " + lights_dp_ + ", " + weather_dp_ + ", " + command_dp_ +
                                "); ignored");
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
