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
// contract) and the per-step decision (road_users/vehicle_behaviour.h: its description, its
// state, the step) are in src/road_users; this engine reads its config into the description,
// turns its datapacks into the step's inputs and publishes its state.
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
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
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
#include "road_user_wire/datapack_users.h"
#include "road_users/agent_config.h"
#include "road_users/command.h"
#include "road_users/lights.h"
#include "road_users/neighbours.h"
#include "road_users/routing.h"
#include "road_users/vehicle_behaviour.h"
#include "road_users/weather.h"

namespace convoy::engines::vehicle_agent {
namespace odr = convoy::opendrive;
namespace ru = convoy::road_users;
namespace wire = convoy::road_user_wire;
using nlohmann::json;

namespace {

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

}  // namespace

class VehicleAgent final : public Engine {
 public:
  std::vector<engine::DataPackId> initialize(const std::string& name, const json& config,
                                             int64_t timestep_ns) override;
  int64_t step(int64_t duration_ns) override;
  void set_datapack(const datapack::View& dp) override;
  void get_datapack(const engine::DataPackId& id, datapack::Builder& out) override {
    if (id.name() == state_dp_) datapack::write_proto(out, state_);
  }
  // Its state replaced by its start's (the weather it drives in is kept, as it was).
  void reset() override {
    const ru::Driving weather = s_.driving;
    s_ = ru::start_vehicle(d_);
    s_.driving = weather;
    start();
  }
  std::vector<std::string> take_warnings() override { return std::move(warnings_); }

 private:
  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw std::runtime_error("vehicle_agent '" + d_.name + "': " + key + ": " + what);
  }
  // The users of a neighbours datapack, read in place (road_user_wire).
  void read_users(const std::string& key, const datapack::View& dp,
                  const std::function<void(const wire::UserFields&)>& visit) const {
    try {
      wire::for_each_user(dp, visit);
    } catch (const std::invalid_argument& e) {
      fail(key, e.what());
    }
  }
  void warn_once(const std::string& key, const std::string& text) {
    if (warned_[key]) return;
    warned_[key] = true;
    std::fprintf(stderr, "warning: vehicle_agent '%s': %s\n", d_.name.c_str(), text.c_str());
    warnings_.push_back(text);
  }
  void flush_warnings() {
    for (const auto& [key, text] : s_.warnings) warn_once(key, text);
    s_.warnings.clear();
  }
  void read_parameters(const json& config);
  std::pair<std::string, int> parse_lane(const std::string& key, const json& v) const;
  odr::LaneIndex destination(const json& to) const;  // Route.to's exit lane
  odr::LaneRoute pick_route(const json& config, uint64_t seed) const;
  odr::LaneRoute route_at(const json& config) const;  // Position -> Route.to
  odr::LaneRoute route_between(const json& r) const;  // Route.from -> Route.to
  void plan_from_start_pose(const json& config, std::mt19937_64& rng);
  void start();  // its published state from s_ at its start
  void publish();

  std::unique_ptr<odr::Network> net_;
  std::unique_ptr<odr::LaneGraph> graph_;
  ru::VehicleDescription d_;
  ru::VehicleState s_;
  std::string state_dp_, neighbours_dp_, lights_dp_, weather_dp_;
  data::RoadUser state_;
  std::map<std::string, bool> warned_;
  std::vector<std::string> warnings_;
};

std::pair<std::string, int> VehicleAgent::parse_lane(const std::string& key, const json& v) const {
  try {
    return ru::parse_lane_ref(key, v);
  } catch (const ru::CommandError& e) {
    fail(e.key(), e.detail());
  }
}

odr::LaneIndex VehicleAgent::destination(const json& to) const {
  const auto [tr, tl] = parse_lane("Route.to", to);
  if (!net_->find_road(tr)) fail("Route.to", "road " + tr + " is not in the map " + net_->source);
  try {
    return graph_->exit_lane(tr, tl);
  } catch (const std::exception& e) {
    fail("Route.to", e.what());
  }
}

odr::LaneRoute VehicleAgent::route_at(const json& config) const {
  // Placed at a world point: on a driving lane there, routed to Route.to.
  const json& r = config.at("Route");
  const json& pos = config.at("Position");
  if (!pos.contains("x") || !pos.contains("y") || !pos["x"].is_number() || !pos["y"].is_number())
    fail("Position", "expected numbers \"x\" and \"y\"");
  const double x = pos["x"].get<double>(), y = pos["y"].get<double>();
  std::optional<double> heading;
  if (pos.contains("yaw")) heading = pos["yaw"].get<double>();
  char where[96];
  std::snprintf(where, sizeof where, "(%.2f, %.2f)", x, y);
  const auto loc = graph_->locate(x, y, heading, 50.0);
  if (!loc || loc->distance > 0 || !graph_->lane(loc->lane).drivable()) {
    fail("Position", std::string("placed off-road: ") + where + " is not on a driving lane of " +
                         net_->source + " (" + ru::nearest_lane_text(*graph_, loc) + ")");
  }
  if (r.contains("from")) fail("Route.from", "give Route.from or Position, not both");
  if (!r.contains("to")) fail("Route.to", "needed with Position (where to drive)");
  const odr::LaneIndex dest = destination(r["to"]);
  const odr::LaneNode& dn = graph_->lane(dest);
  auto route = graph_->route(loc->lane, loc->s, dest, dn.forward ? dn.s1 : dn.s0);
  if (!route) {
    fail("Route", std::string("no route from ") + where + " (" + loc->road_id + ":" +
                      std::to_string(loc->lane_id) + ") to " + r["to"].get<std::string>());
  }
  return *route;
}

odr::LaneRoute VehicleAgent::route_between(const json& r) const {
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
      fail(key,
           "road " + road + " has no lane " + std::to_string(lane) + " (in " + net_->source + ")");
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

odr::LaneRoute VehicleAgent::pick_route(const json& config, uint64_t seed) const {
  const json& r = config.at("Route");
  const json& pos = config.at("Position");
  if (!pos.is_object()) fail("Position", "expected {\"x\": ..., \"y\": ...}");
  if (!pos.empty()) return route_at(config);
  if (r.is_object() && (r.contains("from") || r.contains("to"))) return route_between(r);
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

void VehicleAgent::read_parameters(const json& config) {
  ru::Idm& idm = d_.idm;
  idm.v0 = config.at("v0").get<double>();
  idm.T = config.at("T").get<double>();
  idm.s0 = config.at("s0").get<double>();
  idm.a = config.at("a").get<double>();
  idm.b = config.at("b").get<double>();
  idm.delta = config.at("delta").get<double>();
  d_.limit_factor = config.at("SpeedLimitFactor").get<double>();
  d_.max_decel = config.at("MaxDeceleration").get<double>();
  d_.mobil.politeness = config.at("politeness").get<double>();
  d_.mobil.threshold = config.at("threshold").get<double>();
  d_.mobil.b_safe = config.at("b_safe").get<double>();
  d_.lane_changes = config.at("LaneChanges").get<bool>();
  d_.yielding = config.at("JunctionYielding").get<bool>();
  d_.reaction_s = config.at("ReactionTime").get<double>();
  d_.radius = config.at("NeighbourRadius").get<double>();
  d_.start_s = config.at("StartS").get<double>();
  d_.initial_speed = config.at("InitialSpeed").get<double>();
  d_.respawn = config.at("Respawn").get<bool>();
  d_.respawn_delay_s = config.at("RespawnDelay").get<double>();
  d_.model = config.at("Model").get<std::string>();
  d_.category = config.at("Category").get<std::string>();
  d_.length = config.at("Length").get<double>();
  d_.width = config.at("Width").get<double>();
  d_.height = config.at("Height").get<double>();
  d_.wheelbase = config.at("Wheelbase").get<double>();
  if (d_.wheelbase >= d_.length) fail("Wheelbase", "must be shorter than Length");
  d_.rear_overhang = 0.5 * (d_.length - d_.wheelbase);
  state_dp_ = config.at("StateDataPack").get<std::string>();
  neighbours_dp_ = config.at("NeighboursDataPack").get<std::string>();
  lights_dp_ = config.at("TrafficLightsDataPack").get<std::string>();
  weather_dp_ = config.at("WeatherDataPack").get<std::string>();
  d_.weather_adaptation = config.at("WeatherAdaptation").get<bool>();
  d_.command_key = config.at("CommandDataPack").get<std::string>();
}

void VehicleAgent::plan_from_start_pose(const json& config, std::mt19937_64& rng) {
  odr::Pose2 pose;
  try {
    pose = ru::parse_start_pose(config.at("StartPose"));
  } catch (const ru::CommandError& e) {
    fail(e.key(), e.detail());
  }
  const json& r = config.at("Route");
  if (!r.is_object()) fail("Route", "expected {\"to\": \"ROAD:LANE\"} with StartPose");
  for (const auto& [k, v] : r.items()) {
    if (k != "to")
      fail("Route." + k, "give StartPose or Route.from, not both (Route: {\"to\"} only)");
  }
  if (config.at("Position").is_object() && !config.at("Position").empty())
    fail("StartPose", "give Position or StartPose, not both");
  if (d_.start_s > 0) fail("StartS", "give StartS or StartPose, not both");
  d_.start_pose = pose;
  char where[96];
  std::snprintf(where, sizeof where, "(%.2f, %.2f)", pose.x, pose.y);
  const auto loc = ru::locate_drivable(*graph_, pose.x, pose.y, pose.heading, 50.0);
  if (!loc)
    fail("StartPose",
         std::string(where) + " is not within 50 m of a driving lane of " + net_->source);
  d_.initial_onward = !r.contains("to");
  if (r.contains("to")) {
    const odr::LaneIndex dest = destination(r["to"]);
    const odr::LaneNode& dn = graph_->lane(dest);
    if (!dn.drivable()) {
      const auto [tr, tl] = parse_lane("Route.to", r["to"]);
      fail("Route.to", "lane " + tr + ":" + std::to_string(tl) + " is a " + dn.type +
                           " lane, not a driving lane");
    }
    d_.initial_goals.push_back({dest, dn.forward ? dn.s1 : dn.s0});
  }
  size_t failed = 0;
  const ru::RoutePlan plan{*graph_, ru::kVehicleOnwardLength, rng};
  auto route = ru::route_from(plan, d_.initial_goals, d_.initial_onward, loc->lane, loc->s, 0,
                              &d_.initial_open_end, &failed);
  if (!route) {
    fail("Route", std::string("no route from StartPose ") + where + " (" + loc->road_id + ":" +
                      std::to_string(loc->lane_id) + ") to " + r["to"].get<std::string>());
  }
  d_.initial_route = *route;
}

std::vector<engine::DataPackId> VehicleAgent::initialize(const std::string& name,
                                                         const json& config, int64_t) {
  d_.name = name;
  if (!config.contains("Map") || !config["Map"].is_string())
    fail("Map", "no map given (an OpenDRIVE .xodr file)");
  try {
    net_ = std::make_unique<odr::Network>(odr::load(config["Map"].get<std::string>()));
    graph_ = std::make_unique<odr::LaneGraph>(*net_);
  } catch (const std::exception& e) {
    fail("Map", e.what());
  }
  d_.graph = graph_.get();
  read_parameters(config);
  const uint64_t seed = config.at("Seed").get<uint64_t>();
  std::mt19937_64 rng(seed * 0x9E3779B97F4A7C15ull + 0x0A7Eull);  // onward choices
  const json& sp = config.at("StartPose");
  if (!sp.is_object()) fail("StartPose", "expected {\"x\": ..., \"y\": ..., \"yaw\": ...}");
  if (!sp.empty()) {
    plan_from_start_pose(config, rng);
  } else {
    d_.initial_route = pick_route(config, seed);
    const auto& last = d_.initial_route.segments.back();
    d_.initial_goals = {{last.lane, last.s_to}};
  }
  d_.initial_rng = rng;
  const ru::Path p = ru::make_path(*graph_, d_.initial_route, ru::kVehicleSampleDs);
  if (p.poses.size() < 2)
    fail(d_.start_pose ? "StartPose" : "Route", "the route is empty (a dead end there)");
  if (d_.start_s >= p.length())
    fail("StartS", "placed off its route: " + std::to_string(d_.start_s) +
                       " m is beyond the route's end (" + std::to_string(p.length()) + " m)");
  s_ = ru::start_vehicle(d_);
  start();

  std::vector<engine::DataPackId> ids(1);
  ids[0].set_name(state_dp_);
  ids[0].set_type(std::string(datapack::type_name<data::RoadUser>()));
  ids[0].set_engine_name(name);
  return ids;
}

void VehicleAgent::start() {
  state_.Clear();
  state_.set_id(d_.name);
  state_.set_category(d_.category);
  state_.set_model(d_.model);
  state_.set_length(d_.length);
  state_.set_width(d_.width);
  state_.set_height(d_.height);
  state_.set_length_offset(0.5 * d_.length - d_.rear_overhang);
  publish();
}

int64_t VehicleAgent::step(int64_t duration_ns) {
  bool moved = false;
  try {
    moved = ru::step_vehicle(d_, s_, duration_ns);
  } catch (const ru::CommandError& e) {
    flush_warnings();
    fail(e.key(), e.detail());
  }
  flush_warnings();
  if (moved) publish();
  return s_.time_ns;
}

void VehicleAgent::publish() {
  state_.set_absent(s_.absent);
  state_.set_x(s_.x);
  state_.set_y(s_.y);
  state_.set_yaw(s_.yaw);
  state_.set_speed(s_.v);
  state_.set_acceleration(s_.acc);
  state_.set_yaw_rate(s_.yaw_rate);
  state_.set_vx(s_.v * std::cos(s_.yaw));
  state_.set_vy(s_.v * std::sin(s_.yaw));
  uint32_t lights = 0;
  const bool braking = s_.commanded_acc ? *s_.commanded_acc < 0 : s_.acc < -0.3;
  if (braking || (s_.v < 0.1 && !s_.absent)) lights |= data::RoadUser::BRAKE;
  if (s_.changing > 0) lights |= data::RoadUser::INDICATOR_LEFT;
  if (s_.changing < 0) lights |= data::RoadUser::INDICATOR_RIGHT;
  state_.set_lights(lights);
  const auto loc = graph_->locate(s_.x, s_.y, s_.yaw);
  if (loc) {
    state_.set_road(loc->road_id);
    state_.set_lane(loc->lane_id);
    state_.set_s(loc->s);
    state_.set_t(loc->road_t);
    const odr::WorldPose w = graph_->world_pose(loc->road_id, loc->lane_id, loc->s, loc->t);
    state_.set_z(w.z);
  }
  state_.set_time_ns(s_.time_ns);
}

void VehicleAgent::set_datapack(const datapack::View& dp) {
  if (dp.empty()) return;
  const std::string& name = dp.id().name();
  if (name == neighbours_dp_) {
    auto around = std::make_shared<ru::Neighbours>();
    read_users(name, dp, [&](const wire::UserFields& u) {
      if (u.absent || u.id == d_.name) return;
      around->push_back(
          {std::string(u.id), u.x, u.y, u.yaw, u.speed, u.length, u.width, u.length_offset});
    });
    ru::perceive(s_, std::move(around), nullptr);
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
    ru::drive_in(d_, s_, {mu, visibility});
  } else if (name == d_.command_key) {
    if (!dp.is_json()) fail(name, "expected a JSON datapack of commands");
    const json j = datapack::read_json(dp);
    if (j.is_object() && j.empty()) {
      s_.command.reset();  // on its own AI
    } else {
      try {
        s_.command = ru::parse_vehicle_command(j, name, *graph_);
      } catch (const ru::CommandError& e) {
        fail(e.key(), e.detail());
      }
    }
  } else if (name == lights_dp_) {
    if (!dp.is_json()) fail(name, "expected a JSON datapack {\"signals\": {id: state}}");
    const json j = datapack::read_json(dp);
    if (!j.is_object()) fail(name, "expected a JSON object {\"signals\": {id: state}}");
    ru::perceive(s_, nullptr, std::make_shared<const ru::LightStates>(light_states(j)));
  } else {
    warn_once("dp:" + name, "datapack '" + name + "' is not one it reads (" + neighbours_dp_ +
                                ", " + lights_dp_ + ", " + weather_dp_ + ", " + d_.command_key +
                                "); ignored");
  }
}

CONVOY_REGISTER_ENGINE("vehicle_agent", VehicleAgent);

}  // namespace convoy::engines::vehicle_agent
