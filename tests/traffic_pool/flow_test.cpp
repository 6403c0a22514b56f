// Flows given from outside (benchmarks/realism feeds the same flows to the pool and to SUMO):
// vehicles wait absent until Pool::enter puts them at the start of an entry lane, follow their
// route, and leave the network at its edge (set_leave_at_exits) instead of starting again.
#include <gtest/gtest.h>

#include <set>

#include "grid_map.h"
#include "opendrive/lane_graph.h"
#include "opendrive/parser.h"
#include "traffic_pool/pool.h"

namespace convoy::traffic_pool {
namespace {

// An entry lane (no lane leads into it) and the exit lane reached by always taking next[0].
std::pair<uint32_t, uint32_t> entry_and_exit(const PoolNetwork& net) {
  std::vector<uint8_t> led_into(net.lanes().size(), 0);
  for (const PoolLane& l : net.lanes()) {
    for (uint32_t k : l.next) led_into[k] = 1;
  }
  for (uint32_t e = 0; e < net.lanes().size(); ++e) {
    if (led_into[e] || net.lane(e).junction >= 0) continue;
    uint32_t l = e;
    for (int hops = 0; hops < 20 && !net.lane(l).next.empty(); ++hops) l = net.lane(l).next[0];
    if (net.lane(l).next.empty() && l != e) return {e, l};
  }
  return {kNone, kNone};
}

std::vector<VehicleSpec> flow_specs(size_t n, const PoolLane& exit) {
  std::vector<VehicleSpec> specs(n);
  for (size_t k = 0; k < n; ++k) {
    specs[k].id = "flow/" + std::to_string(k);
    specs[k].seed = k;
    specs[k].absent = true;
    specs[k].to = std::make_pair(exit.road_id, exit.lane_id);
  }
  return specs;
}

TEST(PoolFlow, VehiclesEnterFollowTheirRouteAndLeave) {
  const PoolNetwork& net = city().pool;
  const auto [entry, exit] = entry_and_exit(net);
  ASSERT_NE(entry, kNone);
  Pool pool(net, flow_specs(12, net.lane(exit)));
  pool.set_leave_at_exits(true);
  for (size_t i = 0; i < pool.size(); ++i) EXPECT_FALSE(pool.present(i));
  size_t entered = 0, left = 0, overlaps = 0;
  std::vector<uint32_t> last(pool.size(), kNone);
  for (int k = 0; k < 20 * 240; ++k) {
    if (k % 60 == 0 && entered < pool.size()) {  // one every 3 s
      if (pool.enter(entered, entry)) {
        EXPECT_TRUE(pool.present(entered));
        EXPECT_EQ(pool.lane(entered), entry);
        EXPECT_EQ(pool.speed(entered), 0.0);
        if (entered + 1 < pool.size()) {
          EXPECT_FALSE(pool.enter(entered + 1, entry)) << "two entries on one lane in a step";
        }
        ++entered;
      }
    }
    pool.step(0.05);
    for (size_t i = 0; i < entered; ++i) {
      if (pool.present(i)) {
        last[i] = pool.lane(i);
      } else if (last[i] != kNone) {
        EXPECT_EQ(last[i], exit) << "vehicle " << i << " left from another lane";
        last[i] = kNone;
        ++left;
      }
    }
    overlaps += pool.overlaps().size();
  }
  EXPECT_EQ(entered, pool.size());
  EXPECT_GT(left, 6u);
  EXPECT_EQ(pool.stats().respawns, 0u);
  EXPECT_EQ(overlaps, 0u);
}

TEST(PoolFlow, EnterWhilePresentOrOnAJunctionLaneThrows) {
  const PoolNetwork& net = city().pool;
  const auto [entry, exit] = entry_and_exit(net);
  ASSERT_NE(entry, kNone);
  Pool pool(net, flow_specs(2, net.lane(exit)));
  ASSERT_TRUE(pool.enter(0, entry));
  EXPECT_THROW(pool.enter(0, entry), PoolError);
  uint32_t in_junction = kNone;
  for (uint32_t l = 0; l < net.lanes().size() && in_junction == kNone; ++l) {
    if (net.lane(l).junction >= 0) in_junction = l;
  }
  ASSERT_NE(in_junction, kNone);
  EXPECT_THROW(pool.enter(1, in_junction), PoolError);
  EXPECT_FALSE(pool.present(1));
}

TEST(PoolFlow, NoPathToItsDestinationNamesTheRoadUser) {
  const PoolNetwork& net = city().pool;
  const auto [entry, exit] = entry_and_exit(net);
  std::vector<VehicleSpec> specs = flow_specs(1, net.lane(exit));
  specs[0].to = std::make_pair(std::string("no_such_road"), -1);
  Pool pool(net, specs);
  try {
    pool.enter(0, entry);
    ADD_FAILURE() << "no throw";
  } catch (const PoolError& e) {
    EXPECT_NE(std::string(e.what()).find("road user 'flow/0': no path from"), std::string::npos);
  }
  EXPECT_FALSE(pool.present(0));
}

}  // namespace
}  // namespace convoy::traffic_pool
