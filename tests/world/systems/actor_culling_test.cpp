// Culling of actors (docs/road_users.md, Pooled road users): an actor the camera cannot see
// (behind it, beyond its far plane, beside its view) is not drawn and has no ground truth,
// one in view has; an actor far from every moving body is out of collision detection, one
// near it in, and the sweep that compares the actors' boxes finds every overlap.
#include <random>
#include <set>

#include "physics_world.h"
#include "systems/camera_datapacks.h"
#include "systems/contacts.h"
#include "systems/road_user_actors.h"
#include "test_world.h"

namespace convoy::world {
namespace {

using namespace testing;

class ActorCulling : public ::testing::Test {
 protected:
  void start() {
    world_ = make_world(data_file("actor_world.sdf"));  // camera at (-5, 0, 2) along +x
    actors_ = &world_->add<RoadUserActors>();
    world_->add<CameraDatapacks>();
    contacts_ = &world_->add<Contacts>();
    world_->configure(nlohmann::json::object());
  }
  static nlohmann::json car(const std::string& id, double x, double y) {
    return {{"id", id}, {"category", "car"}, {"x", x}, {"y", y}};
  }
  // The camera's ground truth (a new frame: 40 ms later) and what it drew.
  std::set<std::string> boxes() {
    world_->step(40 * kMs);
    std::set<std::string> out;
    const nlohmann::json got = Got(*world_, "rig_camera::cam::boxes").json();
    for (const auto& b : got["boxes"]) out.insert(b["model"].get<std::string>());
    return out;
  }
  int drawn() const { return world_->cameras().last_render_stats()->instances_drawn; }
  std::unique_ptr<WorldSystems> world_;
  RoadUserActors* actors_ = nullptr;
  Contacts* contacts_ = nullptr;
};

TEST_F(ActorCulling, OnlyAnActorInViewIsDrawnAndHasGroundTruth) {
  start();
  (void)boxes();  // the first frame: the ground alone
  const int ground = drawn();
  send_json(*world_, "traffic", car("seen", 10, 0));
  world_->step(20 * kMs);
  EXPECT_EQ(boxes(), std::set<std::string>{"seen"});
  const int with_seen = drawn();
  EXPECT_GT(with_seen, ground);
  // Behind the camera, beyond its far plane (100 m), beside its view (1.2 rad wide).
  send_json(
      *world_, "traffic",
      {{"users",
        {car("seen", 10, 0), car("behind", -20, 0), car("far", 99, -6), car("beside", 0, 30)}}});
  world_->step(20 * kMs);
  EXPECT_EQ(boxes(), std::set<std::string>{"seen"});
  EXPECT_EQ(drawn(), with_seen);
  for (const char* id : {"behind", "far", "beside"}) EXPECT_TRUE(actors_->actor(id)->present);
  // The far one comes within the far plane, the one beside into the view: both are seen.
  send_json(
      *world_, "traffic",
      {{"users",
        {car("seen", 10, 0), car("behind", -20, 0), car("far", 80, -6), car("beside", 40, 8)}}});
  world_->step(20 * kMs);
  EXPECT_EQ(boxes(), (std::set<std::string>{"seen", "far", "beside"}));
  EXPECT_GT(drawn(), with_seen);
}

TEST_F(ActorCulling, OnlyActorsNearAMovingBodyTakePartInCollisionDetection) {
  start();  // the robot (a moving body) stands at (0, -10)
  send_json(*world_, "traffic", {{"users", {car("near", 0, -12), car("away", 60, 40)}}});
  world_->step(20 * kMs);
  PhysicsWorld& physics = world_->physics();
  EXPECT_TRUE(physics.actor_colliding(actors_->actor("near")->physics));
  EXPECT_FALSE(physics.actor_colliding(actors_->actor("away")->physics));
  // Posed next to the robot, the one away is in at once; the other, gone, is out.
  send_json(*world_, "traffic",
            {{"users", {car("away", 0, -8), {{"id", "near"}, {"absent", true}}}}});
  world_->step(20 * kMs);
  EXPECT_TRUE(physics.actor_colliding(actors_->actor("away")->physics));
  EXPECT_FALSE(physics.actor_colliding(actors_->actor("near")->physics));
  // Onto the robot: the physics reports the contact.
  send_json(*world_, "traffic", car("away", 0, -10));
  world_->step(20 * kMs);
  ASSERT_FALSE(contacts_->records().empty());
  EXPECT_EQ(contacts_->records().back()["a"], "away");
}

TEST_F(ActorCulling, TheSweepFindsEveryOverlapOfManyActors) {
  start();
  // 300 cars in a 150 m square, the first step's apart (a grid), then moved at random:
  // the contacts the sweep finds are those of a test of every pair (circles of the boxes'
  // half diagonals overlapping on a common heading are overlaps of their boxes).
  nlohmann::json users = nlohmann::json::array();
  for (int i = 0; i < 300; ++i)
    users.push_back(car("c" + std::to_string(i), 20 + (i % 20) * 7.0, 20 + (i / 20) * 7.0));
  send_json(*world_, "traffic", {{"users", users}});
  world_->step(20 * kMs);
  EXPECT_TRUE(contacts_->records().empty());
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> at(20, 170);
  std::vector<std::pair<double, double>> xy;
  for (auto& u : users) {
    xy.emplace_back(at(rng), at(rng));
    u["x"] = xy.back().first;
    u["y"] = xy.back().second;
  }
  send_json(*world_, "traffic", {{"users", users}});
  world_->step(20 * kMs);
  // Same heading (yaw 0): two boxes overlap when |dx| < length and |dy| < width.
  const RoadUserActors::Actor* a0 = actors_->actor("c0");
  const double length = 2 * a0->half.x(), width = 2 * a0->half.y();
  std::set<std::pair<std::string, std::string>> expected, got;
  for (size_t i = 0; i < xy.size(); ++i)
    for (size_t j = i + 1; j < xy.size(); ++j)
      if (std::abs(xy[i].first - xy[j].first) < length &&
          std::abs(xy[i].second - xy[j].second) < width) {
        auto a = "c" + std::to_string(i), b = "c" + std::to_string(j);
        expected.insert(std::minmax(a, b));
      }
  for (const auto& r : contacts_->records())
    got.insert({r["a"].get<std::string>(), r["b"].get<std::string>()});
  EXPECT_FALSE(expected.empty());
  EXPECT_EQ(got, expected);
}

}  // namespace
}  // namespace convoy::world
