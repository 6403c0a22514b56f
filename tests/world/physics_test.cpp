// Physics against analytic results: free fall, a pendulum's period, PID step responses,
// a wheeled robot's speed, determinism, and SDF error messages.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "joint_pid.h"
#include "physics_world.h"
#include "world_description.h"

namespace convoy::world {
namespace {

const std::string kData = CONVOY_TEST_DATA_DIR;

TEST(WorldDescription, ReadsModelsLinksJointsAndPlugins) {
  WorldDesc w = load_world(kData + "/physics_basics.sdf");
  EXPECT_NEAR(w.gravity.z(), -9.81, 1e-12);
  EXPECT_DOUBLE_EQ(w.max_step_size, 0.001);
  EXPECT_TRUE(w.world_plugin);
  ASSERT_EQ(w.models.size(), 2u);
  const ModelDesc& pend = w.models[1];
  ASSERT_EQ(pend.joints.size(), 1u);
  EXPECT_EQ(pend.joints[0].name, "pendulum::pivot");
  EXPECT_EQ(pend.joints[0].parent, "world");
  EXPECT_NEAR(pend.joints[0].pose.translation().z(), 2.0, 1e-12);  // 1 m above the bob
  EXPECT_NEAR(pend.links[0].pose.translation().z(), 1.0, 1e-12);
  ASSERT_EQ(pend.joint_plugins.size(), 1u);
  EXPECT_EQ(pend.joint_plugins[0].first, "pendulum_joint_plugin");
  EXPECT_EQ(w.models[0].link_plugins, std::vector<std::string>{"ball_link_plugin"});
}

TEST(Physics, FreeFallMatchesTheAnalyticResult) {
  PhysicsWorld p(load_world(kData + "/physics_basics.sdf"));
  int ball = p.link_index("ball::body");
  ASSERT_GE(ball, 0);
  for (int i = 0; i < 1000; ++i) p.step();
  LinkState s = p.link_state(ball);
  EXPECT_NEAR(s.linear_velocity.z(), -9.81, 1e-9);
  // z = z0 - g t^2 / 2, up to the semi-implicit Euler error g dt t / 2 (~5 mm)
  EXPECT_NEAR(s.position.z(), 100 - 0.5 * 9.81, 6e-3);
}

TEST(Physics, StaticSceneryFarAwayStillCollidesWhenABodyComesNear) {
  PhysicsWorld p(load_world(kData + "/static_scenery.sdf"));
  int dropped = p.link_index("dropped::body");
  int thrown = p.link_index("thrown::body");
  ASSERT_GE(dropped, 0);
  ASSERT_GE(thrown, 0);
  auto skel = p.dart_world()->getSkeleton("thrown");
  ASSERT_TRUE(skel);
  static_cast<dart::dynamics::FreeJoint*>(skel->getRootJoint())
      ->setLinearVelocity(Eigen::Vector3d(30, 0, 0));
  double max_x = 0;
  for (int i = 0; i < 3000; ++i) {
    p.step();
    max_x = std::max(max_x, p.link_state(thrown).position.x());
  }
  // The dropped ball rests on the pedestal (top at 1 m), not on the ground.
  EXPECT_NEAR(p.link_state(dropped).position.z(), 1.25, 0.01);
  // The thrown ball never passes the wall's near face (x = 59.5).
  EXPECT_LT(max_x, 59.5);
  EXPECT_GT(max_x, 59.0);  // it did reach the wall
}

TEST(Physics, PendulumPeriodMatchesTheAnalyticResult) {
  PhysicsWorld p(load_world(kData + "/physics_basics.sdf"));
  int pivot = p.joint_index("pendulum::pivot");
  ASSERT_GE(pivot, 0);
  p.set_joint_position(pivot, 0.05);  // small angle
  std::vector<double> crossings;
  double last = p.joint_state(pivot).position;
  for (int i = 0; i < 10000; ++i) {
    p.step();
    double now = p.joint_state(pivot).position;
    if (last > 0 && now <= 0) crossings.push_back(p.time() - p.step_size() * now / (now - last));
    last = now;
  }
  ASSERT_GE(crossings.size(), 3u);
  double period =
      (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
  double expected = 2 * M_PI * std::sqrt(1.0 / 9.81);
  EXPECT_NEAR(period, expected, 0.005 * expected);
}

TEST(Physics, PositionPidConvergesToItsTarget) {
  PhysicsWorld p(load_world(kData + "/physics_basics.sdf"));
  int pivot = p.joint_index("pendulum::pivot");
  JointPid pid(300, 300, 30, 100, -100);
  for (int i = 0; i < 10000; ++i) {
    double error = p.joint_state(pivot).position - 0.5;
    p.set_joint_effort(pivot, pid.update(error, p.step_size()));
    p.step();
  }
  EXPECT_NEAR(p.joint_state(pivot).position, 0.5, 2e-3);
  EXPECT_NEAR(p.joint_state(pivot).velocity, 0.0, 1e-2);
}

// Drives the four wheels at `omega` with the report's velocity PID (P = 10) for `seconds`.
LinkState drive(PhysicsWorld& p, double omega, double seconds, double* wheel_velocity) {
  std::vector<int> wheels;
  for (const char* j : {"robot::j_fl", "robot::j_fr", "robot::j_rl", "robot::j_rr"})
    wheels.push_back(p.joint_index(j));
  std::vector<JointPid> pids(4, JointPid(10, 0, 0, 0, 0));
  int steps = static_cast<int>(std::lround(seconds / p.step_size()));
  for (int i = 0; i < steps; ++i) {
    for (size_t w = 0; w < 4; ++w) {
      double error = p.joint_state(wheels[w]).velocity - omega;
      p.set_joint_effort(wheels[w], pids[w].update(error, p.step_size()));
    }
    p.step();
  }
  *wheel_velocity = p.joint_state(wheels[0]).velocity;
  return p.link_state(p.link_index("robot::chassis"));
}

TEST(Physics, VelocityPidAndWheelsMoveTheRobotAtOmegaTimesRadius) {
  PhysicsWorld p(load_world(kData + "/wheel_robot.sdf"));
  double wheel_velocity = 0;
  LinkState s = drive(p, 5.0, 4.0, &wheel_velocity);
  EXPECT_NEAR(wheel_velocity, 5.0, 0.02 * 5.0);
  double speed = s.linear_velocity.head<2>().norm();
  EXPECT_NEAR(speed, 5.0 * 0.1, 0.02 * 0.5);
  EXPECT_GT(s.position.x(), 1.0);          // forward
  EXPECT_NEAR(s.position.y(), 0.0, 0.05);  // straight
}

TEST(Physics, SameWorldGivesTheSameTrajectoryBitForBit) {
  auto run = [] {
    PhysicsWorld p(load_world(kData + "/wheel_robot.sdf"));
    double w = 0;
    LinkState s = drive(p, 3.0, 2.0, &w);
    return std::vector<double>{s.position.x(), s.position.y(), s.position.z(),
                               s.rotation.w(), s.rotation.z(), w};
  };
  EXPECT_EQ(run(), run());
}

TEST(WorldDescription, IncludeWithModelUriMeshesAndJointTypes) {
  setenv("CONVOY_MODEL_PATH", (kData + "/models").c_str(), 1);
  WorldDesc w = load_world(kData + "/include_world.sdf");
  ASSERT_EQ(w.models.size(), 2u);
  const ModelDesc& tower = w.models[1];
  EXPECT_EQ(tower.name, "tower_a");
  EXPECT_NEAR(tower.links[0].pose.translation().x(), 2.0, 1e-12);
  EXPECT_NEAR(tower.links[0].pose.translation().z(), 0.5, 1e-12);
  EXPECT_EQ(tower.links[0].collisions[0].shape.kind, Shape::kMesh);
  EXPECT_EQ(tower.links[0].collisions[0].shape.mesh.filename(), "block.obj");
  EXPECT_DOUBLE_EQ(tower.links[1].visuals[0].shape.scale.x(), 0.5);
  EXPECT_EQ(tower.joints[1].type, JointDesc::kBall);
  EXPECT_EQ(tower.joints[2].type, JointDesc::kUniversal);
  ASSERT_EQ(tower.joints[2].axes.size(), 2u);

  PhysicsWorld p(w);
  int lift = p.joint_index("tower_a::lift");
  ASSERT_GE(lift, 0);
  p.set_joint_effort(lift, 100.0);  // pushes up, against the 0.3 m limit
  for (int i = 0; i < 2000; ++i) p.step();
  EXPECT_NEAR(p.joint_state(lift).position, 0.3, 0.01);
  // the mesh block rests on the ground
  EXPECT_NEAR(p.link_state(p.link_index("tower_a::base")).position.z(), 0.5, 0.02);
}

TEST(Physics, JointsWithEqualLimitsHoldTheirChildAtTheLimit) {
  // As in Gazebo: a revolute (or prismatic) joint whose lower and upper limits are equal
  // cannot move, here a pendulum held 0.5 rad from the vertical and a slider held 0.2 m up.
  std::string file = ::testing::TempDir() + "/locked_joints.sdf";
  std::ofstream(file) << R"(<sdf version='1.7'><world name='w'>
    <model name='pendulum'><pose>0 0 2 0 0 0</pose>
      <link name='bob'><pose>0 0 -1 0 0 0</pose><inertial><mass>1</mass></inertial></link>
      <joint name='pivot' type='revolute'><parent>world</parent><child>bob</child>
        <pose>0 0 1 0 0 0</pose>
        <axis><xyz>0 1 0</xyz><limit><lower>0.5</lower><upper>0.5</upper></limit></axis></joint>
    </model>
    <model name='slider'><pose>5 0 1 0 0 0</pose>
      <link name='block'><inertial><mass>1</mass></inertial></link>
      <joint name='rail' type='prismatic'><parent>world</parent><child>block</child>
        <axis><xyz>0 0 1</xyz><limit><lower>0.2</lower><upper>0.2</upper></limit></axis></joint>
    </model></world></sdf>)";
  PhysicsWorld p(load_world(file));
  EXPECT_LT(p.joint_index("pendulum::pivot"), 0);  // no degree of freedom left
  for (int i = 0; i < 1000; ++i) p.step();
  // The bob hangs 1 m from the pivot at (0, 0, 2), turned 0.5 rad about +y.
  LinkState bob = p.link_state(p.link_index("pendulum::bob"));
  EXPECT_NEAR(bob.position.x(), -std::sin(0.5), 1e-9);
  EXPECT_NEAR(bob.position.z(), 2 - std::cos(0.5), 1e-9);
  EXPECT_NEAR(bob.linear_velocity.norm(), 0, 1e-9);
  LinkState block = p.link_state(p.link_index("slider::block"));
  EXPECT_NEAR(block.position.z(), 1.2, 1e-9);
  EXPECT_NEAR(block.linear_velocity.norm(), 0, 1e-9);
}

TEST(Physics, LinksJoinedByAFixedJointMoveAsOneRigidBody) {
  // A compound pendulum: a rod (1 kg, 0.5 m below the pivot) with a bob (1 kg, 1 m below,
  // its own moment 0.01 about y, tilted) fixed to it. DART steps the two links as one body;
  // the period must still be 2 pi sqrt(I / (m g d)), with I and d of both links together.
  std::string file = ::testing::TempDir() + "/fixed_links.sdf";
  std::ofstream(file) << R"(<sdf version='1.7'><world name='w'>
    <model name='pend'><pose>0 0 3 0 0 0</pose>
      <link name='rod'><pose>0 0 -0.5 0 0 0</pose><inertial><mass>1</mass>
        <inertia><ixx>1e-9</ixx><iyy>1e-9</iyy><izz>1e-9</izz></inertia></inertial></link>
      <link name='bob'><pose>0 0 -1 0.3 0 0.2</pose><inertial><mass>1</mass>
        <inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz></inertia></inertial></link>
      <joint name='pivot' type='revolute'><parent>world</parent><child>rod</child>
        <pose>0 0 0.5 0 0 0</pose><axis><xyz>0 1 0</xyz></axis></joint>
      <joint name='weld' type='fixed'><parent>rod</parent><child>bob</child></joint>
    </model></world></sdf>)";
  PhysicsWorld p(load_world(file));
  EXPECT_EQ(p.dart_world()->getSkeleton("pend")->getNumBodyNodes(), 1u);
  const int pivot = p.joint_index("pend::pivot"), bob = p.link_index("pend::bob");
  ASSERT_GE(pivot, 0);
  ASSERT_GE(bob, 0);
  EXPECT_NEAR(p.link_state(bob).position.z(), 2.0, 1e-12);
  EXPECT_NEAR(p.link_state(bob).rotation.angularDistance(
                  Eigen::Quaterniond(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()) *
                                     Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()))),
              0, 1e-12);
  p.set_joint_position(pivot, 0.02);
  std::vector<double> crossings;
  double last = p.joint_state(pivot).position, max_speed_error = 0;
  for (int i = 0; i < 10000; ++i) {
    p.step();
    JointState j = p.joint_state(pivot);
    // The bob's velocity is that of a point 1 m from the pivot turning at the joint's rate.
    max_speed_error = std::max(
        max_speed_error, std::abs(p.link_state(bob).linear_velocity.norm() - std::abs(j.velocity)));
    if (last > 0 && j.position <= 0)
      crossings.push_back(p.time() - p.step_size() * j.position / (j.position - last));
    last = j.position;
  }
  EXPECT_LT(max_speed_error, 1e-9);
  ASSERT_GE(crossings.size(), 3u);
  const double period =
      (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
  const double inertia = 1 * 0.25 + 1 * 1.0 + 0.01, mgd = 2 * 9.81 * 0.75;
  const double expected = 2 * M_PI * std::sqrt(inertia / mgd);
  EXPECT_NEAR(period, expected, 0.002 * expected);
}

std::string error_of(const std::string& sdf_text) {
  std::string file = ::testing::TempDir() + "/bad_world.sdf";
  std::ofstream(file) << sdf_text;
  try {
    load_world(file);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

TEST(WorldErrors, MissingFileBadXmlUnknownJointAndMeshAreNamed) {
  try {
    load_world("/nonexistent/world.sdf");
    FAIL();
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/world.sdf"), std::string::npos);
  }
  std::string bad_xml = error_of("<sdf version='1.7'><world name='w'><model name='m'>");
  EXPECT_NE(bad_xml.find("bad_world.sdf"), std::string::npos) << bad_xml;

  std::string unknown_joint = error_of(R"(<sdf version='1.7'><world name='w'>
    <model name='m'><link name='l'><inertial><mass>1</mass></inertial></link>
      <plugin name='jp' filename='NRPGazeboGrpcJointControllerPlugin.so'>
        <nope P='1' I='0' D='0' Type='position' Target='0' IMax='0' IMin='0'/>
      </plugin></model></world></sdf>)");
  EXPECT_NE(unknown_joint.find("bad_world.sdf"), std::string::npos) << unknown_joint;
  EXPECT_NE(unknown_joint.find("plugin 'jp'"), std::string::npos) << unknown_joint;
  EXPECT_NE(unknown_joint.find("unknown joint 'nope'"), std::string::npos) << unknown_joint;

  std::string missing_mesh = error_of(R"(<sdf version='1.7'><world name='w'>
    <model name='m'><link name='l'><visual name='v'><geometry><mesh><uri>model://nothing/car.dae</uri>
    </mesh></geometry></visual></link></model></world></sdf>)");
  EXPECT_NE(missing_mesh.find("model://nothing/car.dae"), std::string::npos) << missing_mesh;
  EXPECT_NE(missing_mesh.find("link 'm::l'"), std::string::npos) << missing_mesh;
}

}  // namespace
}  // namespace convoy::world

namespace convoy::world {
namespace {

// A heightmap collision (as convoy-odr world writes a hilly map's roads): a tilted plane of
// 11 x 11 samples over x in [0, 10], y in [-8, 2], z = 1 + 0.2 x + 0.1 (y + 8). Small balls
// dropped on it roll on its surface wherever they land (a box would slide and tip).
TEST(Physics, BallsRollOnTheSurfaceOfAHeightmap) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("convoy_heightmap_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  auto surface = [](double x, double y) { return 1 + 0.2 * x + 0.1 * (y + 8); };
  {
    std::ofstream pgm(dir / "ramp.pgm", std::ios::binary);
    pgm << "P5\n11 11\n65535\n";
    for (int r = 0; r < 11; ++r) {  // the first row is the largest y
      for (int c = 0; c < 11; ++c) {
        const double h = surface(c, 2 - r) - 1;  // 0 .. 3 above pos.z
        const auto v = static_cast<unsigned>(std::lround(h / 3.0 * 65535));
        pgm.put(static_cast<char>(v >> 8)).put(static_cast<char>(v & 0xff));
      }
    }
  }
  std::string boxes;
  const double at[3][2] = {{3, -5}, {8, 0}, {1, 1}};
  for (int i = 0; i < 3; ++i) {
    boxes += "<model name='box" + std::to_string(i) + "'><pose>" + std::to_string(at[i][0]) + " " +
             std::to_string(at[i][1]) +
             " 6 0 0 0</pose><link name='body'><inertial><mass>1</mass>"
             "</inertial><collision name='c'><geometry><sphere><radius>0.05</radius></sphere>"
             "</geometry></collision></link></model>";
  }
  {
    std::ofstream sdf(dir / "world.sdf");
    sdf << "<?xml version='1.0'?><sdf version='1.7'><world name='w'>"
           "<physics type='ode'><max_step_size>0.001</max_step_size></physics>"
           "<model name='ground'><static>true</static><link name='link'>"
           "<collision name='hm'><geometry><heightmap><uri>ramp.pgm</uri><size>10 10 3</size>"
           "<pos>5 -3 1</pos></heightmap></geometry></collision></link></model>"
        << boxes << "</world></sdf>";
  }
  const WorldDesc desc = load_world(dir / "world.sdf");
  EXPECT_TRUE(is_ground(desc.models[0]));  // no ground-truth box for it
  PhysicsWorld p(desc);
  for (int i = 0; i < 1500; ++i) p.step();  // fallen by 1.1 s, rolling since
  for (int i = 0; i < 3; ++i) {
    const LinkState s = p.link_state(p.link_index("box" + std::to_string(i) + "::body"));
    // the centre of a ball on a slope: its radius along the normal, 1.025 r above the surface
    EXPECT_NEAR(s.position.z(), surface(s.position.x(), s.position.y()) + 0.0512, 0.01)
        << "ball " << i << " at " << s.position.transpose();
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace convoy::world
