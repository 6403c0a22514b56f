// Scenario commands for pooled road users (Pool::set_commands) on the 3x3 SUMO grid: a speed
// command overrides IDM and the AI resumes from there; a teleport moves the car and localises
// it on the lane there; a lane command changes to the neighbour lane; a polyline is followed at
// IDM's speed behind the leader on it; bad ids and bad fields fail with one message naming the
// datapack, the road user and the key. Walkers (the city map): speed, teleport, a route through
// waypoints and a polyline.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "grid_map.h"
#include "traffic_pool/pool.h"

namespace convoy::traffic_pool {
namespace {

using nlohmann::json;

const PoolLane& long_lane() {
  const PoolLane* best = nullptr;
  for (const PoolLane& l : map().pool.lanes()) {
    if (l.junction < 0 && (!best || l.length > best->length)) best = &l;
  }
  return *best;
}

VehicleSpec car(const PoolLane& lane, double s, double speed) {
  VehicleSpec v = at("car", lane, s);
  v.policy = "idm";
  v.speed = speed;
  return v;
}

TEST(PoolCommands, SpeedOverridesIdmAndTheAiResumes) {
  Pool pool(map().pool, {car(long_lane(), 10, 10)});
  for (int k = 0; k < 20; ++k) {
    pool.set_commands(json{{"car", {{"speed", {{"speed", 3.0}, {"acceleration", -2.0}}}}}},
                      "commands", "pool_engine/", 0.25);
    pool.step(0.05);
    EXPECT_DOUBLE_EQ(pool.speed(0), 3.0);
    EXPECT_DOUBLE_EQ(pool.acceleration(0), -2.0);
  }
  pool.step(0.05);  // no command: IDM from 3 m/s (it speeds up, no jump)
  EXPECT_GT(pool.speed(0), 3.0);
  EXPECT_LT(pool.speed(0), 3.2);
  EXPECT_GT(pool.acceleration(0), 0);
}

TEST(PoolCommands, TeleportMovesAndRelocalises) {
  const PoolLane& lane = long_lane();
  Pool pool(map().pool, {car(lane, 10, 5)});
  const opendrive::Pose2 p = lane.at(60);  // the box centre's spot; the command gives the rear
  const double back = 0.25 * 4.5;          // axle, a quarter of its length behind it
  const json cmd{{"teleport",
                  {{"x", p.x - back * std::cos(p.heading)},
                   {"y", p.y - back * std::sin(p.heading)},
                   {"yaw", p.heading},
                   {"speed", 7.0}}}};
  pool.set_commands(json{{"pool_engine/car", cmd}}, "commands", "pool_engine/", 0.25);
  pool.step(0.05);
  EXPECT_NEAR(pool.x(0), p.x, 1e-9);
  EXPECT_NEAR(pool.y(0), p.y, 1e-9);
  EXPECT_DOUBLE_EQ(pool.speed(0), 7.0);
  EXPECT_EQ(&map().pool.lane(pool.lane(0)), &lane);
  EXPECT_NEAR(pool.s(0) - 2.25, 60, 1.01);  // its front along the lane
  pool.step(0.05);                          // on from there on its lane
  EXPECT_NEAR(pool.s(0) - 2.25, 60 + 0.35, 1.2);
  EXPECT_EQ(&map().pool.lane(pool.lane(0)), &lane);
}

TEST(PoolCommands, TeleportFarFromTheLanesStands) {
  Pool pool(map().pool, {car(long_lane(), 10, 5)});
  pool.set_commands(json{{"car", {{"teleport", {{"x", -500.0}, {"y", -500.0}, {"yaw", 0.0}}}}}},
                    "commands", "p/", 0.0);
  for (int k = 0; k < 10; ++k) pool.step(0.05);
  EXPECT_DOUBLE_EQ(pool.x(0), -500.0);
  EXPECT_DOUBLE_EQ(pool.speed(0), 0.0);
  EXPECT_TRUE(pool.standing(0));
  EXPECT_FALSE(pool.present(0));
  const opendrive::Pose2 p = long_lane().at(30);  // put back on the lanes: it drives on
  pool.set_commands(
      json{{"car", {{"teleport", {{"x", p.x}, {"y", p.y}, {"yaw", p.heading}, {"speed", 4.0}}}}}},
      "commands", "p/", 0.0);
  pool.step(0.05);
  EXPECT_FALSE(pool.standing(0));
  EXPECT_EQ(&map().pool.lane(pool.lane(0)), &long_lane());
  pool.step(0.05);
  EXPECT_GT(pool.speed(0), 3.9);
}

TEST(PoolCommands, RouteReplansThroughThePositions) {
  // A car before a junction, routed through a point of each lane out of it in turn (not turning
  // back): it drives onto that lane every time (not the seed's draw).
  const PoolLane& lane = long_lane();
  ASSERT_FALSE(lane.next.empty());
  std::vector<uint32_t> goals;
  for (uint32_t jl : lane.next) {
    if (!map().pool.lane(jl).u_turn)
      goals.insert(goals.end(), map().pool.lane(jl).next.begin(), map().pool.lane(jl).next.end());
  }
  size_t tried = 0;
  for (uint32_t goal : goals) {
    const opendrive::Pose2 p = map().pool.lane(goal).at(20);
    Pool pool(map().pool, {car(lane, 10, 8)});
    bool reached = false;
    for (int k = 0; k < 20 * 60 && !reached; ++k) {
      pool.set_commands(json{{"car", {{"route", {{"positions", {{p.x, p.y}}}}}}}}, "c", "p/", 0.25);
      pool.step(0.05);
      reached = pool.lane(0) == goal;
    }
    EXPECT_TRUE(reached) << "to lane " << goal;
    ++tried;
  }
  EXPECT_GE(tried, 2u);
}

TEST(PoolCommands, LaneChangesToTheNeighbour) {
  const PoolLane* two = nullptr;
  for (const PoolLane& l : map().pool.lanes()) {
    if (l.junction < 0 && l.length > 70 && l.left != kNone) two = &l;
  }
  ASSERT_NE(two, nullptr);
  const PoolLane& to = map().pool.lane(two->left);
  Pool pool(map().pool, {car(*two, 20, 5)});
  pool.set_commands(json{{"car", {{"lane", {{"road", to.road_id}, {"lane", to.lane_id}}}}}},
                    "commands", "p/", 0.25);
  pool.step(0.05);
  EXPECT_EQ(pool.lane(0), two->left);
  EXPECT_EQ(pool.stats().lane_changes, 1u);
}

TEST(PoolCommands, SameCommandsSameRun) {
  auto run = [] {
    std::vector<VehicleSpec> specs = spawn(map().pool, 20, 3, VehicleSpec{}, "pool/");
    Pool pool(map().pool, specs);
    std::vector<double> out;
    for (int k = 0; k < 200; ++k) {
      if (k < 100) {
        pool.set_commands(json{{"pool/3", {{"speed", {{"speed", 2.0}}}}}}, "c", "e/", 0.25);
      }
      pool.step(0.05);
    }
    for (size_t i = 0; i < pool.size(); ++i) out.push_back(pool.x(i) + pool.y(i) + pool.speed(i));
    return out;
  };
  EXPECT_EQ(run(), run());
}

TEST(PoolCommands, BadIdsAndFieldsAreNamed) {
  Pool pool(map().pool, {car(long_lane(), 10, 5)});
  EXPECT_EQ(error_of([&] {
              pool.set_commands(json{{"nobody", json::object()}},
                                "pool 'traffic': datapack 'commands'", "traffic/", 0.25);
            }),
            "pool 'traffic': datapack 'commands': no road user 'nobody' in the pool (ids as it "
            "publishes them, with or without 'traffic/')");
  EXPECT_EQ(error_of([&] {
              pool.set_commands(json{{"car", {{"speed", {{"speed", "fast"}}}}}}, "dp", "t/", 0.25);
            }),
            "dp: road user 'car': command.speed.speed: expected a number, got \"fast\"");
  EXPECT_EQ(error_of([&] {
              pool.set_commands(json{{"car", {{"sped", 1}}}}, "dp", "t/", 0.25);
            }),
            "dp: road user 'car': command.sped: unknown key (time_ns, speed, lane, route, "
            "trajectory, teleport)");
  EXPECT_EQ(error_of([&] {
              pool.set_commands(json{{"car", {{"trajectory", {{"polyline", json::array()}}}}}},
                                "dp", "t/", 0.25);
            }),
            "dp: road user 'car': command.trajectory.polyline: expected a list of at least 1 "
            "points [x, y], got []");
  EXPECT_EQ(error_of([&] {
              pool.set_commands(json{{"car", {{"trajectory", {{"polyline", {{0, 0}, {1}}}}}}}},
                                "dp", "t/", 0.25);
            }),
            "dp: road user 'car': command.trajectory.polyline[1]: expected a point [x, y] (or "
            "[x, y, z]), got [1]");
  EXPECT_EQ(
      error_of([&] {
        pool.set_commands(
            json{{"car",
                  {{"trajectory", {{"polyline", {{0, 0}, {9, 9}}}}},
                   {"lane", {{"road", long_lane().road_id}, {"lane", long_lane().lane_id}}}}}},
            "dp", "t/", 0.25);
      }),
      "dp: road user 'car': command.trajectory: both lane and trajectory steer: give one of "
      "them");
}

// The distance from (x, y) to the polyline through `pts`.
double off_polyline(const road_users::Points& pts, double x, double y) {
  double best = INFINITY;
  for (size_t k = 0; k + 1 < pts.size(); ++k) {
    const double ex = pts[k + 1][0] - pts[k][0], ey = pts[k + 1][1] - pts[k][1];
    const double f =
        std::clamp(((x - pts[k][0]) * ex + (y - pts[k][1]) * ey) / (ex * ex + ey * ey), 0.0, 1.0);
    best = std::min(best, std::hypot(pts[k][0] + f * ex - x, pts[k][1] + f * ey - y));
  }
  return best;
}

json polyline_command(const road_users::Points& pts) {
  json line = json::array();
  for (const auto& p : pts) line.push_back({p[0], p[1]});
  return {{"trajectory", {{"polyline", line}}}};
}

// A lane outside junctions with a neighbour on its left, both over 70 m long.
const PoolLane& two_lane_road() {
  const PoolLane* two = nullptr;
  for (const PoolLane& l : map().pool.lanes()) {
    if (l.junction < 0 && l.length > 70 && l.left != kNone && map().pool.lane(l.left).length > 70)
      two = &l;
  }
  EXPECT_NE(two, nullptr);
  return *two;
}

TEST(PoolCommands, PolylineIsFollowedAtIdmSpeed) {
  // Its reference point (a quarter of its length behind the centre) along a polyline from its
  // lane over to the left one: pure pursuit keeps it within 1 m of the line, IDM speeds it up,
  // and it is on the left lane at the last point.
  const PoolLane& lane = two_lane_road();
  const PoolLane& left = map().pool.lane(lane.left);
  Pool pool(map().pool, {car(lane, 10, 5)});
  const double back = 0.25 * 4.5;
  const double rx = pool.x(0) - back * std::cos(pool.yaw(0));
  const double ry = pool.y(0) - back * std::sin(pool.yaw(0));
  const opendrive::Pose2 a = lane.at(20), b = left.at(45), c = left.at(left.length - 5);
  const road_users::Points pts{{rx, ry}, {a.x, a.y}, {b.x, b.y}, {c.x, c.y}};
  double worst = 0, nearest_end = INFINITY;
  int k = 0;
  for (; k < 400 && nearest_end > 0.5; ++k) {
    pool.set_commands(json{{"car", polyline_command(pts)}}, "dp", "p/", 0.25);
    pool.step(0.05);
    const double x = pool.x(0) - back * std::cos(pool.yaw(0));
    const double y = pool.y(0) - back * std::sin(pool.yaw(0));
    worst = std::max(worst, off_polyline(pts, x, y));
    nearest_end = std::min(nearest_end, std::hypot(x - c.x, y - c.y));
  }
  EXPECT_LT(nearest_end, 0.5) << "after " << k << " steps";
  EXPECT_LT(worst, 1.0);
  EXPECT_GT(pool.speed(0), 8.0);  // IDM from 5 m/s towards its desired speed
  EXPECT_TRUE(pool.present(0));
  EXPECT_EQ(pool.lane(0), lane.left);
  pool.step(0.05);  // the command stops: on along the left lane
  EXPECT_TRUE(pool.lane(0) == lane.left || map().pool.lane(pool.lane(0)).junction >= 0);
}

TEST(PoolCommands, PolylineFollowsTheLeaderOnIt) {
  // A car held standing 40 m ahead on the polyline: the one on it stops behind, no overlap.
  const PoolLane& lane = two_lane_road();
  VehicleSpec lead = car(lane, 55, 0);
  lead.id = "lead";
  Pool pool(map().pool, {car(lane, 10, 8), lead});
  const opendrive::Pose2 a = lane.at(0), b = lane.at(lane.length - 1);
  const road_users::Points pts{{a.x, a.y}, {b.x, b.y}};
  for (int k = 0; k < 300; ++k) {
    pool.set_commands(json{{"car", polyline_command(pts)}, {"lead", {{"speed", {{"speed", 0}}}}}},
                      "dp", "p/", 0.25);
    pool.step(0.05);
    ASSERT_TRUE(pool.overlaps().empty()) << "step " << k;
  }
  EXPECT_LT(pool.speed(0), 0.1);
  const double gap = std::hypot(pool.x(1) - pool.x(0), pool.y(1) - pool.y(0)) - 4.5;
  EXPECT_GT(gap, 1.0);
  EXPECT_LT(gap, 4.0);  // about IDM's jam distance (2 m)
}

TEST(PoolCommands, OnePointPolylineHeadsThere) {
  // As for the agents, one point is a polyline: it drives towards it (straight on past it).
  const PoolLane& lane = long_lane();
  Pool pool(map().pool, {car(lane, 10, 5)});
  const opendrive::Pose2 p = lane.at(40);
  for (int k = 0; k < 20; ++k) {
    pool.set_commands(json{{"car", polyline_command({{p.x, p.y}})}}, "dp", "p/", 0.25);
    pool.step(0.05);
  }
  EXPECT_NEAR(pool.s(0) - 2.25, 10 - 2.25 + 20 * 0.05 * 5.5, 2.0);
  EXPECT_LT(std::hypot(pool.x(0) - p.x, pool.y(0) - p.y), 30);
}

}  // namespace
}  // namespace convoy::traffic_pool

namespace convoy::traffic_pool {
namespace {

TEST(PoolCommands, WalkersTakeSpeedAndTeleportNotLane) {
  Pool pool(city().pool, {});
  pool.set_walkers(spawn_walkers(city().pool, 3, 1, "walker/"));
  const PoolWalkers& w = *pool.walkers();
  for (int k = 0; k < 10; ++k) pool.step(0.05);
  for (int k = 0; k < 20; ++k) {
    pool.set_commands(json{{"walker/1", {{"speed", {{"speed", 0.5}}}}}}, "dp", "p/", 0.25);
    pool.step(0.05);
    EXPECT_LE(w.speed(1), 0.5 + 1e-9);
  }
  const double own = w.spec(1).speed;
  EXPECT_GT(own, 1.0);  // its own pace back after the command
  const double x = w.x(0) + 3, y = w.y(0) + 2;
  pool.set_commands(json{{"p/walker/0", {{"teleport", {{"x", x}, {"y", y}, {"yaw", 1.0}}}}}}, "dp",
                    "p/", 0.25);
  pool.step(0.05);
  EXPECT_NEAR(w.x(0), x, 1e-9);
  EXPECT_NEAR(w.y(0), y, 1e-9);
  EXPECT_DOUBLE_EQ(w.yaw(0), 1.0);
  for (int k = 0; k < 20; ++k) pool.step(0.05);  // and walks on from there
  EXPECT_GT(std::hypot(w.x(0) - x, w.y(0) - y), 0.1);
  const std::string e = error_of([&] {
    pool.set_commands(json{{"walker/2", {{"lane", {{"road", "1"}, {"lane", -1}}}}}}, "dp", "p/",
                      0.25);
  });
  EXPECT_EQ(e,
            "dp: road user 'walker/2': command.lane: a pedestrian has no lane to change to (a "
            "pedestrian_agent takes speed, route, trajectory and teleport)");
}

// A walker on crosswalk `cw`'s end-0 sidewalk, `ahead` m along the road from it.
WalkerSpec walker_near(const opendrive::Crosswalk& cw, double ahead) {
  const opendrive::LaneNode& n = city().graph.lane(cw.ends[0]);
  WalkerSpec w;
  w.id = "walker/x";
  w.lane = cw.ends[0];
  w.s = std::clamp(cw.s + ahead, n.s0 + 1, n.s1 - 1);
  return w;
}

const opendrive::Crosswalk& some_crosswalk() {
  const opendrive::LaneGraph& g = city().graph;
  for (const opendrive::Crosswalk& cw : g.crosswalks()) {
    if (cw.ends[0] != opendrive::kNoLane && cw.ends[1] != opendrive::kNoLane &&
        g.lane(cw.ends[0]).length > 30)
      return cw;
  }
  ADD_FAILURE() << "no crosswalk with sidewalks at both ends";
  return g.crosswalks().front();
}

TEST(PoolCommands, WalkerRouteReachesItsLastWaypoint) {
  // Along the sidewalk to a crosswalk's end, over it (no vehicles: the gap is there) to the far
  // end: it reaches each waypoint (within its keep-right offset, 0.55 m, more round the corner
  // at the far end), then walks on.
  const opendrive::LaneGraph& g = city().graph;
  const opendrive::Crosswalk& cw = some_crosswalk();
  Pool pool(city().pool, {});
  pool.set_walkers({walker_near(cw, 12)});
  const PoolWalkers& w = *pool.walkers();
  const auto end = [&](int e) {
    return g.world_pose(cw.road_id, g.lane(cw.ends[e]).lane_id, cw.s);
  };
  const opendrive::WorldPose a = end(0), b = end(1);
  const json cmd{{"route", {{"positions", {{a.x, a.y}, {b.x, b.y}}}}}};
  double near_a = INFINITY, near_b = INFINITY;
  for (int k = 0; k < 60 * 20 && near_b > 0.6; ++k) {
    pool.set_commands(json{{"walker/x", cmd}}, "dp", "p/", 0.25);
    pool.step(0.05);
    near_a = std::min(near_a, std::hypot(w.x(0) - a.x, w.y(0) - a.y));
    if (near_a < 1.2) near_b = std::min(near_b, std::hypot(w.x(0) - b.x, w.y(0) - b.y));
  }
  EXPECT_LT(near_a, 1.2);
  EXPECT_LT(near_b, 1.2);
  const double x = w.x(0), y = w.y(0);
  for (int k = 0; k < 40; ++k) pool.step(0.05);  // no command: on from there
  EXPECT_GT(std::hypot(w.x(0) - x, w.y(0) - y), 1.0);
}

TEST(PoolCommands, WalkerPolylineIsFollowedAndItStandsAtItsEnd) {
  Pool pool(city().pool, {});
  pool.set_walkers(spawn_walkers(city().pool, 1, 4, "walker/"));
  const PoolWalkers& w = *pool.walkers();
  const double x0 = w.x(0), y0 = w.y(0), h = w.yaw(0) + M_PI / 2;  // off to its left
  const road_users::Points pts{{x0, y0},
                               {x0 + 4 * std::cos(h), y0 + 4 * std::sin(h)},
                               {x0 + 4 * std::cos(h) + 3 * std::cos(h - M_PI / 2),
                                y0 + 4 * std::sin(h) + 3 * std::sin(h - M_PI / 2)}};
  double worst = 0;
  for (int k = 0; k < 200; ++k) {
    pool.set_commands(json{{"walker/0", polyline_command(pts)}}, "dp", "p/", 0.25);
    pool.step(0.05);
    worst = std::max(worst, off_polyline(pts, w.x(0), w.y(0)));
  }
  EXPECT_LT(worst, 0.3);
  EXPECT_LT(std::hypot(w.x(0) - pts[2][0], w.y(0) - pts[2][1]), 1e-6);
  EXPECT_DOUBLE_EQ(w.speed(0), 0.0);
  for (int k = 0; k < 5; ++k) {  // at a commanded pace
    pool.set_commands(
        json{{"walker/0",
              {{"trajectory", {{"polyline", {pts[2], pts[0]}}}}, {"speed", {{"speed", 2.0}}}}}},
        "dp", "p/", 0.25);
    pool.step(0.05);
    EXPECT_NEAR(w.speed(0), 2.0, 1e-9);
  }
  const double x = w.x(0), y = w.y(0);
  for (int k = 0; k < 40; ++k) pool.step(0.05);  // no command: to the nearest sidewalk and on
  EXPECT_GT(std::hypot(w.x(0) - x, w.y(0) - y), 1.0);
}

TEST(PoolCommands, WalkerPathsBadInputIsNamed) {
  Pool pool(city().pool, {});
  pool.set_walkers(spawn_walkers(city().pool, 1, 4, "walker/"));
  EXPECT_EQ(error_of([&] {
              pool.set_commands(json{{"walker/0", {{"route", {{"positions", json::array()}}}}}},
                                "dp", "p/", 0.25);
            }),
            "dp: road user 'walker/0': command.route.positions: expected a list of points [x, y], "
            "got []");
  const std::string far = error_of([&] {
    pool.set_commands(json{{"walker/0", {{"route", {{"positions", {{-5000.0, -5000.0}}}}}}}}, "dp",
                      "p/", 0.25);
  });
  EXPECT_EQ(far.rfind("dp: road user 'walker/0': command.route.positions[0]: (-5000.00, -5000.00) "
                      "is farther than 20 m from any lane of ",
                      0),
            0u)
      << far;
  EXPECT_EQ(error_of([&] {
              pool.set_commands(json{{"walker/0", {{"trajectory", {{"polyline", json::array()}}}}}},
                                "dp", "p/", 0.25);
            }),
            "dp: road user 'walker/0': command.trajectory.polyline: expected a list of points [x, "
            "y], got []");
}

}  // namespace
}  // namespace convoy::traffic_pool
