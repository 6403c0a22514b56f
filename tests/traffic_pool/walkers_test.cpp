// Pooled walkers (pool_walkers.h) on the city map (sidewalks, 8 crosswalks, lights at both
// junctions): they stay on the sidewalks and are off them only on a crosswalk, a vehicle stops
// for a walker crossing its lane, a run is the same for the same seed, and bad input (a count the
// sidewalks cannot hold, a start off the sidewalks, an unknown crosswalk, an id twice; an unknown
// key of the engine's config) is named.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "config/json_schema.h"
#include "grid_map.h"
#include "traffic_pool/pool.h"

namespace convoy::traffic_pool {
namespace {

namespace odr = convoy::opendrive;

const odr::Crosswalk& crosswalk(const std::string& id) {
  for (const odr::Crosswalk& c : city().graph.crosswalks()) {
    if (c.id == id) return c;
  }
  throw std::runtime_error("no crosswalk " + id);
}

// Distance from (x, y) to the nearest crosswalk's line (between its sidewalks, at its s).
double to_crosswalk(double x, double y) {
  const odr::LaneGraph& g = city().graph;
  double best = INFINITY;
  for (const odr::Crosswalk& c : g.crosswalks()) {
    if (c.ends[0] == odr::kNoLane || c.ends[1] == odr::kNoLane) continue;
    const odr::WorldPose a = g.world_pose(c.road_id, g.lane(c.ends[0]).lane_id, c.s);
    const odr::WorldPose b = g.world_pose(c.road_id, g.lane(c.ends[1]).lane_id, c.s);
    const double ex = b.x - a.x, ey = b.y - a.y, len2 = ex * ex + ey * ey;
    const double f = std::clamp(((x - a.x) * ex + (y - a.y) * ey) / len2, 0.0, 1.0);
    best = std::min(best, std::hypot(x - a.x - f * ex, y - a.y - f * ey));
  }
  return best;
}

TEST(PoolWalkers, SidewalksCapacityAndBadInput) {
  const PoolNetwork& net = city().pool;
  const size_t cap = walker_capacity(net);
  EXPECT_GT(sidewalk_km(net), 1.0);
  EXPECT_EQ(cap, spawn_walkers(net, cap, 1).size());
  EXPECT_LT(walker_capacity(net, {{-150, -1.75, 40}}), cap);
  const std::string e = error_of([&] { spawn_walkers(net, cap + 1, 1); });
  EXPECT_NE(e.find("a count of " + std::to_string(cap + 1) + " pedestrians cannot fit the map"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("hold at most " + std::to_string(cap) + " walkers 4 m apart"), std::string::npos)
      << e;
  std::vector<WalkerSpec> w = spawn_walkers(net, 2, 1);
  w[1].lane = city().graph.find("2", -1, 50);  // a driving lane
  EXPECT_EQ(error_of([&] { PoolWalkers(net, w); }),
            "road user 'walker/1': its start is not on a sidewalk lane of the map");
  w = spawn_walkers(net, 1, 1);
  w[0].crosswalk = "99";
  EXPECT_EQ(error_of([&] { PoolWalkers(net, w); }),
            "road user 'walker/0': the map has no crosswalk '99' with sidewalks at both ends");
  const PoolLane* road = nullptr;
  for (const PoolLane& l : net.lanes()) {
    if (!road && l.junction < 0 && l.length > 30) road = &l;
  }
  Pool pool(net, {at("walker/0", *road, 10)});
  EXPECT_EQ(error_of([&] { pool.set_walkers(spawn_walkers(net, 1, 1)); }),
            "road user 'walker/0' is listed twice");
}

TEST(PoolWalkers, UnknownConfigKeyIsNamed) {
  std::ifstream f(CONVOY_POOL_SCHEMA);
  const nlohmann::json schema = nlohmann::json::parse(f);
  const auto issues = config::validate(
      schema, {{"Map", "city.xodr"}, {"Pedestrain", 200}, {"PedestrianDensity", -1}});
  ASSERT_EQ(issues.size(), 2u);
  std::string all;
  for (const auto& i : issues) all += i.pointer + ": " + i.message + "\n";
  EXPECT_NE(all.find("/Pedestrain: unknown key (ignored)"), std::string::npos) << all;
  EXPECT_NE(all.find("/PedestrianDensity: "), std::string::npos) << all;
}

// 150 vehicles and 80 walkers for 5 simulated minutes: a walker is on a sidewalk lane, or
// within 2 m of a crosswalk's line; walkers cross, and no vehicle or walker touches one.
TEST(PoolWalkers, StayOnSidewalksCrossAtCrosswalks) {
  const PoolNetwork& net = city().pool;
  Pool pool(net, spawn(net, 150, 3, VehicleSpec{}));
  pool.set_walkers(spawn_walkers(net, 80, 3));
  const PoolWalkers& w = *pool.walkers();
  size_t off_sidewalk = 0, outside_crosswalks = 0, touching = 0;
  for (int k = 0; k < 20 * 300; ++k) {
    pool.step(0.05);
    touching += pool.walker_overlaps().size() + w.overlaps().size();
    if (k % 10) continue;
    for (size_t i = 0; i < w.size(); ++i) {
      const auto loc = city().graph.locate_if(
          w.x(i), w.y(i), std::nullopt, 5.0,
          [](const odr::LaneNode& n, double) { return n.type == "sidewalk"; });
      if (loc && loc->distance <= 1e-6) continue;
      ++off_sidewalk;
      if (to_crosswalk(w.x(i), w.y(i)) > 2.0) {
        ++outside_crosswalks;
        ADD_FAILURE() << w.spec(i).id << " off the sidewalks at (" << w.x(i) << ", " << w.y(i)
                      << ") t " << pool.time();
      }
    }
  }
  EXPECT_GT(off_sidewalk, 0u);
  EXPECT_EQ(outside_crosswalks, 0u);
  EXPECT_GT(w.stats().crossings, 20u);
  EXPECT_GT(w.stats().trips, 100u);
  EXPECT_EQ(touching, 0u);
  EXPECT_EQ(pool.overlaps().size(), 0u);
}

// A car standing in junction J100 on its way into road 2's outer lane, held by an external car
// ahead; a slow walker crosses road 2 at crosswalk 2 (just past the junction). Once it is in the
// car's lane the external goes away: the car waits behind the walker, then drives on.
TEST(PoolWalkers, VehicleStopsForACrossingWalker) {
  const PoolNetwork& net = city().pool;
  const odr::LaneGraph& g = city().graph;
  const odr::Crosswalk& cw = crosswalk("2");
  const uint32_t exit = net.pool_lane(g.find("2", -2, 1.0));
  uint32_t in = kNone;
  for (uint32_t l = 0; l < net.lanes().size(); ++l) {
    const PoolLane& p = net.lane(l);
    if (p.junction >= 0 && !p.u_turn && p.next.size() == 1 && p.next[0] == exit &&
        (in == kNone || p.length > net.lane(in).length))
      in = l;  // the longest: straight on
  }
  ASSERT_NE(in, kNone);
  const PoolLane& c = net.lane(in);
  Pool pool(net, {at("car", c, c.length - 9)});
  const opendrive::Pose2 hold = c.at(c.length - 3);
  pool.set_external({{"holder", hold.x, hold.y, hold.heading, 0, 4.5, 1.8}});
  WalkerSpec ws;
  ws.id = "slow";
  ws.lane = cw.ends[0];
  ws.s = cw.s;
  ws.speed = 0.3;
  ws.gap = 0;
  ws.crosswalk = "2";
  ws.obey_lights = false;
  pool.set_walkers({ws});
  const PoolWalkers& w = *pool.walkers();
  auto in_lane = [&] {
    const opendrive::Pose2 p = net.lane(exit).at(2.75);
    const double lat = -(w.x(0) - p.x) * std::sin(p.heading) + (w.y(0) - p.y) * std::cos(p.heading);
    return std::abs(lat) < 1.2;
  };
  int k = 0;
  for (; k < 2000 && !in_lane(); ++k) pool.step(0.05);
  ASSERT_TRUE(in_lane()) << "the walker never reached the car's lane";
  pool.set_external({});
  double min_speed = INFINITY;
  bool stood = false, passed = false;
  for (; k < 6000 && !passed; ++k) {
    pool.step(0.05);
    ASSERT_TRUE(pool.walker_overlaps().empty()) << "t " << pool.time();
    if (in_lane()) {
      min_speed = std::min(min_speed, pool.speed(0));
      // Standing, its front short of the walker's line (s 2.75 on the exit lane).
      const bool short_of = pool.lane(0) == in || (pool.lane(0) == exit && pool.s(0) < 2.0);
      stood = stood || (pool.speed(0) < 0.05 && short_of);
    }
    passed = pool.lane(0) != in && pool.lane(0) != exit;
  }
  EXPECT_TRUE(stood) << "min speed while the walker was in its lane " << min_speed;
  EXPECT_TRUE(passed) << "the car never drove on";
  EXPECT_GE(w.stats().crossings, 1u);
}

// Walkers crossing crosswalk 2 from both sides (no vehicles): `per_side` on each sidewalk, 2.5 m
// apart along it from 2 m past the crosswalk. Steps `seconds` s; returns the most walkers whose
// boxes overlapped at once, and how many are on the road at the end.
std::pair<size_t, size_t> cross_both_ways(int per_side, bool lights, double seconds,
                                          uint64_t* crossings) {
  const PoolNetwork& net = city().pool;
  const odr::LaneGraph& g = city().graph;
  const odr::Crosswalk& cw = crosswalk("2");
  std::vector<WalkerSpec> specs;
  for (int side = 0; side < 2; ++side) {
    const odr::LaneNode& n = g.lane(cw.ends[side]);
    for (int k = 0; k < per_side; ++k) {
      WalkerSpec ws;
      ws.id = "w" + std::to_string(side) + "_" + std::to_string(k);
      ws.lane = cw.ends[side];
      ws.s = std::min(cw.s + 2.0 + 2.5 * k, n.s1 - 0.5);  // (the crosswalk is near s 0)
      ws.speed = 1.2 + 0.05 * k;
      ws.gap = 0;
      ws.crosswalk = "2";
      ws.obey_lights = lights;
      ws.seed = 10 * side + k;
      specs.push_back(ws);
    }
  }
  Pool pool(net, {});
  pool.set_walkers(specs);
  const PoolWalkers& w = *pool.walkers();
  size_t most = 0;
  for (int k = 0; k < static_cast<int>(20 * seconds); ++k) {
    pool.step(0.05);
    most = std::max(most, w.overlaps().size());
  }
  size_t on_road = 0;
  for (size_t i = 0; i < w.size(); ++i) on_road += w.on_road(i);
  *crossings = w.stats().crossings;
  return {most, on_road};
}

// Two walkers meeting head-on on a crosswalk pass each other, clear (their boxes never overlap).
TEST(PoolWalkers, HeadOnWalkersPassClear) {
  uint64_t crossings = 0;
  const auto [most, on_road] = cross_both_ways(1, false, 40, &crossings);
  EXPECT_EQ(most, 0u);
  EXPECT_GE(crossings, 2u);
  EXPECT_EQ(on_road, 0u);
}

// Six walkers a side walk up to the curb and wait there for the lights (a queue), then cross
// both ways at once, through the other side's queue: no two boxes ever overlap, all cross, none
// is left on the road.
TEST(PoolWalkers, CurbQueueNeverOverlaps) {
  uint64_t crossings = 0;
  const auto [most, on_road] = cross_both_ways(6, true, 150, &crossings);
  EXPECT_EQ(most, 0u);
  EXPECT_GE(crossings, 12u);
  EXPECT_EQ(on_road, 0u);
}

TEST(PoolWalkers, SameSeedSameRun) {
  const PoolNetwork& net = city().pool;
  auto run = [&](uint64_t seed) {
    Pool pool(net, spawn(net, 60, seed, VehicleSpec{}));
    pool.set_walkers(spawn_walkers(net, 40, seed));
    for (int k = 0; k < 20 * 60; ++k) pool.step(0.05);
    std::vector<double> out;
    for (size_t i = 0; i < pool.walkers()->size(); ++i) {
      out.push_back(pool.walkers()->x(i));
      out.push_back(pool.walkers()->y(i));
      out.push_back(pool.walkers()->walk_phase(i));
    }
    return out;
  };
  const auto a = run(4);
  EXPECT_EQ(a, run(4));
  EXPECT_NE(a, run(5));
  const auto s = spawn_walkers(net, 5, 4);
  for (const WalkerSpec& w : s) {
    EXPECT_GE(w.speed, 1.2);
    EXPECT_LT(w.speed, 1.5);
  }
}

}  // namespace
}  // namespace convoy::traffic_pool
