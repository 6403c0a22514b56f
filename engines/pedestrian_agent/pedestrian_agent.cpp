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
#include <algorithm>
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

struct Path {
  std::vector<odr::Pose2> poses;
  std::vector<double> arc;
  std::vector<Crossing> crossings;
  double length() const { return arc.empty() ? 0 : arc.back(); }
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
  void append(const std::vector<odr::Pose2>& more) {
    for (const auto& p : more) {
      if (!poses.empty()) {
        const double d = std::hypot(p.x - poses.back().x, p.y - poses.back().y);
        if (d < 1e-6) continue;
        arc.push_back(arc.back() + d);
      } else {
        arc.push_back(0);
      }
      poses.push_back(p);
    }
  }
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
  struct Threat {
    double tta = INFINITY;  // s until its front reaches the crossing line
    double front = 0;       // m from its front to the line, along its heading
    double u = 0;           // where it crosses the line, m from the leg's start
    double half_width = 0.9;
    double speed = 0;
  };
  std::vector<Threat> threats(const Crossing& c) const;
  double walker_ahead_speed(double v) const;

  std::string name_;
  std::unique_ptr<odr::Network> net_;
  std::unique_ptr<odr::LaneGraph> graph_;
  double speed_ = 1.35, gap_ = 4.0, stop_distance_ = 8, step_back_distance_ = 4;
  double length_ = 0.5, width_ = 0.6, height_ = 1.75, stride_ = 1.4, radius_ = 100;
  bool obey_lights_ = true;
  std::string model_, state_dp_, neighbours_dp_, lights_dp_, weather_dp_;
  Path initial_path_;

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
    path.crossings.push_back(cr);
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

  const Plan p = pick_plan(config, rng, u_mid < p_mid, mid_dist);
  initial_path_ = make_path(p);
  if (initial_path_.poses.size() < 2 || initial_path_.length() < 0.5)
    fail("Route", "the route is empty (its start and end are the same point)");
  start();

  std::vector<engine::DataPackId> ids(1);
  ids[0].set_name(state_dp_);
  ids[0].set_type(std::string(datapack::type_name<data::RoadUser>()));
  ids[0].set_engine_name(name);
  return ids;
}

void PedestrianAgent::start() {
  path_ = initial_path_;
  time_ns_ = 0;
  arc_ = 0;
  v_ = acc_ = walked_ = yaw_rate_ = 0;
  const odr::Pose2 p = path_.at(0);
  x_ = p.x + kKeepRight * std::sin(p.heading);
  y_ = p.y - kKeepRight * std::cos(p.heading);
  yaw_ = p.heading;
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
  bool known = false;
  if (!c.ped_signals.empty()) {
    for (const auto& id : c.ped_signals) {
      const std::string st = state(id);
      if (st.empty() || st == "off") continue;
      known = true;
      if (st != "green") return false;
    }
    if (known) return true;
  }
  for (const auto& id : c.veh_signals) {
    const std::string st = state(id);
    if (st.empty() || st == "off") continue;
    if (st != "red") return false;  // the traffic it crosses may move
  }
  return true;
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

std::vector<PedestrianAgent::Threat> PedestrianAgent::threats(const Crossing& c) const {
  std::vector<Threat> out;
  if (!neighbours_) return out;
  const odr::Pose2 a = path_.at(c.start), b = path_.at(c.end);
  const double ex = b.x - a.x, ey = b.y - a.y;
  const double len = std::hypot(ex, ey);
  if (len < 1e-6) return out;
  const double ux = ex / len, uy = ey / len;
  for (const auto& u : neighbours_->users()) {
    if (u.absent() || u.id() == name_ || u.category() == "pedestrian") continue;
    if (std::hypot(u.x() - x_, u.y() - y_) > radius_) continue;
    const double dx = std::cos(u.yaw()), dy = std::sin(u.yaw());
    const double denom = dx * uy - dy * ux;  // cross(dir, e)
    if (std::abs(denom) < 0.2) continue;     // moving along the crossing, not across it
    const double lo = u.length_offset() + 0.5 * u.length();
    const double fx = u.x() + lo * dx, fy = u.y() + lo * dy;  // its front
    const double wx = a.x - fx, wy = a.y - fy;
    const double tau = (wx * uy - wy * ux) / denom;    // along its heading to the line
    const double along = (wx * dy - wy * dx) / denom;  // where on the line (from a), m
    Threat t;
    t.half_width = 0.5 * (u.width() > 0 ? u.width() : 1.8);
    if (along < -t.half_width - 1.0 || along > len + t.half_width + 1.0) continue;
    if (tau < -std::max(u.length(), 1.0)) continue;  // its back has passed
    t.front = tau;
    t.u = along;
    t.speed = u.speed();
    t.tta = tau <= 0 ? 0.0 : (u.speed() > 0.05 ? tau / u.speed() : INFINITY);
    out.push_back(t);
  }
  return out;
}

int64_t PedestrianAgent::step(int64_t duration_ns) {
  const double dt = duration_ns * 1e-9;
  time_ns_ += duration_ns;
  if (absent_) {
    // Respawn: at its start again, once RespawnDelay has passed and no walker is within 1 m.
    if (!respawn_ || time_ns_ - absent_since_ns_ < std::llround(respawn_delay_s_ * 1e9))
      return time_ns_;
    const odr::Pose2 p0 = initial_path_.at(0);
    const double sx = p0.x + kKeepRight * std::sin(p0.heading);
    const double sy = p0.y - kKeepRight * std::cos(p0.heading);
    if (neighbours_) {
      for (const auto& u : neighbours_->users()) {
        if (!u.absent() && u.id() != name_ && std::hypot(u.x() - sx, u.y() - sy) < 1.0)
          return time_ns_;
      }
    }
    path_ = initial_path_;
    arc_ = 0;
    v_ = acc_ = yaw_rate_ = 0;
    x_ = sx;
    y_ = sy;
    yaw_ = p0.heading;
    committed_ = SIZE_MAX;
    absent_ = false;
    publish();
    return time_ns_;
  }
  const double v_des = speed_ * rain_factor_;
  double limit = path_.length();  // the farthest arc it may be at
  // The next crossing not yet behind it.
  size_t ci = SIZE_MAX;
  for (size_t i = 0; i < path_.crossings.size(); ++i) {
    if (path_.crossings[i].exit > arc_ + 1e-9 &&
        path_.crossings[i].exit > path_.crossings[i].enter) {
      ci = i;
      break;
    }
  }
  if (ci != SIZE_MAX) {
    const Crossing& c = path_.crossings[ci];
    const double wait_at = c.enter - kCurbWait;
    if (committed_ != ci) {
      if (arc_ >= wait_at - 3.0) {
        bool ok = lights_allow(c);
        if (ok) {
          for (const Threat& t : threats(c)) {
            if (t.tta < gap_) ok = false;
          }
        }
        if (ok && arc_ >= wait_at - v_des * dt - 1e-6) committed_ = ci;
        if (!ok) limit = std::min(limit, wait_at);
      }
    }
    if (committed_ == ci) {
      const double my_u = arc_ - c.start;
      for (const Threat& t : threats(c)) {
        const bool over = t.front <= 0;        // its body is over the crossing line
        if (!over && t.speed < 0.5) continue;  // standing before the line
        const double lo = t.u - t.half_width - 0.5, hi = t.u + t.half_width + 0.5;
        if (my_u > lo && my_u < hi) {
          // In its lane: back out when the vehicle is within StepBackDistance, or when it
          // would arrive before it could clear the lane forwards and backing out is shorter.
          const double t_fwd = (hi - my_u) / v_des, t_back = (my_u - lo) / v_des;
          if (!over && (t.front < step_back_distance_ || (t.tta < t_fwd + 0.5 && t_back < t_fwd)))
            limit = std::min(limit, c.start + lo - 0.2);
        } else if (my_u <= lo && lo - my_u < 1.5 &&
                   (over || t.front < stop_distance_ || t.tta < (hi - my_u) / v_des + 1.0)) {
          limit = std::min(limit, std::max(arc_, c.start + lo - 0.2));  // wait before it
        }
      }
    }
  }
  double v = 0;
  if (limit < arc_ - 1e-9) {
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
  const double yaw_new = p.heading;
  yaw_rate_ = std::remainder(yaw_new - yaw_, 2 * M_PI) / dt;
  x_ = p.x + kKeepRight * std::sin(p.heading);  // keeps right, so oncoming walkers pass
  y_ = p.y - kKeepRight * std::cos(p.heading);
  yaw_ = yaw_new;
  if (arc_ >= path_.length() - 1e-6) {
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
  } else if (name == weather_dp_) {
    if (!dp.is_json()) fail(name, "expected the JSON weather datapack");
    const json w = datapack::read_json(dp);
    if (!w.is_object()) fail(name, "expected a JSON object");
    const double p = w.value("precipitation", 0.0);
    const bool rain = w.value("precipitation_type", std::string("none")) == "rain";
    rain_factor_ = rain && p > 0 ? 1.0 + 0.2 * std::clamp(p, 0.0, 1.0) : 1.0;
  } else {
    warn_once("dp:" + name, "datapack '" + name + "' is not one it reads (" + neighbours_dp_ +
                                ", " + lights_dp_ + ", " + weather_dp_ + "); ignored");
  }
}

void PedestrianAgent::get_datapack(const engine::DataPackId& id, datapack::Builder& out) {
  if (id.name() == state_dp_) datapack::write_proto(out, state_);
}

CONVOY_REGISTER_ENGINE("pedestrian_agent", PedestrianAgent);

}  // namespace convoy::engines::pedestrian_agent
