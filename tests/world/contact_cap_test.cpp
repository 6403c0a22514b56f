// SDF <max_contacts> (engines/gazebo_grpc/contact_cap.h): contacts per pair of collision
// shapes bounded by the world's <physics> and each collision's value, the deepest kept; worlds
// that set none keep every contact Bullet finds.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "physics_world.h"
#include "world_description.h"

namespace convoy::world {
namespace {

namespace fs = std::filesystem;

// A world with a ground plane and a wheel (the smart car's: a cylinder of radius 0.3 m and
// width 0.2 m, lying on its side) resting on it; `physics` and `collision` are put into the
// <physics> element and the wheel's <collision>.
fs::path box_world(const std::string& name, const std::string& physics,
                   const std::string& collision) {
  const fs::path file = fs::temp_directory_path() /
                        ("convoy_contact_cap_" + name + "_" + std::to_string(::getpid()) + ".sdf");
  std::ofstream(file) << R"(<?xml version="1.0"?>
<sdf version="1.7"><world name="w">
  <physics type="ode"><max_step_size>0.001</max_step_size>)"
                      << physics << R"(</physics>
  <model name="ground"><static>true</static><link name="l">
    <collision name="c"><geometry><plane><normal>0 0 1</normal><size>100 100</size></plane></geometry></collision>
  </link></model>
  <model name="box"><pose>0 0 0.3 1.5707963 0 0</pose><link name="body">
    <inertial><mass>1</mass><inertia><ixx>0.03</ixx><iyy>0.03</iyy><izz>0.045</izz></inertia></inertial>
    <collision name="c"><geometry><cylinder><radius>0.3</radius><length>0.2</length></cylinder></geometry>)"
                      << collision << R"(</collision>
  </link></model>
</world></sdf>)";
  return file;
}

struct Rest {
  size_t contacts;
  double z;
};

Rest settle(const fs::path& file) {
  PhysicsWorld p(load_world(file));
  fs::remove(file);
  for (int i = 0; i < 300; ++i) p.step();
  return {p.dart_world()->getLastCollisionResult().getNumContacts(),
          p.link_state(p.link_index("box::body")).position.z()};
}

TEST(ContactCap, WithoutMaxContactsEveryContactStays) {
  const Rest r = settle(box_world("none", "", ""));
  EXPECT_GE(r.contacts, 2u);  // Bullet's points across the tyre's width
  EXPECT_NEAR(r.z, 0.3, 0.01);
}

TEST(ContactCap, TheWorldsMaxContactsBoundsEachPair) {
  const Rest r = settle(box_world("world", "<max_contacts>1</max_contacts>", ""));
  EXPECT_EQ(r.contacts, 1u);
  EXPECT_NEAR(r.z, 0.3, 0.01);  // one point still holds the wheel up
}

TEST(ContactCap, ACollisionsMaxContactsBoundsItsPairsAndTheLeastBoundApplies) {
  const Rest one = settle(box_world("collision", "", "<max_contacts>1</max_contacts>"));
  EXPECT_EQ(one.contacts, 1u);
  const Rest least = settle(
      box_world("least", "<max_contacts>5</max_contacts>", "<max_contacts>1</max_contacts>"));
  EXPECT_EQ(least.contacts, 1u);
  const Rest world_least = settle(
      box_world("world_least", "<max_contacts>1</max_contacts>", "<max_contacts>5</max_contacts>"));
  EXPECT_EQ(world_least.contacts, 1u);
}

TEST(ContactCap, ZeroKeepsEveryContact) {
  const Rest r = settle(box_world("zero", "<max_contacts>0</max_contacts>", ""));
  EXPECT_GE(r.contacts, 2u);
}

TEST(ContactCap, ReadFromTheSdfAndANegativeValueNamesFileAndCollision) {
  const fs::path ok =
      box_world("read", "<max_contacts>4</max_contacts>", "<max_contacts>2</max_contacts>");
  const WorldDesc w = load_world(ok);
  fs::remove(ok);
  EXPECT_EQ(w.max_contacts, 4);
  EXPECT_EQ(w.models[1].links[0].collisions[0].max_contacts, 2);
  EXPECT_EQ(w.models[0].links[0].collisions[0].max_contacts, 0);  // not set
  const fs::path bad = box_world("bad", "", "<max_contacts>-1</max_contacts>");
  try {
    load_world(bad);
    ADD_FAILURE() << "a negative <max_contacts> was accepted";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(bad.string()), std::string::npos) << what;
    EXPECT_NE(what.find("collision 'c'"), std::string::npos) << what;
    EXPECT_NE(what.find("<max_contacts> is -1"), std::string::npos) << what;
  }
  fs::remove(bad);
}

}  // namespace
}  // namespace convoy::world
