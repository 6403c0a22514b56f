// Brakes and ABS (systems/brakes.h): a braked car slows down; with ABS its wheels keep
// turning with their slip near the target, without they lock; the brake datapacks.
#include "systems/brakes.h"

#include <cmath>

#include "convoy/datapacks.pb.h"
#include "systems/joint_controllers.h"
#include "test_world.h"

namespace convoy::world {
namespace {

using namespace testing;

// A 300 kg car on flat ground (tyres r 0.3 m, I 0.675 kg m^2, as the smart car's), brakes
// on its four wheels, a velocity controller on its rear wheels.
std::string car_world(bool abs) {
  std::string wheels, joints, brakes;
  const char* names[4] = {"fl", "fr", "rl", "rr"};
  const double xs[4] = {1.2, 1.2, -1.2, -1.2}, ys[4] = {0.8, -0.8, 0.8, -0.8};
  for (int i = 0; i < 4; ++i) {
    const std::string n = names[i];
    wheels += "<link name='wheel_" + n + "'><pose>" + std::to_string(xs[i]) + " " +
              std::to_string(ys[i]) +
              " 0.3 -1.5708 0 0</pose><inertial><mass>15</mass><inertia><ixx>0.39</ixx>"
              "<iyy>0.39</iyy><izz>0.675</izz><ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia>"
              "</inertial><collision name='c'><geometry><cylinder><radius>0.3</radius>"
              "<length>0.2</length></cylinder></geometry></collision></link>";
    joints += "<joint name='j_" + n + "' type='continuous'><parent>body</parent><child>wheel_" + n +
              "</child><axis><xyz>0 0 1</xyz></axis></joint>";
    brakes += "<j_" + n + " MaxTorque='1500'/>";
  }
  return "<?xml version='1.0'?><sdf version='1.7'><world name='w'>"
         "<physics type='ode'><max_step_size>0.001</max_step_size></physics>"
         "<model name='ground'><static>true</static><link name='link'><collision name='c'>"
         "<geometry><plane><normal>0 0 1</normal><size>500 500</size></plane></geometry>"
         "</collision></link></model>"
         "<model name='car'><pose>0 0 0 0 0 0</pose><link name='body'><pose>0 0 0.6 0 0 0</pose>"
         "<inertial><mass>300</mass><inertia><ixx>35</ixx><iyy>110</iyy><izz>130</izz>"
         "<ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial><collision name='c'>"
         "<geometry><box><size>3 1.4 0.4</size></box></geometry></collision></link>" +
         wheels + joints +
         "<plugin name='car_joints' filename='NRPGazeboGrpcJointControllerPlugin.so'>"
         "<j_rl P='10' I='0' D='0' Type='velocity' Target='0' IMax='0' IMin='0'/>"
         "<j_rr P='10' I='0' D='0' Type='velocity' Target='0' IMax='0' IMin='0'/></plugin>"
         "<plugin name='car_brakes' filename='ConvoyBrakePlugin.so'><abs>" +
         (abs ? "true" : "false") + "</abs><slip>0.15</slip>" + brakes +
         "</plugin></model></world></sdf>";
}

class WorldBrakes : public ::testing::Test {
 protected:
  void start(bool abs) {
    world_ = make_world(write_world(car_world(abs)));
    joints_ = &world_->add<JointControllers>();
    brakes_ = &world_->add<Brakes>();
    provided_ = world_->configure(nlohmann::json::object());
    world_->step(200 * kMs);  // settle on the tyres
    // Rolling at 15 m/s: the body moving, each wheel spinning at v / r about +y.
    auto skel = world_->physics().dart_world()->getSkeleton("car");
    static_cast<dart::dynamics::FreeJoint*>(skel->getRootJoint())
        ->setLinearVelocity(Eigen::Vector3d(15, 0, 0));
    for (const char* j : {"car::j_fl", "car::j_fr", "car::j_rl", "car::j_rr"})
      world_->physics()
          .joint_child(world_->physics().joint_index(j))
          ->getParentJoint()
          ->setVelocity(0, 15 / 0.3);
    for (const char* j : {"car_joints::j_rl", "car_joints::j_rr"}) {
      data::Joint target;
      target.set_velocity(15 / 0.3);
      send_proto(*world_, j, target);
    }
  }
  void brake(double torque) {
    for (const char* j :
         {"car_brakes::j_fl", "car_brakes::j_fr", "car_brakes::j_rl", "car_brakes::j_rr"}) {
      data::Joint command;
      command.set_effort(static_cast<float>(torque));
      send_proto(*world_, j, command);
    }
  }
  double speed() {
    return world_->physics()
        .link_state(world_->physics().link_index("car::body"))
        .linear_velocity.x();
  }
  double spin(const char* joint) {
    return world_->physics().joint_state(world_->physics().joint_index(joint)).velocity;
  }
  std::unique_ptr<WorldSystems> world_;
  JointControllers* joints_ = nullptr;
  Brakes* brakes_ = nullptr;
  std::vector<ProvidedDataPack> provided_;
};

TEST_F(WorldBrakes, ProvidesOneJointDatapackPerBrakedWheelAfterTheModelsJoints) {
  start(true);
  // The car's joint controllers first (model by model, registration order), then its brakes.
  EXPECT_EQ(names(provided_),
            (std::vector<std::string>{"car_joints::j_rl", "car::j_rl", "car_joints::j_rr",
                                      "car::j_rr", "car_brakes::j_fl", "car_brakes::j_fr",
                                      "car_brakes::j_rl", "car_brakes::j_rr"}));
  EXPECT_EQ(provided_[4].type, "convoy.data.Joint");
  EXPECT_EQ(provided_[4].model, 1);
}

TEST_F(WorldBrakes, AbsStopsTheCarWithTheWheelsTurningAndTheSlipNearItsTarget) {
  start(true);
  const double v0 = speed();
  EXPECT_GT(v0, 14.5);
  brake(1500);
  // After the first half second of braking (the PI controller finds the grip: 1500 Nm at
  // once briefly locks the wheel), the slip stays near <slip> and no wheel locks.
  double slip_sum = 0;
  int samples = 0, locked = 0;
  const int64_t pressed = world_->context().time_ns;
  while (speed() > 3) {
    world_->step(5 * kMs);
    const double v = speed(), w = spin("car::j_fl");
    if (v > 3 && world_->context().time_ns - pressed > 500 * kMs) {
      slip_sum += (v - w * 0.3) / v;
      ++samples;
      locked += w < 0.05 * v / 0.3;
    }
    ASSERT_LT(world_->context().time_ns, 10'000 * kMs) << "the car does not stop";
  }
  ASSERT_GT(samples, 50);
  EXPECT_EQ(locked, 0);
  EXPECT_NEAR(slip_sum / samples, 0.15, 0.08);  // (locked: 1)
  // The ABS applies less than the command while it holds the slip; the datapack says so.
  const double applied = brakes_->applied("car_brakes::j_fl");
  EXPECT_GT(applied, 0);
  EXPECT_LT(applied, 1500);
  EXPECT_FLOAT_EQ(Got(*world_, "car_brakes::j_fl").proto<data::Joint>().effort(), applied);
  // Deceleration near mu g (DART's friction 1 for the tyres and the plane).
  const double t = static_cast<double>(world_->context().time_ns - pressed) * 1e-9;
  EXPECT_GT((v0 - speed()) / t, 0.7 * 9.81);
}

TEST_F(WorldBrakes, WithoutAbsTheWheelsLock) {
  start(false);
  brake(1500);
  world_->step(300 * kMs);
  EXPECT_GT(speed(), 5);
  EXPECT_LT(std::abs(spin("car::j_fl")), 0.5);  // rad/s: locked while the car slides
  EXPECT_DOUBLE_EQ(brakes_->applied("car_brakes::j_fl"), 1500);
}

TEST_F(WorldBrakes, ABrakingWheelsControllerIsIdleAndACommandIsClamped) {
  start(true);
  EXPECT_FALSE(brakes_->braking(world_->physics().joint_index("car::j_rl")));
  brake(5000);
  EXPECT_TRUE(brakes_->braking(world_->physics().joint_index("car::j_rl")));
  world_->step(1 * kMs);
  // No effort from the rear wheels' velocity controller while they brake.
  EXPECT_EQ(world_->physics().joint_state(world_->physics().joint_index("car::j_rl")).effort, 0);
  EXPECT_LE(brakes_->applied("car_brakes::j_rl"), 1500);  // MaxTorque
  brake(0);
  world_->step(1 * kMs);
  EXPECT_FALSE(brakes_->braking(world_->physics().joint_index("car::j_rl")));
  EXPECT_EQ(brakes_->applied("car_brakes::j_rl"), 0);
}

TEST_F(WorldBrakes, ANegativeTorqueOrAnotherTypeIsAnError) {
  start(true);
  data::Joint command;
  command.set_effort(-1);
  EXPECT_EQ(error_of([&] { send_proto(*world_, "car_brakes::j_fl", command); }),
            "engine 'test': datapack 'car_brakes::j_fl': the brake torque (effort) must be >= 0 "
            "Nm, got -1.000000");
  EXPECT_EQ(error_of([&] {
              send_json(*world_, "car_brakes::j_fl", {{"effort", 1}});
            }),
            "datapack 'car_brakes::j_fl' must be a GazeboJointDataPack");
}

TEST_F(WorldBrakes, ResetReleasesTheBrakes) {
  start(true);
  brake(1500);
  world_->step(50 * kMs);
  world_->reset();
  EXPECT_FALSE(brakes_->braking(world_->physics().joint_index("car::j_fl")));
  EXPECT_EQ(brakes_->applied("car_brakes::j_fl"), 0);
  EXPECT_EQ(world_->context().time_ns, 0);
}

}  // namespace
}  // namespace convoy::world
