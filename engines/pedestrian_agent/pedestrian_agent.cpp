// EngineType "pedestrian_agent": one pedestrian as its own engine, on an OpenDRIVE lane graph.
//
// How it walks, waits at the curb (lights, critical gap), stops and steps back while crossing:
// road_users/pedestrian_behaviour.h. Speed (N(Speed, SpeedSd)), critical gap (N(CriticalGap,
// CriticalGapSd)), the mid-block choice and a route when none is given are drawn from Seed.
//
// Datapacks written:
//   <StateDataPack> ("state")  convoy.data.RoadUser, category "pedestrian", walk_phase
//                    advancing with the distance walked; `absent` once its route has ended.
// Datapacks read:
//   <NeighboursDataPack> ("neighbours")  convoy.data.RoadUsers (or one RoadUser): road users
//                    around it; those of category "pedestrian" and its own id are skipped.
//   <TrafficLightsDataPack> ("traffic_lights")  JSON {"signals": {"<signal id>": state}}.
//   <WeatherDataPack> ("weather")  optional JSON (docs/road_users.md): in rain it walks
//                    faster, x(1 + 0.2 precipitation).
//   <CommandDataPack> ("command")  optional JSON, the scenario engine's commands for this step
//                    (docs/road_users.md, "Commands"): speed (its walking speed, gap acceptance
//                    ignored), route (positions walked through in straight lines, then back to
//                    its sidewalk routing), trajectory (timed: the pose to take; untimed: a
//                    polyline to walk), teleport. `lane` is an error for a pedestrian.
//
// StartPose {x, y, yaw}: it starts exactly there and walks to the nearest sidewalk, then to
// Route.to, or without a Route along the sidewalks onward in the direction it faces (forks
// chosen by Seed). With no sidewalk within 50 m it stands there until commanded.
//
// Its planner (road_users/pedestrian_walks.h), its step (pedestrian_behaviour.h), the command
// contract, the crossing's threats, gap acceptance, lights and caution on the road are in
// src/road_users; this engine reads its config, turns its datapacks into inputs and publishes.
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
#include <tuple>
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
#include "road_users/pedestrian_behaviour.h"
#include "road_users/pedestrian_command.h"
#include "road_users/pedestrian_walks.h"

namespace convoy::engines::pedestrian_agent {
namespace odr = convoy::opendrive;
namespace ru = convoy::road_users;
namespace wire = convoy::road_user_wire;
using nlohmann::json;

namespace {

// The signals' states of the lights datapack ({"signals": {id: state}}, or the map itself); a
// state that is not a string is left out.
ru::SignalStates signal_states(const json& j) {
  ru::SignalStates out;
  const json& sig = j.contains("signals") ? j["signals"] : j;
  if (!sig.is_object()) return out;
  for (const auto& [id, v] : sig.items()) {
    if (v.is_string()) out.emplace(id, v.get<std::string>());
  }
  return out;
}

// The ends of its walk as its config gives them, and how (for messages).
struct Ends {
  ru::Spot from, to;
  const odr::Crosswalk* only = nullptr;
  std::string what;
};

}  // namespace

class PedestrianAgent final : public Engine {
 public:
  std::vector<engine::DataPackId> initialize(const std::string& name, const json& config,
                                             int64_t timestep_ns) override;
  int64_t step(int64_t duration_ns) override;
  void set_datapack(const datapack::View& dp) override;
  void get_datapack(const engine::DataPackId& id, datapack::Builder& out) override {
    if (id.name() == state_dp_) datapack::write_proto(out, state_);
  }
  void reset() override {
    s_ = ru::start_pedestrian(d_);
    start();
  }
  std::vector<std::string> take_warnings() override { return std::move(warnings_); }

 private:
  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw std::runtime_error("pedestrian_agent '" + d_.name + "': " + key + ": " + what);
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
    std::fprintf(stderr, "warning: pedestrian_agent '%s': %s\n", d_.name.c_str(), text.c_str());
    warnings_.push_back(text);
  }
  void read_parameters(const json& config, std::mt19937_64& rng);
  ru::Spot sidewalk(const std::string& key, const json& v, const json* s_value,
                    bool at_entry) const;
  Ends ends_across(const json& r) const;               // Route.crosswalk
  Ends ends_at(const json& r, const json& pos) const;  // Position -> Route.to
  ru::WalkPlan drawn_plan(std::mt19937_64& rng) const;
  ru::WalkPlan pick_plan(const json& config, std::mt19937_64& rng, bool mid_block_drawn,
                         double factor);
  void walk_from_start_pose(const json& config, std::mt19937_64& rng);
  void start();  // its published state from s_ at its start
  void publish();

  std::unique_ptr<odr::Network> net_;
  std::unique_ptr<odr::LaneGraph> graph_;
  ru::PedestrianDescription d_;
  ru::PedestrianState s_;
  bool mid_block_drawn_ = false;
  double mid_block_distance_ = 0;
  std::string state_dp_, neighbours_dp_, weather_dp_, command_dp_;
  data::RoadUser state_;
  std::map<std::string, bool> warned_;
  std::vector<std::string> warnings_;
};

ru::Spot PedestrianAgent::sidewalk(const std::string& key, const json& v, const json* s_value,
                                   bool at_entry) const {
  std::string road;
  int lane = 0;
  try {
    std::tie(road, lane) = ru::parse_lane_ref(key, v);
  } catch (const ru::CommandError& e) {
    fail(e.key(), e.detail());
  }
  const std::string text = v.get<std::string>();
  const odr::Road* r = net_->find_road(road);
  if (!r) fail(key, "road " + road + " is not in the map " + net_->source);
  double s = 0;
  odr::LaneIndex li = odr::kNoLane;
  if (s_value) {
    if (!s_value->is_number()) fail(key + "_s", "expected a number (m along the road)");
    s = s_value->get<double>();
    if (s < 0 || s > r->length)
      fail(key + "_s", "outside road " + road + " (0.." + std::to_string(r->length) + " m)");
    li = graph_->find(road, lane, s);
  } else {
    try {
      li = at_entry ? graph_->entry_lane(road, lane) : graph_->exit_lane(road, lane);
    } catch (const std::exception& e) {
      fail(key, e.what());
    }
    if (li != odr::kNoLane) {
      const odr::LaneNode& n = graph_->lane(li);
      s = (at_entry == n.forward) ? n.s0 : n.s1;
    }
  }
  if (li == odr::kNoLane)
    fail(key,
         "road " + road + " has no lane " + std::to_string(lane) + " (in " + net_->source + ")");
  if (graph_->lane(li).type != "sidewalk")
    fail(key, "lane " + text + " is a " + graph_->lane(li).type + " lane, not a sidewalk");
  return {li, s};
}

Ends PedestrianAgent::ends_across(const json& r) const {
  Ends e;
  const odr::Crosswalk*& only = e.only;
  const std::string id =
      r["crosswalk"].is_string() ? r["crosswalk"].get<std::string>() : r["crosswalk"].dump();
  for (const auto& cw : graph_->crosswalks()) {
    if (cw.id == id) only = &cw;
  }
  if (!only) fail("Route.crosswalk", "no crosswalk with id " + id + " in " + net_->source);
  if (only->ends[0] == odr::kNoLane || only->ends[1] == odr::kNoLane)
    fail("Route.crosswalk", "crosswalk " + id + " has no sidewalk at both ends");
  const bool rev = r.value("reverse", false);
  const odr::Road* road = net_->find_road(only->road_id);
  const double dir = only->s < 0.5 * road->length ? 1.0 : -1.0;
  const double s = std::clamp(only->s + dir * 8.0, 0.0, road->length);
  for (int k = 0; k < 2; ++k) {
    const odr::LaneIndex end = only->ends[rev ? 1 - k : k];
    const odr::LaneIndex li = graph_->find(only->road_id, graph_->lane(end).lane_id, s);
    (k == 0 ? e.from : e.to) =
        ru::Spot{li == odr::kNoLane ? end : li, li == odr::kNoLane ? only->s : s};
  }
  e.what = "across crosswalk " + id;
  return e;
}

Ends PedestrianAgent::ends_at(const json& r, const json& pos) const {
  Ends e;
  if (!pos.contains("x") || !pos.contains("y") || !pos["x"].is_number() || !pos["y"].is_number())
    fail("Position", "expected numbers \"x\" and \"y\"");
  const double x = pos["x"].get<double>(), y = pos["y"].get<double>();
  char where[96];
  std::snprintf(where, sizeof where, "(%.2f, %.2f)", x, y);
  const auto loc = graph_->locate(x, y, std::nullopt, 50.0);
  if (!loc || loc->distance > 0 || graph_->lane(loc->lane).type != "sidewalk") {
    fail("Position", std::string("placed off the sidewalks: ") + where +
                         " is not on a sidewalk of " + net_->source + " (" +
                         ru::nearest_lane_text(*graph_, loc) + ")");
  }
  if (r.contains("from")) fail("Route.from", "give Route.from or Position, not both");
  if (!r.contains("to")) fail("Route.to", "needed with Position (where to walk)");
  e.from = {loc->lane, loc->s};
  e.to = sidewalk("Route.to", r["to"], r.contains("to_s") ? &r["to_s"] : nullptr, false);
  e.what = std::string("from ") + where + " to " + r["to"].get<std::string>();
  return e;
}

ru::WalkPlan PedestrianAgent::drawn_plan(std::mt19937_64& rng) const {
  ru::WalkPlan p;
  // Drawn from the seed: between two points on sidewalks outside junctions, at least 30 m
  // apart along the route; one that crosses a road is preferred in the first attempts.
  std::vector<odr::LaneIndex> lanes;
  for (const auto& l : graph_->lanes()) {
    if (l.type == "sidewalk" && l.junction == "-1" && l.length > 5) lanes.push_back(l.index);
  }
  if (lanes.empty()) fail("Map", "no sidewalk outside junctions in " + net_->source);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int attempt = 0; attempt < 200; ++attempt) {
    const auto& a = graph_->lane(lanes[rng() % lanes.size()]);
    const auto& b = graph_->lane(lanes[rng() % lanes.size()]);
    const double sa = a.s0 + unit(rng) * (a.s1 - a.s0);
    const double sb = b.s0 + unit(rng) * (b.s1 - b.s0);
    ru::WalkPlan q = ru::plan_walk(*graph_, {a.index, sa}, {b.index, sb}, nullptr);
    if (!q.before || q.length < 30 || (attempt < 100 && !q.cross)) continue;
    p = std::move(q);
    break;
  }
  if (!p.before)
    fail("Route", "none given, and no route could be drawn from its Seed on " + net_->source);
  return p;
}

ru::WalkPlan PedestrianAgent::pick_plan(const json& config, std::mt19937_64& rng,
                                        bool mid_block_drawn, double factor) {
  const json& r = config.at("Route");
  const json& pos = config.at("Position");
  if (!r.is_object()) fail("Route", "expected an object");
  if (!pos.is_object()) fail("Position", "expected {\"x\": ..., \"y\": ...}");
  for (const auto& [k, v] : r.items()) {
    if (k != "from" && k != "to" && k != "from_s" && k != "to_s" && k != "crosswalk" &&
        k != "reverse")
      fail("Route", "unknown key \"" + k + "\" (from, to, from_s, to_s, crosswalk, reverse)");
  }
  ru::WalkPlan p;
  Ends e;
  if (r.contains("crosswalk")) {
    if (r.contains("from") || r.contains("to") || !pos.empty())
      fail("Route.crosswalk", "give a crosswalk, or from / to, not both");
    e = ends_across(r);
  } else if (!pos.empty()) {
    e = ends_at(r, pos);
  } else if (r.contains("from") || r.contains("to")) {
    if (!r.contains("from") || !r.contains("to")) fail("Route", "give both \"from\" and \"to\"");
    e.from = sidewalk("Route.from", r["from"], r.contains("from_s") ? &r["from_s"] : nullptr, true);
    e.to = sidewalk("Route.to", r["to"], r.contains("to_s") ? &r["to_s"] : nullptr, false);
    e.what = "from " + r["from"].get<std::string>() + " to " + r["to"].get<std::string>();
  } else {
    p = drawn_plan(rng);
    e.what = "drawn from Seed";
  }
  const ru::Spot from = e.from;
  if (!p.before) p = ru::plan_walk(*graph_, from, e.to, e.only);
  if (!p.before)
    fail("Route", "no route " + e.what + " over the sidewalks and crosswalks of " + net_->source);
  if (mid_block_drawn && p.cross && !p.cross->crosswalk.empty()) {
    if (auto m = ru::mid_block(*graph_, *p.cross, factor)) {
      // Re-route the walks to and from the mid-block crossing.
      auto w1 = ru::walk(*graph_,
                         from.lane == odr::kNoLane ? ru::Spot{p.before->segments.front().lane,
                                                              p.before->segments.front().s_from}
                                                   : from,
                         m->from);
      const auto& last = p.after->segments.back();
      auto w2 = ru::walk(*graph_, m->to, ru::Spot{last.lane, last.s_to});
      if (w1 && w2) {
        p.before = w1;
        p.after = w2;
        p.cross = m;
      }
    }
  }
  return p;
}

void PedestrianAgent::read_parameters(const json& config, std::mt19937_64& rng) {
  // Draws in a fixed order: speed, gap, mid-block choice and distance, then the route.
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double z_speed = std::clamp(normal(rng), -2.0, 2.0);
  const double z_gap = std::clamp(normal(rng), -2.0, 2.0);
  const double u_mid = unit(rng);
  const double u_dist = unit(rng);
  d_.speed = std::max(
      0.3, config.at("Speed").get<double>() + z_speed * config.at("SpeedSd").get<double>());
  d_.respawn = config.at("Respawn").get<bool>();
  d_.respawn_delay_s = config.at("RespawnDelay").get<double>();
  d_.gap = std::max(0.0, config.at("CriticalGap").get<double>() +
                             z_gap * config.at("CriticalGapSd").get<double>());
  mid_block_drawn_ = u_mid < config.at("MidBlockProbability").get<double>();
  mid_block_distance_ = config.at("MidBlockDistance").get<double>() * (0.6 + 0.8 * u_dist);
  d_.obey_lights = config.at("ObeyLights").get<bool>();
  d_.stop_distance = config.at("StopDistance").get<double>();
  d_.step_back_distance = config.at("StepBackDistance").get<double>();
  d_.model = config.at("Model").get<std::string>();
  d_.length = config.at("Length").get<double>();
  d_.width = config.at("Width").get<double>();
  d_.height = config.at("Height").get<double>();
  d_.stride = config.at("StrideLength").get<double>();
  d_.radius = config.at("NeighbourRadius").get<double>();
  state_dp_ = config.at("StateDataPack").get<std::string>();
  neighbours_dp_ = config.at("NeighboursDataPack").get<std::string>();
  d_.lights_key = config.at("TrafficLightsDataPack").get<std::string>();
  weather_dp_ = config.at("WeatherDataPack").get<std::string>();
  command_dp_ = config.at("CommandDataPack").get<std::string>();
}

void PedestrianAgent::walk_from_start_pose(const json& config, std::mt19937_64& rng) {
  odr::Pose2 pose;
  try {
    pose = ru::parse_start_pose(config.at("StartPose"));
  } catch (const ru::CommandError& e) {
    fail(e.key(), e.detail());
  }
  const json& r = config.at("Route");
  if (!r.is_object()) fail("Route", "expected {\"to\": \"ROAD:LANE\"} with StartPose");
  for (const auto& [k, v] : r.items()) {
    if (k != "to" && k != "to_s")
      fail("Route." + k,
           "give StartPose or Route." + k + ", not both (Route: {\"to\"[, \"to_s\"]})");
  }
  if (config.at("Position").is_object() && !config.at("Position").empty())
    fail("StartPose", "give Position or StartPose, not both");
  d_.start_pose = pose;
  if (r.contains("to"))
    d_.dest = sidewalk("Route.to", r["to"], r.contains("to_s") ? &r["to_s"] : nullptr, false);
  d_.initial_path = ru::WalkPath{};
  d_.initial_path.append({pose});
  d_.initial_kr_from = INFINITY;
  if (!ru::walk_path_from(*graph_, d_.initial_path, pose.x, pose.y, pose.heading, d_.dest, rng,
                          &d_.initial_kr_from)) {
    char where[96];
    std::snprintf(where, sizeof where, "(%.2f, %.2f)", pose.x, pose.y);
    warn_once("idle", std::string("no sidewalk within 50 m of its StartPose ") + where +
                          ": it stands there until commanded");
  }
  d_.initial_idle = d_.initial_path.length() < 1e-6;
}

std::vector<engine::DataPackId> PedestrianAgent::initialize(const std::string& name,
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
  const uint64_t seed = config.at("Seed").get<uint64_t>();
  std::mt19937_64 rng(seed * 0x9E3779B97F4A7C15ull + 0x5EED);
  read_parameters(config, rng);
  std::mt19937_64 onward(seed * 0x9E3779B97F4A7C15ull + 0x0A7Eull);  // onward choices
  const json& sp = config.at("StartPose");
  if (!sp.is_object()) fail("StartPose", "expected {\"x\": ..., \"y\": ..., \"yaw\": ...}");
  if (!sp.empty()) {
    walk_from_start_pose(config, onward);
  } else {
    const ru::WalkPlan p = pick_plan(config, rng, mid_block_drawn_, mid_block_distance_);
    d_.initial_path = ru::make_walk_path(*graph_, p);
    if (d_.initial_path.poses.size() < 2 || d_.initial_path.length() < 0.5)
      fail("Route", "the route is empty (its start and end are the same point)");
    const odr::LaneRoute& last = p.after && !p.after->segments.empty() ? *p.after : *p.before;
    if (!last.segments.empty())
      d_.dest = ru::Spot{last.segments.back().lane, last.segments.back().s_to};
  }
  d_.initial_rng = onward;
  s_ = ru::start_pedestrian(d_);
  start();

  std::vector<engine::DataPackId> ids(1);
  ids[0].set_name(state_dp_);
  ids[0].set_type(std::string(datapack::type_name<data::RoadUser>()));
  ids[0].set_engine_name(name);
  return ids;
}

void PedestrianAgent::start() {
  state_.Clear();
  state_.set_id(d_.name);
  state_.set_category("pedestrian");
  state_.set_model(d_.model);
  state_.set_length(d_.length);
  state_.set_width(d_.width);
  state_.set_height(d_.height);
  publish();
}

int64_t PedestrianAgent::step(int64_t duration_ns) {
  const bool moved = ru::step_pedestrian(d_, s_, duration_ns);
  for (const auto& [key, text] : s_.warnings) warn_once(key, text);
  s_.warnings.clear();
  if (moved) publish();
  return s_.time_ns;
}

void PedestrianAgent::publish() {
  state_.set_absent(s_.absent);
  state_.set_x(s_.x);
  state_.set_y(s_.y);
  state_.set_yaw(s_.yaw);
  state_.set_speed(s_.v);
  state_.set_acceleration(s_.acc);
  state_.set_yaw_rate(s_.yaw_rate);
  state_.set_vx(s_.v * std::cos(s_.yaw));
  state_.set_vy(s_.v * std::sin(s_.yaw));
  state_.set_walk_phase(std::fmod(s_.walked / d_.stride, 1.0));
  const auto loc = graph_->locate(s_.x, s_.y);
  if (loc) {
    state_.set_road(loc->road_id);
    state_.set_lane(loc->lane_id);
    state_.set_s(loc->s);
    state_.set_t(loc->road_t);
    state_.set_z(graph_->world_pose(loc->road_id, loc->lane_id, loc->s, loc->t).z);
  }
  state_.set_time_ns(s_.time_ns);
}

void PedestrianAgent::set_datapack(const datapack::View& dp) {
  if (dp.empty()) return;
  const std::string& name = dp.id().name();
  if (name == neighbours_dp_) {
    auto around = std::make_shared<ru::WalkerNeighbours>();
    read_users(name, dp, [&](const wire::UserFields& u) {
      if (u.absent || u.id == d_.name) return;
      (u.category == "pedestrian" ? around->walkers : around->vehicles)
          .push_back(
              {std::string(u.id), u.x, u.y, u.yaw, u.speed, u.length, u.width, u.length_offset});
    });
    s_.neighbours = std::move(around);
  } else if (name == d_.lights_key) {
    if (!dp.is_json()) fail(name, "expected a JSON datapack {\"signals\": {id: state}}");
    const json j = datapack::read_json(dp);
    if (!j.is_object()) fail(name, "expected a JSON object {\"signals\": {id: state}}");
    s_.lights = std::make_shared<const ru::SignalStates>(signal_states(j));
  } else if (name == command_dp_) {
    if (!dp.is_json()) fail(name, "expected a JSON datapack of commands");
    const json j = datapack::read_json(dp);
    if (j.is_object() && j.empty()) {
      s_.command.reset();  // on its own AI
    } else {
      try {
        s_.command = ru::parse_pedestrian_command(j, name, *graph_);
      } catch (const ru::CommandError& e) {
        fail(e.key(), e.detail());
      }
    }
  } else if (name == weather_dp_) {
    if (!dp.is_json()) fail(name, "expected the JSON weather datapack");
    const json w = datapack::read_json(dp);
    if (!w.is_object()) fail(name, "expected a JSON object");
    const double p = w.value("precipitation", 0.0);
    const bool rain = w.value("precipitation_type", std::string("none")) == "rain";
    s_.rain_factor = ru::rain_factor(p, rain);
  } else {
    warn_once("dp:" + name, "datapack '" + name + "' is not one it reads (" + neighbours_dp_ +
                                ", " + d_.lights_key + ", " + weather_dp_ + ", " + command_dp_ +
                                "); ignored");
  }
}

CONVOY_REGISTER_ENGINE("pedestrian_agent", PedestrianAgent);

}  // namespace convoy::engines::pedestrian_agent
