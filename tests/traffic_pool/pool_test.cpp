// The pooled host's core on a 3x3 SUMO grid (2 lanes a direction, lights at the junctions
// SUMO guessed them for): the network's junctions, lights and conflicts; bad input naming the
// road user; a run with no collision, vehicles moving through junctions, and determinism.
#include "traffic_pool/pool.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <set>

#include "grid_map.h"
#include "opendrive/lane_graph.h"
#include "opendrive/parser.h"

namespace convoy::traffic_pool {
namespace {

TEST(PoolNetwork, LanesJunctionsConflicts) {
  const PoolNetwork& net = map().pool;
  ASSERT_GT(net.lanes().size(), 50u);
  ASSERT_EQ(net.junctions().size(), 9u);
  size_t approaches = 0, with_conflicts = 0, lit = 0;
  for (const PoolLane& l : net.lanes()) {
    approaches += l.approach >= 0;
    with_conflicts += !l.conflicts.empty();
    lit += l.group >= 0;
    EXPECT_GT(l.length, 0);
    if (l.junction >= 0) {
      EXPECT_EQ(l.left, kNone);
    }
  }
  EXPECT_GT(approaches, 20u);
  EXPECT_GT(with_conflicts, 10u);
  EXPECT_GT(lit, 0u);
}

TEST(PoolNetwork, LightGroupsTakeTurns) {
  const LightCycle c;
  for (double t = 0; t < c.period(); t += 0.5) {
    const road_users::Light a = c.state(t, 0, 0), b = c.state(t, 0, 1);
    EXPECT_FALSE(a != road_users::Light::kRed && b != road_users::Light::kRed) << t;
  }
  EXPECT_EQ(c.state(1, 0, 0), road_users::Light::kGreen);
  EXPECT_EQ(c.state(c.green_s + 1, 0, 0), road_users::Light::kYellow);
  EXPECT_EQ(c.state(1, 0, 1), road_users::Light::kRed);
}

const PoolLane& long_lane() {
  for (const PoolLane& l : map().pool.lanes()) {
    if (l.junction < 0 && l.length > 40) return l;
  }
  throw std::runtime_error("no lane");
}

TEST(PoolErrors, UnknownPolicyNamesTheRoadUser) {
  VehicleSpec v = at("car_7", long_lane(), 20);
  v.policy = "teleport";
  EXPECT_EQ(error_of([&] { Pool(map().pool, {v}); }),
            "road user 'car_7': unknown policy 'teleport' (known: idm_mobil, idm)");
}

TEST(PoolErrors, TwoOnOneSpot) {
  const std::string e = error_of([&] {
    Pool(map().pool, {at("a", long_lane(), 20), at("b", long_lane(), 22)});
  });
  EXPECT_NE(e.find("road user 'a' and road user 'b' are on one spot"), std::string::npos) << e;
  EXPECT_EQ(error_of([&] {
              Pool(map().pool, {at("a", long_lane(), 20), at("b", long_lane(), 30)});
            }),
            "");
}

TEST(PoolErrors, CountThatCannotFit) {
  const std::string e = error_of([&] { spawn(map().pool, 100000, 1, VehicleSpec{}); });
  EXPECT_NE(e.find("a count of 100000 cannot fit the network"), std::string::npos) << e;
}

TEST(PoolSpawn, CapacityKmAndKeepClear) {
  const PoolNetwork& net = map().pool;
  const VehicleSpec base;
  const size_t all = spawn_capacity(net, base);
  EXPECT_EQ(spawn(net, all, 1, base).size(), all);
  const double km = driving_km(net);
  EXPECT_GT(km, 1.0);
  // Slots are length + s0 + 2 = 8.5 m apart on each lane: ~118 a km, one more or less a lane.
  EXPECT_LE(all, static_cast<size_t>(km * 1000 / 8.5) + net.lanes().size());
  EXPECT_GT(all, static_cast<size_t>(km * 1000 / 8.5 * 0.7));
  // A disc round the middle of the map is kept clear, and costs slots.
  const ClearZone z{0.5 * (net.min_x + net.max_x), 0.5 * (net.min_y + net.max_y), 60};
  const size_t kept = spawn_capacity(net, base, {z});
  EXPECT_LT(kept, all);
  for (const VehicleSpec& v : spawn(net, kept, 3, base, "pool/", {z})) {
    const opendrive::Pose2 p = net.lane(v.pool_lane).at(v.s - 0.5 * v.length);
    EXPECT_GE(std::hypot(p.x - z.x, p.y - z.y), z.radius) << v.id;
  }
  EXPECT_NE(error_of([&] { spawn(net, kept + 1, 3, base, "pool/", {z}); }).find("cannot fit"),
            std::string::npos);
}

TEST(PoolErrors, RouteWithNoPathAndUnknownLane) {
  VehicleSpec v = at("bus_1", long_lane(), 20);
  v.to = std::make_pair(std::string("no_such_road"), -1);
  EXPECT_NE(error_of([&] { Pool(map().pool, {v}); }).find("road user 'bus_1': no path from"),
            std::string::npos);
  VehicleSpec w = at("van", long_lane(), 20);
  w.road = "nowhere";
  EXPECT_NE(error_of([&] { Pool(map().pool, {w}); }).find("road user 'van': road 'nowhere'"),
            std::string::npos);
  VehicleSpec d = at("twin", long_lane(), 20);
  EXPECT_NE(error_of([&] { Pool(map().pool, {d, d}); }).find("listed twice"), std::string::npos);
}

TEST(PoolRun, NoCollisionVehiclesMoveThroughJunctions) {
  Pool pool(map().pool, spawn(map().pool, 120, 7, VehicleSpec{}));
  std::vector<double> x0(pool.size()), y0(pool.size());
  for (size_t i = 0; i < pool.size(); ++i) x0[i] = pool.x(i), y0[i] = pool.y(i);
  size_t overlaps = 0;
  for (int k = 0; k < 20 * 120; ++k) {  // 2 simulated minutes at 20 Hz
    pool.step(0.05);
    for (const auto& [a, b] : pool.overlaps()) {
      if (++overlaps < 6) {
        ADD_FAILURE() << "t " << pool.time() << ": " << a << " lane " << pool.lane(a) << " s "
                      << pool.s(a) << " j " << map().pool.lane(pool.lane(a)).junction << " v "
                      << pool.speed(a) << " / " << b << " lane " << pool.lane(b) << " s "
                      << pool.s(b) << " j " << map().pool.lane(pool.lane(b)).junction << " v "
                      << pool.speed(b);
      }
    }
  }
  EXPECT_EQ(overlaps, 0u);
  EXPECT_GT(pool.stats().junction_entries, 200u);
  EXPECT_GT(pool.stats().lane_changes, 0u);
  size_t moved = 0;
  for (size_t i = 0; i < pool.size(); ++i) {
    moved += std::hypot(pool.x(i) - x0[i], pool.y(i) - y0[i]) > 50;
    EXPECT_LE(pool.speed(i), 13.9 + 1e-6);
  }
  EXPECT_GT(moved, pool.size() / 2);
}

TEST(PoolRun, NobodyEntersOnALongRed) {
  // A vehicle claims its junction lane on green or (unable to stop) on yellow, so it enters
  // at most a few seconds into red; never on a light that has been red for 3 s.
  const PoolNetwork& net = map().pool;
  Pool pool(net, spawn(net, 150, 11, VehicleSpec{}));
  std::vector<uint32_t> before(pool.size());
  size_t checked = 0;
  for (int k = 0; k < 20 * 150; ++k) {
    for (size_t i = 0; i < pool.size(); ++i) before[i] = pool.lane(i);
    pool.step(0.05);
    for (size_t i = 0; i < pool.size(); ++i) {
      const PoolLane& from = net.lane(before[i]);
      if (pool.lane(i) == before[i] || from.group < 0 || net.lane(pool.lane(i)).junction < 0) {
        continue;
      }
      ++checked;
      const bool long_red = net.light(before[i], pool.time()) == road_users::Light::kRed &&
                            net.light(before[i], pool.time() - 3) == road_users::Light::kRed;
      EXPECT_FALSE(long_red) << "vehicle " << i << " at t " << pool.time();
    }
  }
  EXPECT_GT(checked, 100u);
}

TEST(PoolRun, OvertakesASlowLeaderByMobil) {
  const PoolNetwork& net = map().pool;
  const PoolLane* two = nullptr;  // a lane with a neighbour in its direction
  for (const PoolLane& l : net.lanes()) {
    if (l.junction < 0 && l.length > 70 && (l.left != kNone || l.right != kNone)) two = &l;
  }
  ASSERT_NE(two, nullptr);
  VehicleSpec slow = at("slow", *two, 40);
  slow.policy = "idm";
  slow.idm.v0 = 2;
  slow.speed = 2;
  VehicleSpec fast = at("fast", *two, 8);
  fast.speed = 10;
  Pool pool(net, {slow, fast});
  const uint32_t start = pool.lane(1);
  bool changed = false;
  for (int k = 0; k < 60 && !changed; ++k) {
    pool.step(0.05);
    changed = pool.lane(1) != start && pool.lane(1) != pool.lane(0);
  }
  EXPECT_TRUE(changed);
  EXPECT_EQ(pool.stats().lane_changes, 1u);
  EXPECT_EQ(pool.lane(0), start);  // the slow one, policy idm, keeps its lane
}

TEST(PoolRun, SameSeedSameRun) {
  Pool a(map().pool, spawn(map().pool, 60, 3, VehicleSpec{}));
  Pool b(map().pool, spawn(map().pool, 60, 3, VehicleSpec{}));
  for (int k = 0; k < 400; ++k) a.step(0.05), b.step(0.05);
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a.x(i), b.x(i));
    EXPECT_EQ(a.speed(i), b.speed(i));
  }
}

TEST(PoolRun, RoutedVehicleFollowsItsRoute) {
  const PoolNetwork& net = map().pool;
  const PoolLane& start = long_lane();
  // Its destination: a lane two lanes on from its start.
  const PoolLane& j = net.lane(start.next.at(0));
  const PoolLane& exit = net.lane(j.next.at(0));
  VehicleSpec v = at("routed", start, 5);
  v.to = std::make_pair(exit.road_id, exit.lane_id);
  Pool pool(net, {v});
  std::set<uint32_t> seen;
  for (int k = 0; k < 600 && seen.size() < 3; ++k) {
    pool.step(0.05);
    seen.insert(pool.lane(0));
  }
  EXPECT_TRUE(seen.count(net.pool_lane(exit.graph_lane))) << seen.size();
}

// The city map (experiments/city_traffic/city.xodr): its roads end at the map's edges, so
// vehicles leave the map there and come back at an entry (a lane no lane leads into). Over 10
// simulated minutes at 300 vehicles: no collision, vehicles keep leaving and coming back, and
// every jump to a lane that does not follow (nor sit beside) the last one lands on an entry.
TEST(PoolRun, CityLeavesAtEdgesComesBackAtEntries) {
  static const opendrive::Network net = opendrive::load(CONVOY_CITY_XODR);
  static const opendrive::LaneGraph graph{net};
  static const PoolNetwork pnet{graph};
  std::vector<uint8_t> led_into(pnet.lanes().size(), 0);
  for (const PoolLane& l : pnet.lanes()) {
    for (uint32_t k : l.next) led_into[k] = 1;
  }
  Pool pool(pnet, spawn(pnet, 300, 5, VehicleSpec{}));
  std::vector<uint32_t> last(pool.size());
  for (size_t i = 0; i < pool.size(); ++i) last[i] = pool.lane(i);
  size_t overlaps = 0, jumps = 0;
  for (int k = 0; k < 20 * 600; ++k) {
    pool.step(0.05);
    for (size_t i = 0; i < pool.size(); ++i) {
      const uint32_t now = pool.lane(i), was = last[i];
      last[i] = now;
      if (now == was) continue;
      const PoolLane& w = pnet.lane(was);
      const bool follows = std::find(w.next.begin(), w.next.end(), now) != w.next.end() ||
                           now == w.left || now == w.right;
      if (follows) continue;
      ++jumps;
      EXPECT_FALSE(led_into[now]) << "vehicle " << i << " came back on lane " << now;
    }
    overlaps += pool.overlaps().size();
  }
  EXPECT_EQ(overlaps, 0u);
  EXPECT_GT(pool.stats().respawns, 50u);
  EXPECT_EQ(jumps, pool.stats().respawns);
}

}  // namespace
}  // namespace convoy::traffic_pool
