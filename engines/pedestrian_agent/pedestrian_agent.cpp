// EngineType "pedestrian_agent": one pedestrian as its own engine, on an OpenDRIVE lane graph.
//
// It walks the centre of sidewalk lanes along a route (sidewalks in either direction) and
// crosses a road at a crosswalk or, with probability MidBlockProbability, mid-block (the same
// road, MidBlockDistance from the crosswalk, away from the junction). A crossing is a straight
// line from one sidewalk's centre to the other's; the part of it off the sidewalks is "on the
// road".
//
// Before stepping onto the road it waits at the curb until
//   - the light lets it (ObeyLights): at a crosswalk with pedestrian lights (type 1000002 on the
//     crossed road within 12 m of it), while they are green; without them, while every vehicle
//     light (1000001) of the crossed road within 12 m is red (so it crosses when the traffic it
//     crosses is held); no such signal, or a state the datapack does not give: unsignalised;
//   - and every approaching vehicle's time-to-arrival at its crossing line (the vehicle's front
//     along its heading, at its speed) is at least its critical gap.
// While crossing it stops before the next vehicle's lane when a moving vehicle's front is
// within StopDistance of the crossing (or would arrive before it has crossed that lane), and
// steps back out of the lane it is in when one is within StepBackDistance (or would arrive
// before it could clear the lane forwards, and backing out is shorter). Speed (N(Speed, SpeedSd))
// and critical gap (N(CriticalGap, CriticalGapSd)) differ per pedestrian, drawn from Seed, as are
// the mid-block choice and a route when none is given. Deterministic: no wall clock, no other
// randomness.
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
// Its path (poses and arcs), the command contract, and the crossing's threats, gap acceptance,
// lights and caution on the road are in src/road_users; this engine plans its walks on the
// sidewalk graph and turns its datapacks into their inputs.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
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
#include "road_users/path.h"
#include "road_users/pedestrian_command.h"
#include "road_users/walker.h"

namespace convoy::engines::pedestrian_agent {
namespace odr = convoy::opendrive;
using nlohmann::json;

namespace {

constexpr double kSampleDs = 0.25;    // m between the path's poses
constexpr double kCurbWait = 0.3;     // m before the road's edge where it waits
constexpr double kSignalNear = 12.0;  // m along the road: a signal belongs to a crosswalk
constexpr double kKeepRight = 0.55;   // m right of its path's centre line: walkers pass
constexpr double kFollowGap = 1.0;    // m: closer than this behind a walker, it keeps its pace

struct Crossing {
  std::string road_id, crosswalk;  // crosswalk id, empty mid-block
  double start = 0, end = 0;       // arcs of the leg (sidewalk centre to sidewalk centre)
  double enter = 0, exit = 0;      // arcs where it is on the road
  std::vector<std::string> ped_signals, veh_signals;
};

// Its path: the library's poses and arcs, with the roads it crosses on it.
using RoadCrossings = std::vector<Crossing>;  // (inside Path, Crossing is the junction's)

struct Path : road_users::Path {
  RoadCrossings road_crossings;
};

// A point on a sidewalk lane.
struct Spot {
  odr::LaneIndex lane = odr::kNoLane;
  double s = 0;
};

// One crossing of a road at s, from the sidewalk `from` to the sidewalk `to`.
struct CrossPlan {
  std::string road_id, crosswalk;
  Spot from, to;
};

struct Plan {
  std::optional<odr::LaneRoute> before, after;  // walks; `after` only with a crossing
  std::optional<CrossPlan> cross;
  double length = INFINITY;
};

using road_users::Points;
using Command = road_users::PedestrianCommand;

}  // namespace

class PedestrianAgent final : public Engine {
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
    throw std::runtime_error("pedestrian_agent '" + name_ + "': " + key + ": " + what);
  }
  void warn_once(const std::string& key, const std::string& text) {
    if (warned_[key]) return;
    warned_[key] = true;
    std::fprintf(stderr, "warning: pedestrian_agent '%s': %s\n", name_.c_str(), text.c_str());
    warnings_.push_back(text);
  }
  Spot sidewalk(const std::string& key, const json& v, const json* s_value, bool at_entry) const;
  std::optional<odr::LaneRoute> walk(Spot a, Spot b) const;
  Plan plan(Spot from, Spot to, const odr::Crosswalk* only) const;
  std::optional<CrossPlan> mid_block(const CrossPlan& c, double factor) const;
  Plan pick_plan(const json& config, std::mt19937_64& rng, bool mid_block_drawn, double factor);
  Path make_path(const Plan& p) const;
  void start();
  void publish();
  bool lights_allow(const Crossing& c);
  std::vector<road_users::CrossingThreat> threats(const Crossing& c) const;
  double walker_ahead_speed(double v) const;
  std::optional<odr::LanePosition> nearest_sidewalk(double x, double y) const;
  // A straight leg from a to b; the part of it off the sidewalks is a crossing (with gap
  // acceptance), `committed` when it starts on the road already.
  void append_leg(Path& path, double ax, double ay, double bx, double by) const;
  // From (x, y): to the nearest sidewalk, then to its destination over sidewalks and
  // crosswalks, or along the sidewalks onward in the direction `yaw`; false without a
  // sidewalk near (the path is then where it stands).
  bool path_from(Path& path, double x, double y, double yaw, double* join = nullptr);
  void replan(const Points& via);  // from where it stands, through `via`, then as path_from
  void set_polyline(const Points& points);

  std::string name_;
  std::unique_ptr<odr::Network> net_;
  std::unique_ptr<odr::LaneGraph> graph_;
  double speed_ = 1.35, gap_ = 4.0, stop_distance_ = 8, step_back_distance_ = 4;
  double length_ = 0.5, width_ = 0.6, height_ = 1.75, stride_ = 1.4, radius_ = 100;
  bool obey_lights_ = true;
  std::string model_, state_dp_, neighbours_dp_, lights_dp_, weather_dp_, command_dp_;
  Path initial_path_;
  std::optional<Spot> dest_;  // where its route ends (none: onward)
  std::optional<odr::Pose2> start_pose_;
  bool initial_idle_ = false;
  std::mt19937_64 rng_, initial_rng_;  // onward choices

  // State.
  int64_t time_ns_ = 0;
  Path path_;
  double arc_ = 0, v_ = 0, acc_ = 0, walked_ = 0;
  double x_ = 0, y_ = 0, yaw_ = 0, yaw_rate_ = 0;
  size_t committed_ = SIZE_MAX;  // index of the crossing it has stepped onto / may step onto
  bool absent_ = false;
  bool respawn_ = false;
  double respawn_delay_s_ = 2.0;
  int64_t absent_since_ns_ = 0;
  std::shared_ptr<const data::RoadUsers> neighbours_;
  std::shared_ptr<const json> lights_;
  double rain_factor_ = 1.0;
  data::RoadUser state_;
  std::map<std::string, bool> warned_;
  std::vector<std::string> warnings_;
  // Commands.
  double kr_ = kKeepRight;  // how far right of the path it walks (0 at a new path's start)
  double kr_from_ = 0;      // the arc from which it eases over to kKeepRight (on the sidewalk)
  double initial_kr_from_ = 0;
  bool idle_ = false;          // no sidewalk near: it stands until commanded
  bool stand_at_end_ = false;  // its path does not reach a sidewalk: it stands at its end
  std::optional<Command> command_;
  Points last_route_, polyline_;
  Path traj_path_;
  bool off_path_ = false;  // a command moved it off path_: re-plan when the AI takes over
};

Spot PedestrianAgent::sidewalk(const std::string& key, const json& v, const json* s_value,
                               bool at_entry) const {
  if (!v.is_string()) fail(key, "expected \"ROAD:LANE\"");
  const std::string text = v.get<std::string>();
  const auto colon = text.rfind(':');
  std::string road;
  int lane = 0;
  try {
    if (colon == std::string::npos || colon == 0) throw std::invalid_argument("no colon");
    size_t used = 0;
    lane = std::stoi(text.substr(colon + 1), &used);
    if (used != text.size() - colon - 1 || lane == 0) throw std::invalid_argument("lane");
    road = text.substr(0, colon);
  } catch (const std::exception&) {
    fail(key, "expected \"ROAD:LANE\" with a non-zero lane id, got \"" + text + "\"");
  }
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

std::optional<odr::LaneRoute> PedestrianAgent::walk(Spot a, Spot b) const {
  odr::RouteOptions o;
  o.lane_types = {"sidewalk"};
  o.both_directions = true;
  o.lane_changes = false;
  return graph_->route(a.lane, a.s, b.lane, b.s, o);
}

Plan PedestrianAgent::plan(Spot from, Spot to, const odr::Crosswalk* only) const {
  Plan best;
  if (!only) {
    if (auto w = walk(from, to)) {
      best.before = w;
      best.length = w->length;
    }
  }
  for (const auto& cw : graph_->crosswalks()) {
    if (only && &cw != only) continue;
    if (cw.ends[0] == odr::kNoLane || cw.ends[1] == odr::kNoLane) continue;
    for (int d = 0; d < 2; ++d) {
      const Spot a{cw.ends[d], cw.s}, b{cw.ends[1 - d], cw.s};
      auto w1 = walk(from, a);
      if (!w1) continue;
      auto w2 = walk(b, to);
      if (!w2) continue;
      const odr::WorldPose pa = graph_->world_pose(cw.road_id, graph_->lane(a.lane).lane_id, a.s);
      const odr::WorldPose pb = graph_->world_pose(cw.road_id, graph_->lane(b.lane).lane_id, b.s);
      const double len = w1->length + w2->length + std::hypot(pb.x - pa.x, pb.y - pa.y);
      if (len < best.length - 1e-9) {
        best.before = w1;
        best.after = w2;
        best.cross = CrossPlan{cw.road_id, cw.id, a, b};
        best.length = len;
      }
    }
  }
  return best;
}

std::optional<CrossPlan> PedestrianAgent::mid_block(const CrossPlan& c, double factor) const {
  const odr::Road* r = net_->find_road(c.road_id);
  if (!r) return std::nullopt;
  const double dir = c.from.s < 0.5 * r->length ? 1.0 : -1.0;  // away from the near end
  const double s = std::clamp(c.from.s + dir * factor, 2.0, r->length - 2.0);
  const odr::LaneIndex a = graph_->find(c.road_id, graph_->lane(c.from.lane).lane_id, s);
  const odr::LaneIndex b = graph_->find(c.road_id, graph_->lane(c.to.lane).lane_id, s);
  if (a == odr::kNoLane || b == odr::kNoLane) return std::nullopt;
  if (graph_->lane(a).type != "sidewalk" || graph_->lane(b).type != "sidewalk") return std::nullopt;
  return CrossPlan{c.road_id, "", {a, s}, {b, s}};
}

Plan PedestrianAgent::pick_plan(const json& config, std::mt19937_64& rng, bool mid_block_drawn,
                                double factor) {
  const json& r = config.at("Route");
  const json& pos = config.at("Position");
  if (!r.is_object()) fail("Route", "expected an object");
  if (!pos.is_object()) fail("Position", "expected {\"x\": ..., \"y\": ...}");
  for (const auto& [k, v] : r.items()) {
    if (k != "from" && k != "to" && k != "from_s" && k != "to_s" && k != "crosswalk" &&
        k != "reverse")
      fail("Route", "unknown key \"" + k + "\" (from, to, from_s, to_s, crosswalk, reverse)");
  }
  Plan p;
  const odr::Crosswalk* only = nullptr;
  Spot from, to;
  std::string what;
  if (r.contains("crosswalk")) {
    if (r.contains("from") || r.contains("to") || !pos.empty())
      fail("Route.crosswalk", "give a crosswalk, or from / to, not both");
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
      (k == 0 ? from : to) = Spot{li == odr::kNoLane ? end : li, li == odr::kNoLane ? only->s : s};
    }
    what = "across crosswalk " + id;
  } else if (!pos.empty()) {
    if (!pos.contains("x") || !pos.contains("y") || !pos["x"].is_number() || !pos["y"].is_number())
      fail("Position", "expected numbers \"x\" and \"y\"");
    const double x = pos["x"].get<double>(), y = pos["y"].get<double>();
    char where[96];
    std::snprintf(where, sizeof where, "(%.2f, %.2f)", x, y);
    const auto loc = graph_->locate(x, y, std::nullopt, 50.0);
    if (!loc || loc->distance > 0 || graph_->lane(loc->lane).type != "sidewalk") {
      std::string near = "no road within 50 m";
      if (loc) {
        char d[160];
        std::snprintf(d, sizeof d, "nearest lane %s:%d (%s) %.2f m away", loc->road_id.c_str(),
                      loc->lane_id, graph_->lane(loc->lane).type.c_str(), loc->distance);
        near = d;
      }
      fail("Position", std::string("placed off the sidewalks: ") + where +
                           " is not on a sidewalk of " + net_->source + " (" + near + ")");
    }
    if (r.contains("from")) fail("Route.from", "give Route.from or Position, not both");
    if (!r.contains("to")) fail("Route.to", "needed with Position (where to walk)");
    from = {loc->lane, loc->s};
    to = sidewalk("Route.to", r["to"], r.contains("to_s") ? &r["to_s"] : nullptr, false);
    what = std::string("from ") + where + " to " + r["to"].get<std::string>();
  } else if (r.contains("from") || r.contains("to")) {
    if (!r.contains("from") || !r.contains("to")) fail("Route", "give both \"from\" and \"to\"");
    from = sidewalk("Route.from", r["from"], r.contains("from_s") ? &r["from_s"] : nullptr, true);
    to = sidewalk("Route.to", r["to"], r.contains("to_s") ? &r["to_s"] : nullptr, false);
    what = "from " + r["from"].get<std::string>() + " to " + r["to"].get<std::string>();
  } else {
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
      Plan q = plan({a.index, sa}, {b.index, sb}, nullptr);
      if (!q.before || q.length < 30 || (attempt < 100 && !q.cross)) continue;
      p = std::move(q);
      break;
    }
    if (!p.before)
      fail("Route", "none given, and no route could be drawn from its Seed on " + net_->source);
    what = "drawn from Seed";
  }
  if (!p.before) p = plan(from, to, only);
  if (!p.before)
    fail("Route", "no route " + what + " over the sidewalks and crosswalks of " + net_->source);
  if (mid_block_drawn && p.cross && !p.cross->crosswalk.empty()) {
    if (auto m = mid_block(*p.cross, factor)) {
      // Re-route the walks to and from the mid-block crossing.
      auto w1 = walk(from.lane == odr::kNoLane
                         ? Spot{p.before->segments.front().lane, p.before->segments.front().s_from}
                         : from,
                     m->from);
      const auto& last = p.after->segments.back();
      auto w2 = walk(m->to, Spot{last.lane, last.s_to});
      if (w1 && w2) {
        p.before = w1;
        p.after = w2;
        p.cross = m;
      }
    }
  }
  return p;
}

Path PedestrianAgent::make_path(const Plan& p) const {
  Path path;
  if (p.before && !p.before->segments.empty()) path.append(graph_->sample(*p.before, kSampleDs));
  if (p.cross) {
    const CrossPlan& c = *p.cross;
    const odr::WorldPose a =
        graph_->world_pose(c.road_id, graph_->lane(c.from.lane).lane_id, c.from.s);
    const odr::WorldPose b = graph_->world_pose(c.road_id, graph_->lane(c.to.lane).lane_id, c.to.s);
    if (path.poses.empty()) path.append({odr::Pose2{a.x, a.y, 0}});
    Crossing cr;
    cr.road_id = c.road_id;
    cr.crosswalk = c.crosswalk;
    // From where the walk ended (near a) straight to b, via a.
    const double heading = std::atan2(b.y - a.y, b.x - a.x);
    path.poses.back().heading = heading;
    std::vector<odr::Pose2> line;
    line.push_back(odr::Pose2{a.x, a.y, heading});
    const double len = std::hypot(b.x - a.x, b.y - a.y);
    const int n = std::max(1, static_cast<int>(std::ceil(len / kSampleDs)));
    for (int i = 1; i <= n; ++i) {
      const double f = static_cast<double>(i) / n;
      line.push_back(odr::Pose2{a.x + f * (b.x - a.x), a.y + f * (b.y - a.y), heading});
    }
    const size_t first = path.poses.size();
    path.append(line);
    const size_t i0 = first > 0 ? first - 1 : 0;
    cr.start = path.arc[i0];
    cr.end = path.arc.back();
    // On the road: the part of the line outside sidewalks.
    cr.enter = cr.end;
    cr.exit = cr.start;
    for (size_t i = i0; i < path.poses.size(); ++i) {
      const auto loc = graph_->locate(path.poses[i].x, path.poses[i].y, std::nullopt, 2.0);
      if (loc && loc->distance <= 0 && graph_->lane(loc->lane).type == "sidewalk") continue;
      cr.enter = std::min(cr.enter, path.arc[i] - 0.5 * kSampleDs);
      cr.exit = std::max(cr.exit, path.arc[i] + 0.5 * kSampleDs);
    }
    if (cr.exit < cr.enter) cr.enter = cr.exit = cr.start;  // nothing to cross
    if (!c.crosswalk.empty()) {
      for (const auto& sig : graph_->signals()) {
        if (!sig.signal || sig.road_id != c.road_id) continue;
        if (std::abs(sig.signal->s - c.from.s) > kSignalNear) continue;
        if (sig.pedestrian_light) cr.ped_signals.push_back(sig.signal->id);
        if (sig.traffic_light) cr.veh_signals.push_back(sig.signal->id);
      }
    }
    path.road_crossings.push_back(cr);
    if (p.after && !p.after->segments.empty()) path.append(graph_->sample(*p.after, kSampleDs));
  }
  return path;
}

std::vector<engine::DataPackId> PedestrianAgent::initialize(const std::string& name,
                                                            const json& config,
                                                            int64_t /*timestep_ns*/) {
  name_ = name;
  if (!config.contains("Map") || !config["Map"].is_string())
    fail("Map", "no map given (an OpenDRIVE .xodr file)");
  try {
    net_ = std::make_unique<odr::Network>(odr::load(config["Map"].get<std::string>()));
    graph_ = std::make_unique<odr::LaneGraph>(*net_);
  } catch (const std::exception& e) {
    fail("Map", e.what());
  }
  const uint64_t seed = config.at("Seed").get<uint64_t>();
  std::mt19937_64 rng(seed * 0x9E3779B97F4A7C15ull + 0x5EED);
  // Draws in a fixed order: speed, gap, mid-block choice and distance, then the route.
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double z_speed = std::clamp(normal(rng), -2.0, 2.0);
  const double z_gap = std::clamp(normal(rng), -2.0, 2.0);
  const double u_mid = unit(rng);
  const double u_dist = unit(rng);
  speed_ = std::max(
      0.3, config.at("Speed").get<double>() + z_speed * config.at("SpeedSd").get<double>());
  respawn_ = config.at("Respawn").get<bool>();
  respawn_delay_s_ = config.at("RespawnDelay").get<double>();
  gap_ = std::max(0.0, config.at("CriticalGap").get<double>() +
                           z_gap * config.at("CriticalGapSd").get<double>());
  const double p_mid = config.at("MidBlockProbability").get<double>();
  const double mid_dist = config.at("MidBlockDistance").get<double>() * (0.6 + 0.8 * u_dist);
  obey_lights_ = config.at("ObeyLights").get<bool>();
  stop_distance_ = config.at("StopDistance").get<double>();
  step_back_distance_ = config.at("StepBackDistance").get<double>();
  model_ = config.at("Model").get<std::string>();
  length_ = config.at("Length").get<double>();
  width_ = config.at("Width").get<double>();
  height_ = config.at("Height").get<double>();
  stride_ = config.at("StrideLength").get<double>();
  radius_ = config.at("NeighbourRadius").get<double>();
  state_dp_ = config.at("StateDataPack").get<std::string>();
  neighbours_dp_ = config.at("NeighboursDataPack").get<std::string>();
  lights_dp_ = config.at("TrafficLightsDataPack").get<std::string>();
  weather_dp_ = config.at("WeatherDataPack").get<std::string>();

  command_dp_ = config.at("CommandDataPack").get<std::string>();
  rng_.seed(seed * 0x9E3779B97F4A7C15ull + 0x0A7Eull);

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
      if (k != "to" && k != "to_s")
        fail("Route." + k,
             "give StartPose or Route." + k + ", not both (Route: {\"to\"[, \"to_s\"]})");
    }
    if (config.at("Position").is_object() && !config.at("Position").empty())
      fail("StartPose", "give Position or StartPose, not both");
    odr::Pose2 pose;
    pose.x = sp["x"].get<double>();
    pose.y = sp["y"].get<double>();
    pose.heading = sp["yaw"].get<double>();
    start_pose_ = pose;
    if (r.contains("to"))
      dest_ = sidewalk("Route.to", r["to"], r.contains("to_s") ? &r["to_s"] : nullptr, false);
    initial_path_ = Path{};
    initial_path_.append({pose});
    initial_kr_from_ = INFINITY;
    if (!path_from(initial_path_, pose.x, pose.y, pose.heading, &initial_kr_from_)) {
      char where[96];
      std::snprintf(where, sizeof where, "(%.2f, %.2f)", pose.x, pose.y);
      warn_once("idle", std::string("no sidewalk within 50 m of its StartPose ") + where +
                            ": it stands there until commanded");
    }
    initial_idle_ = initial_path_.length() < 1e-6;
  } else {
    const Plan p = pick_plan(config, rng, u_mid < p_mid, mid_dist);
    initial_path_ = make_path(p);
    if (initial_path_.poses.size() < 2 || initial_path_.length() < 0.5)
      fail("Route", "the route is empty (its start and end are the same point)");
    const odr::LaneRoute& last = p.after && !p.after->segments.empty() ? *p.after : *p.before;
    if (!last.segments.empty()) dest_ = Spot{last.segments.back().lane, last.segments.back().s_to};
  }
  initial_rng_ = rng_;
  start();

  std::vector<engine::DataPackId> ids(1);
  ids[0].set_name(state_dp_);
  ids[0].set_type(std::string(datapack::type_name<data::RoadUser>()));
  ids[0].set_engine_name(name);
  return ids;
}

void PedestrianAgent::start() {
  path_ = initial_path_;
  idle_ = initial_idle_;
  rng_ = initial_rng_;
  kr_ = start_pose_ ? 0.0 : kKeepRight;
  kr_from_ = initial_kr_from_;
  stand_at_end_ = false;
  command_.reset();
  last_route_.clear();
  polyline_.clear();
  off_path_ = false;
  time_ns_ = 0;
  arc_ = 0;
  v_ = acc_ = walked_ = yaw_rate_ = 0;
  const odr::Pose2 p = path_.at(0);
  x_ = p.x + kr_ * std::sin(p.heading);
  y_ = p.y - kr_ * std::cos(p.heading);
  yaw_ = start_pose_ ? start_pose_->heading : p.heading;
  committed_ = SIZE_MAX;
  absent_ = false;
  neighbours_.reset();
  lights_.reset();
  rain_factor_ = 1.0;
  state_.Clear();
  state_.set_id(name_);
  state_.set_category("pedestrian");
  state_.set_model(model_);
  state_.set_length(length_);
  state_.set_width(width_);
  state_.set_height(height_);
  publish();
}

bool PedestrianAgent::lights_allow(const Crossing& c) {
  if (!obey_lights_ || (c.ped_signals.empty() && c.veh_signals.empty())) return true;
  if (!lights_) {
    warn_once("no-lights", "no '" + lights_dp_ + "' datapack yet: crosswalk " + c.crosswalk +
                               " treated as unsignalised");
    return true;
  }
  const json& sig = lights_->contains("signals") ? (*lights_)["signals"] : *lights_;
  auto state = [&](const std::string& id) -> std::string {
    auto it = sig.find(id);
    return it != sig.end() && it->is_string() ? it->get<std::string>() : std::string();
  };
  std::vector<std::string> ped, veh;
  for (const auto& id : c.ped_signals) ped.push_back(state(id));
  for (const auto& id : c.veh_signals) veh.push_back(state(id));
  return road_users::walker_lights_allow(ped, veh);
}

// The pace it may walk at with other walkers ahead: one in its way (within its body's width
// of its line, going its way or standing) closer than kFollowGap is not overtaken.
double PedestrianAgent::walker_ahead_speed(double v) const {
  if (!neighbours_) return v;
  const double c = std::cos(yaw_), s = std::sin(yaw_);
  for (const auto& u : neighbours_->users()) {
    if (u.absent() || u.id() == name_ || u.category() != "pedestrian") continue;
    const double dx = u.x() - x_, dy = u.y() - y_;
    const double lon = dx * c + dy * s, lat = -dx * s + dy * c;
    if (lon <= 0 || lon > kFollowGap + 0.5 || std::abs(lat) > 0.6) continue;
    const double along = u.speed() * std::cos(u.yaw() - yaw_);
    if (along < -0.1) continue;  // coming towards it: they pass each other on the right
    v = std::min(v, lon < kFollowGap ? std::max(0.0, along) : v);
  }
  return v;
}

std::vector<road_users::CrossingThreat> PedestrianAgent::threats(const Crossing& c) const {
  std::vector<road_users::CrossingThreat> out;
  if (!neighbours_) return out;
  const odr::Pose2 a = path_.at(c.start), b = path_.at(c.end);
  const double ex = b.x - a.x, ey = b.y - a.y;
  const double len = std::hypot(ex, ey);
  if (len < 1e-6) return out;
  const road_users::CrossingLeg leg{a.x, a.y, ex / len, ey / len, len};
  for (const auto& u : neighbours_->users()) {
    if (u.absent() || u.id() == name_ || u.category() == "pedestrian") continue;
    if (std::hypot(u.x() - x_, u.y() - y_) > radius_) continue;
    const road_users::CrossingVehicle v{u.x(),      u.y(),     u.yaw(),          u.speed(),
                                        u.length(), u.width(), u.length_offset()};
    if (const auto t = road_users::crossing_threat(leg, v)) out.push_back(*t);
  }
  return out;
}

std::optional<odr::LanePosition> PedestrianAgent::nearest_sidewalk(double x, double y) const {
  return graph_->locate_if(x, y, std::nullopt, 50.0,
                           [](const odr::LaneNode& n, double) { return n.type == "sidewalk"; });
}

void PedestrianAgent::append_leg(Path& path, double ax, double ay, double bx, double by) const {
  const double len = std::hypot(bx - ax, by - ay);
  if (len < 1e-6) return;
  const double heading = std::atan2(by - ay, bx - ax);
  if (!path.poses.empty()) path.poses.back().heading = heading;
  std::vector<odr::Pose2> line;
  line.push_back(odr::Pose2{ax, ay, heading});
  const int n = std::max(1, static_cast<int>(std::ceil(len / kSampleDs)));
  for (int i = 1; i <= n; ++i) {
    const double f = static_cast<double>(i) / n;
    line.push_back(odr::Pose2{ax + f * (bx - ax), ay + f * (by - ay), heading});
  }
  const size_t first = path.poses.size();
  path.append(line);
  const size_t i0 = first > 0 ? first - 1 : 0;
  Crossing cr;
  cr.start = path.arc[i0];
  cr.end = path.arc.back();
  cr.enter = cr.end;
  cr.exit = cr.start;
  for (size_t i = i0; i < path.poses.size(); ++i) {
    const auto loc = graph_->locate(path.poses[i].x, path.poses[i].y, std::nullopt, 2.0);
    if (loc && loc->distance <= 0 && graph_->lane(loc->lane).type == "sidewalk") continue;
    cr.enter = std::min(cr.enter, path.arc[i] - 0.5 * kSampleDs);
    cr.exit = std::max(cr.exit, path.arc[i] + 0.5 * kSampleDs);
  }
  if (cr.exit > cr.enter) {
    cr.enter = std::max(cr.enter, cr.start);
    cr.exit = std::min(cr.exit, cr.end);
    path.road_crossings.push_back(cr);
  }
}

bool PedestrianAgent::path_from(Path& path, double x, double y, double yaw, double* join) {
  const auto loc = nearest_sidewalk(x, y);
  if (!loc) return false;
  const odr::WorldPose w = graph_->world_pose(loc->road_id, loc->lane_id, loc->s);
  append_leg(path, x, y, w.x, w.y);
  if (join) *join = (path.arc.empty() ? 0.0 : path.arc.back()) + 0.5;  // past the corner
  const Spot from{loc->lane, loc->s};
  if (dest_) {
    const Plan p = plan(from, *dest_, nullptr);
    if (p.before) {
      const Path rest = make_path(p);
      if (rest.poses.empty()) return true;
      const double base = path.arc.empty() ? 0.0 : path.arc.back();
      const double gap = path.poses.empty() ? 0.0
                                            : std::hypot(rest.poses[0].x - path.poses.back().x,
                                                         rest.poses[0].y - path.poses.back().y);
      const double offset = base + (gap < 1e-6 ? 0.0 : gap);
      path.append(rest.poses);
      for (Crossing c : rest.road_crossings) {
        c.start += offset;
        c.end += offset;
        c.enter += offset;
        c.exit += offset;
        path.road_crossings.push_back(c);
      }
      return true;
    }
  }
  // Along the sidewalks onward, the way it faces; at each fork a choice drawn from Seed.
  const odr::LaneNode& n0 = graph_->lane(loc->lane);
  const double h_s = w.heading + (n0.forward ? 0.0 : M_PI);  // the lane's +s direction
  bool with_s = std::abs(std::remainder(yaw - h_s, 2 * M_PI)) <= M_PI / 2;
  odr::LaneRoute route;
  odr::LaneIndex cur = loc->lane;
  double cs = loc->s, length = 0;
  for (int guard = 0; guard < 10000 && length < 1000.0; ++guard) {
    const odr::LaneNode& n = graph_->lane(cur);
    odr::RouteSegment seg;
    seg.lane = cur;
    seg.road_id = n.road->id;
    seg.lane_id = n.lane_id;
    seg.junction = n.junction;
    seg.s_from = std::clamp(cs, n.s0, n.s1);
    seg.s_to = with_s ? n.s1 : n.s0;
    if (n.s1 > n.s0) length += std::abs(seg.s_to - seg.s_from) / (n.s1 - n.s0) * n.length;
    route.segments.push_back(seg);
    std::vector<odr::LaneEndRef> next;
    for (const odr::LaneEndRef& r : with_s ? n.at_end : n.at_start) {
      if (graph_->lane(r.lane).type == "sidewalk") next.push_back(r);
    }
    if (next.empty()) break;
    const odr::LaneEndRef r = next.size() == 1 ? next[0] : next[rng_() % next.size()];
    cur = r.lane;
    with_s = r.end == odr::LaneEnd::kStart;
    cs = with_s ? graph_->lane(cur).s0 : graph_->lane(cur).s1;
  }
  route.length = length;
  path.append(graph_->sample(route, kSampleDs));
  return true;
}

void PedestrianAgent::replan(const Points& via) {
  Path path;
  path.append({odr::Pose2{x_, y_, yaw_}});
  for (const auto& [px, py] : via)
    append_leg(path, path.poses.back().x, path.poses.back().y, px, py);
  const double yaw = path.poses.size() > 1 ? path.poses.back().heading : yaw_;
  kr_from_ = INFINITY;
  stand_at_end_ = !path_from(path, path.poses.back().x, path.poses.back().y, yaw, &kr_from_);
  if (stand_at_end_ && via.empty()) {
    char where[96];
    std::snprintf(where, sizeof where, "(%.2f, %.2f)", x_, y_);
    warn_once("idle", std::string("no sidewalk within 50 m of ") + where +
                          ": it stands there until commanded");
  }
  path_ = std::move(path);
  idle_ = path_.length() < 1e-6;
  arc_ = 0;
  kr_ = 0;
  // Already on the road where the path starts: it is crossing, it does not wait.
  committed_ = SIZE_MAX;
  for (size_t i = 0; i < path_.road_crossings.size(); ++i) {
    if (path_.road_crossings[i].enter - kCurbWait <= 1e-9) committed_ = i;
    break;
  }
}

void PedestrianAgent::set_polyline(const Points& points) {
  if (points == polyline_) return;
  polyline_ = points;
  traj_path_ = Path{};
  std::vector<odr::Pose2> poses;
  for (size_t i = 0; i < points.size(); ++i) {
    const size_t j = i + 1 < points.size() ? i + 1 : i;
    const double h = j != i ? std::atan2(points[j][1] - points[i][1], points[j][0] - points[i][0])
                            : (poses.empty() ? yaw_ : poses.back().heading);
    if (i + 1 < points.size()) {
      const double len = std::hypot(points[j][0] - points[i][0], points[j][1] - points[i][1]);
      const int n = std::max(1, static_cast<int>(std::ceil(len / kSampleDs)));
      for (int k = 0; k < n; ++k) {
        const double f = static_cast<double>(k) / n;
        poses.push_back(odr::Pose2{points[i][0] + f * (points[j][0] - points[i][0]),
                                   points[i][1] + f * (points[j][1] - points[i][1]), h});
      }
    } else {
      poses.push_back(odr::Pose2{points[i][0], points[i][1], h});
    }
  }
  traj_path_.append(poses);
}

int64_t PedestrianAgent::step(int64_t duration_ns) {
  const double dt = duration_ns * 1e-9;
  time_ns_ += duration_ns;
  std::optional<Command> cmd;
  cmd.swap(command_);
  if (absent_ && !(cmd && (cmd->teleport || cmd->timed))) {
    // Respawn: at its start again, once RespawnDelay has passed and no walker is within 1 m.
    if (!respawn_ || time_ns_ - absent_since_ns_ < std::llround(respawn_delay_s_ * 1e9))
      return time_ns_;
    const odr::Pose2 p0 = initial_path_.at(0);
    const double kr0 = start_pose_ ? 0.0 : kKeepRight;
    const double sx = p0.x + kr0 * std::sin(p0.heading);
    const double sy = p0.y - kr0 * std::cos(p0.heading);
    if (neighbours_) {
      for (const auto& u : neighbours_->users()) {
        if (!u.absent() && u.id() != name_ && std::hypot(u.x() - sx, u.y() - sy) < 1.0)
          return time_ns_;
      }
    }
    path_ = initial_path_;
    idle_ = initial_idle_;
    kr_ = kr0;
    kr_from_ = initial_kr_from_;
    stand_at_end_ = false;
    arc_ = 0;
    v_ = acc_ = yaw_rate_ = 0;
    x_ = sx;
    y_ = sy;
    yaw_ = start_pose_ ? start_pose_->heading : p0.heading;
    committed_ = SIZE_MAX;
    absent_ = false;
    publish();
    return time_ns_;
  }
  absent_ = false;
  if (cmd && cmd->teleport) {
    // Put there once, then back to its routing from there.
    const Command::Pose& p = *cmd->teleport;
    x_ = p.x;
    y_ = p.y;
    yaw_ = std::remainder(p.yaw, 2 * M_PI);
    if (p.speed) v_ = *p.speed;
    acc_ = yaw_rate_ = 0;
    off_path_ = false;
    polyline_.clear();
    replan({});
    publish();
    return time_ns_;
  }
  if (cmd && cmd->timed) {
    const Command::Pose& p = *cmd->timed;
    const double v = p.speed.value_or(0.0);
    const double yaw = std::remainder(p.yaw, 2 * M_PI);
    walked_ += std::hypot(p.x - x_, p.y - y_);
    yaw_rate_ = std::remainder(yaw - yaw_, 2 * M_PI) / dt;
    acc_ = (v - v_) / dt;
    x_ = p.x;
    y_ = p.y;
    yaw_ = yaw;
    v_ = v;
    off_path_ = true;
    publish();
    return time_ns_;
  }
  if (cmd && cmd->route && *cmd->route != last_route_) {
    last_route_ = *cmd->route;
    if (!cmd->polyline) off_path_ = false;
    replan(*cmd->route);
  }
  const bool on_poly = cmd && cmd->polyline;
  if (on_poly) {
    set_polyline(*cmd->polyline);
    off_path_ = true;
  } else if (off_path_) {
    off_path_ = false;
    polyline_.clear();
    replan({});
  }
  const double v_des = cmd && cmd->speed ? *cmd->speed : speed_ * rain_factor_;
  if (on_poly) {
    // Towards a point 0.5 m ahead on the polyline (its end at the last), at its speed.
    const Path& t = traj_path_;
    size_t best = 0;
    double d2 = INFINITY;
    for (size_t i = 0; i < t.poses.size(); ++i) {
      const double dx = t.poses[i].x - x_, dy = t.poses[i].y - y_;
      if (dx * dx + dy * dy < d2) {
        d2 = dx * dx + dy * dy;
        best = i;
      }
    }
    const odr::Pose2& end = t.poses.back();
    const double ahead = t.arc[best] + 0.5;
    const odr::Pose2 target = ahead >= t.length() ? end : t.at(ahead);
    const double dx = target.x - x_, dy = target.y - y_;
    const double dist = std::hypot(dx, dy);
    double v = cmd->speed ? v_des : walker_ahead_speed(v_des);
    double step = v * dt;
    if (ahead >= t.length()) step = std::min(step, dist);  // stops at its end
    if (dist > 1e-9 && step > 0) {
      const double yaw = std::atan2(dy, dx);
      x_ += step * dx / dist;
      y_ += step * dy / dist;
      yaw_rate_ = std::remainder(yaw - yaw_, 2 * M_PI) / dt;
      yaw_ = yaw;
    } else {
      step = 0;
      yaw_rate_ = 0;
    }
    walked_ += step;
    acc_ = (step / dt - v_) / dt;
    v_ = step / dt;
    publish();
    return time_ns_;
  }
  double limit = path_.length();  // the farthest arc it may be at
  // The next crossing not yet behind it.
  size_t ci = SIZE_MAX;
  for (size_t i = 0; i < path_.road_crossings.size(); ++i) {
    if (path_.road_crossings[i].exit > arc_ + 1e-9 &&
        path_.road_crossings[i].exit > path_.road_crossings[i].enter) {
      ci = i;
      break;
    }
  }
  if (ci != SIZE_MAX) {
    const Crossing& c = path_.road_crossings[ci];
    const double wait_at = c.enter - kCurbWait;
    if (committed_ != ci) {
      if (arc_ >= wait_at - 3.0) {
        bool ok = lights_allow(c);
        if (ok) ok = road_users::gap_accepted(threats(c), gap_);
        if (ok && arc_ >= wait_at - v_des * dt - 1e-6) committed_ = ci;
        if (!ok) limit = std::min(limit, wait_at);
      }
    }
    if (committed_ == ci) {
      limit = road_users::crossing_limit(threats(c), c.start, arc_, v_des,
                                         {stop_distance_, step_back_distance_}, limit);
    }
  }
  double v = 0;
  if (idle_) {
    v = 0;
  } else if (cmd && cmd->speed) {
    // Commanded: on along its path at that speed, whatever the traffic.
    v = std::min(v_des, (path_.length() - arc_) / dt);
    for (size_t i = 0; i < path_.road_crossings.size(); ++i) {
      const Crossing& c = path_.road_crossings[i];
      if (c.exit > c.enter && c.enter - kCurbWait <= arc_ + v * dt && c.exit > arc_) {
        committed_ = i;  // on it: the AI finishes the crossing
        break;
      }
    }
  } else if (limit < arc_ - 1e-9) {
    v = -std::min(v_des, (arc_ - limit) / dt);  // stepping back
  } else {
    v = std::min(v_des, (limit - arc_) / dt);
    v = std::min(v, walker_ahead_speed(v));
  }
  arc_ = std::max(0.0, arc_ + v * dt);
  walked_ += std::abs(v) * dt;
  acc_ = (v - v_) / dt;
  v_ = v;
  const odr::Pose2 p = path_.at(arc_);
  const double yaw_new = idle_ ? yaw_ : p.heading;
  yaw_rate_ = std::remainder(yaw_new - yaw_, 2 * M_PI) / dt;
  // Keeps right, so oncoming walkers pass (on a new path from where it stood, easing over).
  if (arc_ > kr_from_) kr_ = std::min(kKeepRight, kr_ + 0.25 * std::abs(v) * dt);
  x_ = p.x + kr_ * std::sin(p.heading);
  y_ = p.y - kr_ * std::cos(p.heading);
  yaw_ = yaw_new;
  if (!idle_ && stand_at_end_ && arc_ >= path_.length() - 1e-6) {
    idle_ = true;  // no sidewalk to go on to: it stands where its route ended
  } else if (!idle_ && arc_ >= path_.length() - 1e-6) {
    absent_ = true;
    absent_since_ns_ = time_ns_;
    if (respawn_) {  // absent, it waits at its start: its view is around there
      const odr::Pose2 p0 = initial_path_.at(0);
      x_ = p0.x + kKeepRight * std::sin(p0.heading);
      y_ = p0.y - kKeepRight * std::cos(p0.heading);
      yaw_ = p0.heading;
    }
    v_ = acc_ = yaw_rate_ = 0;
  }
  publish();
  return time_ns_;
}

void PedestrianAgent::publish() {
  state_.set_absent(absent_);
  state_.set_x(x_);
  state_.set_y(y_);
  state_.set_yaw(yaw_);
  state_.set_speed(v_);
  state_.set_acceleration(acc_);
  state_.set_yaw_rate(yaw_rate_);
  state_.set_vx(v_ * std::cos(yaw_));
  state_.set_vy(v_ * std::sin(yaw_));
  state_.set_walk_phase(std::fmod(walked_ / stride_, 1.0));
  const auto loc = graph_->locate(x_, y_);
  if (loc) {
    state_.set_road(loc->road_id);
    state_.set_lane(loc->lane_id);
    state_.set_s(loc->s);
    state_.set_t(loc->road_t);
    state_.set_z(graph_->world_pose(loc->road_id, loc->lane_id, loc->s, loc->t).z);
  }
  state_.set_time_ns(time_ns_);
}

void PedestrianAgent::set_datapack(const datapack::View& dp) {
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
    neighbours_ = std::move(users);
  } else if (name == lights_dp_) {
    if (!dp.is_json()) fail(name, "expected a JSON datapack {\"signals\": {id: state}}");
    auto j = std::make_shared<json>(datapack::read_json(dp));
    if (!j->is_object()) fail(name, "expected a JSON object {\"signals\": {id: state}}");
    lights_ = std::move(j);
  } else if (name == command_dp_) {
    if (!dp.is_json()) fail(name, "expected a JSON datapack of commands");
    const json j = datapack::read_json(dp);
    if (j.is_object() && j.empty()) {
      command_.reset();  // on its own AI
    } else {
      try {
        command_ = road_users::parse_pedestrian_command(j, name, *graph_);
      } catch (const road_users::CommandError& e) {
        fail(e.key(), e.detail());
      }
    }
  } else if (name == weather_dp_) {
    if (!dp.is_json()) fail(name, "expected the JSON weather datapack");
    const json w = datapack::read_json(dp);
    if (!w.is_object()) fail(name, "expected a JSON object");
    const double p = w.value("precipitation", 0.0);
    const bool rain = w.value("precipitation_type", std::string("none")) == "rain";
    rain_factor_ = rain && p > 0 ? 1.0 + 0.2 * std::clamp(p, 0.0, 1.0) : 1.0;
  } else {
    warn_once("dp:" + name, "datapack '" + name + "' is not one it reads (" + neighbours_dp_ +
                                ", " + lights_dp_ + ", " + weather_dp_ + ", " + command_dp_ +
                                "); ignored");
  }
}

void PedestrianAgent::get_datapack(const engine::DataPackId& id, datapack::Builder& out) {
  if (id.name() == state_dp_) datapack::write_proto(out, state_);
}

CONVOY_REGISTER_ENGINE("pedestrian_agent", PedestrianAgent);

}  // namespace convoy::engines::pedestrian_agent
