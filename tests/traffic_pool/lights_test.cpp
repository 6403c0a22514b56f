// Lights given from outside (Pool::set_light_states, the traffic_lights engine's states) on the
// city map (two lit junctions, a traffic light per approach, crosswalks next to them) and the
// SUMO grid: every lit approach lane finds its signals; all red, no pooled vehicle crosses a stop
// line while they queue; all green they pass; one approach always red, none leaves it while
// the others flow; walkers wait at the curb while the crossed road is green and cross on its red.
#include <gtest/gtest.h>

#include <set>

#include "grid_map.h"
#include "traffic_pool/pool.h"

namespace convoy::traffic_pool {
namespace {

using road_users::Light;
using road_users::LightStates;

// Every traffic light of the map in state `all`, those in `other` in state `to`.
LightStates states(const Map& m, Light all, const std::set<std::string>& other = {},
                   Light to = Light::kRed) {
  LightStates out;
  for (const opendrive::SignalInfo& s : m.graph.signals()) {
    if (s.traffic_light && s.signal) out[s.signal->id] = other.count(s.signal->id) ? to : all;
  }
  return out;
}

bool has_signal(const PoolLane& l, const std::string& id) {
  return std::find(l.signals.begin(), l.signals.end(), id) != l.signals.end();
}

// (SUMO's grid3.xodr is not used: its lights' validity names lane 1 on the roads' right, so
// they apply to no lane, for road_users::red_for as here.)
TEST(PoolLights, LitApproachesFindTheirSignals) {
  std::set<std::string> used;
  size_t lit = 0;
  for (const PoolLane& l : city().pool.lanes()) {
    if (l.group >= 0) {
      ++lit;
      EXPECT_EQ(l.signals.size(), 1u) << "road " << l.road_id << " lane " << l.lane_id;
    }
    if (l.group < 0) {
      EXPECT_TRUE(l.signals.empty()) << "road " << l.road_id;
    }
    used.insert(l.signals.begin(), l.signals.end());
  }
  EXPECT_GT(lit, 4u);
  EXPECT_EQ(used.size(), states(city(), Light::kRed).size());
  // A signal missing from the states is green; the stricter of several signals counts.
  const PoolNetwork& net = city().pool;
  for (uint32_t l = 0; l < net.lanes().size(); ++l) {
    if (net.lane(l).signals.empty()) {
      EXPECT_EQ(net.signal_light(l, states(city(), Light::kRed)), Light::kOff);
      continue;
    }
    EXPECT_EQ(net.signal_light(l, LightStates{}), Light::kGreen);
    EXPECT_EQ(net.signal_light(l, states(city(), Light::kYellow)), Light::kYellow);
    EXPECT_EQ(net.signal_light(l, states(city(), Light::kOff)), Light::kOff);
  }
  EXPECT_EQ(stricter(Light::kGreen, Light::kRed), Light::kRed);
  EXPECT_EQ(stricter(Light::kYellow, Light::kGreen), Light::kYellow);
  EXPECT_EQ(stricter(Light::kOff, Light::kGreen), Light::kGreen);
}

struct Flow {
  size_t crossings = 0, from_red = 0, queued = 0;  // queued: most at once, standing at a red
};

// 60 s of 60 vehicles on the city map under `lights` (none: the pool's own cycle); a crossing is
// a step from an approach lane with signals into a junction; from_red: from one of `red` lanes;
// queued: the most standing on `red` lanes at once after 30 s.
Flow run(const std::optional<LightStates>& lights, const std::set<std::string>& red = {}) {
  const PoolNetwork& net = city().pool;
  Pool pool(net, spawn(net, 60, 5, VehicleSpec{}));
  if (lights) pool.set_light_states(*lights);
  Flow f;
  std::vector<uint32_t> before(pool.size());
  for (int k = 0; k < 20 * 60; ++k) {
    for (size_t i = 0; i < pool.size(); ++i) before[i] = pool.lane(i);
    pool.step(0.05);
    size_t queued = 0;
    for (size_t i = 0; i < pool.size(); ++i) {
      const PoolLane& was = net.lane(before[i]);
      bool is_red = false;
      for (const std::string& id : red) is_red = is_red || has_signal(was, id);
      if (k > 20 * 30 && is_red && pool.lane(i) == before[i] && pool.speed(i) < 0.1) ++queued;
      if (pool.lane(i) == before[i] || was.approach < 0 || was.signals.empty()) continue;
      if (net.lane(pool.lane(i)).junction < 0) continue;
      ++f.crossings;
      f.from_red += is_red;
    }
    f.queued = std::max(f.queued, queued);
  }
  EXPECT_EQ(pool.overlaps().size(), 0u);
  return f;
}

std::set<std::string> all_ids(const Map& m) {
  std::set<std::string> out;
  for (const auto& [id, l] : states(m, Light::kRed)) out.insert(id);
  return out;
}

TEST(PoolLights, AllRedNobodyCrossesAStopLineTheyQueue) {
  const Flow f = run(states(city(), Light::kRed), all_ids(city()));
  EXPECT_EQ(f.crossings, 0u);
  EXPECT_GE(f.queued, 6u);
  // Red-yellow holds them too.
  EXPECT_EQ(run(states(city(), Light::kRedYellow)).crossings, 0u);
}

TEST(PoolLights, AllGreenTheyPassOwnCycleToo) {
  const Flow green = run(states(city(), Light::kGreen));
  EXPECT_GT(green.crossings, 20u);
  EXPECT_GT(run(LightStates{}).crossings, 20u);  // no states yet: all green
  const Flow own = run(std::nullopt);
  EXPECT_GT(own.crossings, 10u);
  EXPECT_LT(own.crossings, green.crossings);  // the own cycle holds some at red
}

TEST(PoolLights, OneApproachAlwaysRedNoneLeavesIt) {
  const Flow f = run(states(city(), Light::kGreen, {"1"}, Light::kRed), {"1"});
  EXPECT_EQ(f.from_red, 0u);
  EXPECT_GE(f.queued, 2u);
  EXPECT_GT(f.crossings, 20u);
  // The same approach green: some leave it (the check above can fail).
  EXPECT_GT(run(states(city(), Light::kGreen), {"1"}).from_red, 0u);
}

// `n` walkers whose first trip crosses crosswalk 2 (road 2 by junction J100), no vehicles,
// 60 s under `lights`: how many crossings they made.
uint64_t walker_crossings(const LightStates& lights) {
  const PoolNetwork& net = city().pool;
  const opendrive::LaneGraph& g = city().graph;
  const opendrive::Crosswalk* cw = nullptr;
  for (const opendrive::Crosswalk& c : g.crosswalks()) cw = c.id == "2" ? &c : cw;
  std::vector<WalkerSpec> specs;
  for (int side = 0; side < 2; ++side) {
    WalkerSpec ws;
    ws.id = "w" + std::to_string(side);
    ws.lane = cw->ends[side];
    ws.s = cw->s + 2.0;
    ws.gap = 0;
    ws.crosswalk = "2";
    ws.seed = side;
    specs.push_back(ws);
  }
  Pool pool(net, {});
  pool.set_light_states(lights);
  pool.set_walkers(specs);
  for (int k = 0; k < 20 * 60; ++k) pool.step(0.05);
  return pool.walkers()->stats().crossings;
}

// The signals of road 2's approaches within 30 m of crosswalk 2 (those the walkers obey).
std::set<std::string> road2_signals() {
  std::set<std::string> out;
  for (const PoolLane& l : city().pool.lanes()) {
    if (l.road_id == "2" && l.approach >= 0) out.insert(l.signals.begin(), l.signals.end());
  }
  return out;
}

TEST(PoolLights, WalkersWaitWhileTheCrossedRoadIsGreen) {
  const std::set<std::string> road2 = road2_signals();
  ASSERT_FALSE(road2.empty());
  // Every other light red, road 2's green (or yellow, or red-yellow): nobody crosses.
  EXPECT_EQ(walker_crossings(states(city(), Light::kRed, road2, Light::kGreen)), 0u);
  EXPECT_EQ(walker_crossings(states(city(), Light::kRed, road2, Light::kYellow)), 0u);
  EXPECT_EQ(walker_crossings(states(city(), Light::kRed, road2, Light::kRedYellow)), 0u);
  EXPECT_EQ(walker_crossings({}), 0u);  // missing: green
  // Road 2 red (the others green): they cross; all dark: on the gap alone.
  EXPECT_GE(walker_crossings(states(city(), Light::kGreen, road2, Light::kRed)), 2u);
  EXPECT_GE(walker_crossings(states(city(), Light::kOff)), 2u);
}

}  // namespace
}  // namespace convoy::traffic_pool
