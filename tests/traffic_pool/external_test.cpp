// External road users in the pool (the ego, agent engines' road users) on the 3x3 SUMO grid:
// a pooled car follows a stopped external car and stops behind it at its IDM gap; a lane
// change into a lane with an external car alongside is refused (and made without it); a
// pooled car waits while an external car stands in the junction across its path; externals
// are never moved.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "grid_map.h"
#include "opendrive/lane_graph.h"
#include "opendrive/parser.h"
#include "traffic_pool/pool.h"

namespace convoy::traffic_pool {
namespace {

// An external car whose box centre is `s` m along `lane`, heading along it.
ExternalUser car_on(const std::string& id, const PoolLane& lane, double s, double speed = 0) {
  const opendrive::Pose2 p = lane.at(s);
  ExternalUser u;
  u.id = id;
  u.x = p.x;
  u.y = p.y;
  u.yaw = p.heading;
  u.speed = speed;
  return u;
}

// A lane outside the junctions, longer than 70 m, with a same-direction neighbour.
const PoolLane& two_lane_road() {
  const PoolLane* two = nullptr;
  for (const PoolLane& l : map().pool.lanes()) {
    if (l.junction < 0 && l.length > 70 && (l.left != kNone || l.right != kNone)) two = &l;
  }
  if (two == nullptr) throw std::runtime_error("no lane");
  return *two;
}

TEST(PoolExternal, StopsBehindAStoppedExternalCarAtItsGap) {
  const PoolLane& lane = two_lane_road();
  VehicleSpec car = at("car", lane, 10);
  car.policy = "idm";
  car.speed = 10;
  const ExternalUser ego = car_on("ego", lane, 50);
  Pool pool(map().pool, {car});
  pool.set_external({ego});
  size_t touched = 0;
  for (int k = 0; k < 20 * 30; ++k) {
    pool.step(0.05);
    touched += pool.external_overlaps().size();
  }
  EXPECT_EQ(touched, 0u);
  EXPECT_LT(pool.speed(0), 0.05);
  const double rear = 50 - 0.5 * ego.length;  // the external's rear, along the lane
  EXPECT_NEAR(rear - pool.s(0), car.idm.s0, 0.3) << "stopped at s " << pool.s(0);
  // Never moved by the pool.
  EXPECT_EQ(pool.external().at(0).x, ego.x);
  EXPECT_EQ(pool.size(), 1u);
  // Without it, the car drives on past that point.
  Pool free_pool(map().pool, {car});
  const uint32_t start = free_pool.lane(0);
  for (int k = 0; k < 20 * 10; ++k) free_pool.step(0.05);
  EXPECT_TRUE(free_pool.lane(0) != start || free_pool.s(0) > rear + 5) << free_pool.s(0);
}

TEST(PoolExternal, LaneChangeNextToAnExternalCarIsRefused) {
  const PoolNetwork& net = map().pool;
  const PoolLane& two = two_lane_road();
  const PoolLane& beside = net.lane(two.left != kNone ? two.left : two.right);
  VehicleSpec slow = at("slow", two, 40);
  slow.policy = "idm";
  slow.idm.v0 = 2;
  slow.speed = 2;
  VehicleSpec fast = at("fast", two, 8);
  fast.speed = 10;
  Pool pool(net, {slow, fast});
  const uint32_t start = pool.lane(1);
  for (int k = 0; k < 60; ++k) {
    // An external car alongside the fast one, on the lane it would change to, moving with it.
    const double s = pool.s(1) * beside.length / two.length - 0.5 * 4.5;
    pool.set_external({car_on("ego", beside, s, pool.speed(1))});
    pool.step(0.05);
    ASSERT_EQ(pool.lane(1), start) << "changed lanes at step " << k;
    ASSERT_TRUE(pool.external_overlaps().empty());
  }
  EXPECT_EQ(pool.stats().lane_changes, 0u);
  // With the external car far behind, the same change is made (OvertakesASlowLeaderByMobil).
  Pool again(net, {slow, fast});
  again.set_external({car_on("ego", beside, 1, 0)});
  bool changed = false;
  for (int k = 0; k < 60 && !changed; ++k) {
    again.step(0.05);
    changed = again.lane(1) != start;
  }
  EXPECT_TRUE(changed);
}

TEST(PoolExternal, WaitsWhileAnExternalCarStandsAcrossItsJunctionPath) {
  const PoolNetwork& net = map().pool;
  // An approach, its first junction lane (the car is routed through it), and a junction lane
  // crossing it.
  for (uint32_t a = 0; a < net.lanes().size(); ++a) {
    const PoolLane& app = net.lane(a);
    if (app.approach < 0 || app.length < 40 || app.next.empty()) continue;
    bool green = true;  // for the first 20 s: only the external car can stop it
    for (double t = 0; t <= 21; t += 0.5) {
      const road_users::Light l = net.light(a, t);
      green = green && (l == road_users::Light::kGreen || l == road_users::Light::kOff);
    }
    if (!green) continue;
    const PoolLane& path = net.lane(app.next[0]);
    if (path.next.empty()) continue;
    const PoolLane& exit = net.lane(path.next[0]);
    for (uint32_t c : path.conflicts) {
      const PoolLane& cross = net.lane(c);
      if (cross.poses.size() < 10) continue;
      VehicleSpec car = at("car", app, app.length - 30);
      car.policy = "idm";
      car.speed = 5;
      car.to = std::make_pair(exit.road_id, exit.lane_id);
      Pool pool(net, {car});
      pool.set_external({car_on("ego", cross, 0.5 * cross.length)});
      for (int k = 0; k < 20 * 20; ++k) {
        pool.step(0.05);
        ASSERT_TRUE(pool.external_overlaps().empty()) << "t " << pool.time();
      }
      EXPECT_EQ(pool.lane(0), a) << "entered the junction while the external car stood in it";
      EXPECT_LT(pool.speed(0), 0.05);
      // Once it has gone, the car goes on (within a light cycle).
      pool.set_external({});
      for (int k = 0; k < 20 * 70 && pool.lane(0) == a; ++k) pool.step(0.05);
      EXPECT_NE(pool.lane(0), a);
      return;
    }
  }
  FAIL() << "no approach with a crossing junction lane on the grid";
}

// An external car coming up an approach that crosses the pooled car's junction path (on
// green, too fast to be sure it stops) keeps the pooled car at its line; a standing one does not.
TEST(PoolExternal, YieldsToAnExternalCarComingIntoTheJunction) {
  const PoolNetwork& net = map().pool;
  const auto green = [&](uint32_t lane) {  // for the test's first 8 s
    for (double t = 0; t <= 8; t += 0.5) {
      const road_users::Light l = net.light(lane, t);
      if (l != road_users::Light::kGreen && l != road_users::Light::kOff) return false;
    }
    return true;
  };
  for (uint32_t a = 0; a < net.lanes().size(); ++a) {
    const PoolLane& app = net.lane(a);
    if (app.approach < 0 || app.length < 40 || app.next.empty() || !green(a)) continue;
    const uint32_t j = app.next[0];
    const PoolLane& path = net.lane(j);
    if (path.next.empty()) continue;
    for (uint32_t c : path.conflicts) {
      for (uint32_t b = 0; b < net.lanes().size(); ++b) {
        const PoolLane& other = net.lane(b);
        if (b == a || other.approach < 0 || other.length < 40 || !green(b)) continue;
        if (std::find(other.next.begin(), other.next.end(), c) == other.next.end()) continue;
        const PoolLane& exit = net.lane(path.next[0]);
        VehicleSpec car = at("car", app, app.length - 15);
        car.policy = "idm";
        car.speed = 5;
        car.to = std::make_pair(exit.road_id, exit.lane_id);
        Pool pool(net, {car});
        const ExternalUser coming = car_on("ego", other, other.length - 20, 10);
        for (int k = 0; k < 3 * 20; ++k) {
          pool.set_external({coming});
          pool.step(0.05);
        }
        EXPECT_EQ(pool.lane(0), a) << "entered the junction in front of the external car";
        ExternalUser standing = car_on("ego", other, other.length - 40, 0);
        for (int k = 0; k < 10 * 20 && pool.lane(0) == a; ++k) {
          pool.set_external({standing});
          pool.step(0.05);
        }
        EXPECT_NE(pool.lane(0), a) << "kept waiting for a standing external car";
        return;
      }
    }
  }
  FAIL() << "no two green approaches into crossing junction lanes on the grid";
}

}  // namespace
}  // namespace convoy::traffic_pool
