// The model plugins of an SDF world (world_plugins.h): each kind read into the ModelDesc, and
// their errors, which name the file, the model and the plugin.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sdf/sdf.hh>

#include "world_description.h"
#include "world_plugins.h"

namespace convoy::world {
namespace {

const std::filesystem::path kFile = "/worlds/plugins.sdf";

// A model 'm' with the joints j1 and j2 and a link l that shows lamp_red and lamp_green, and
// the element of an SDF model 'm' that has `plugins`.
class WorldPlugins : public ::testing::Test {
 protected:
  WorldPlugins() {
    model_.name = "m";
    for (const char* j : {"m::j1", "m::j2"}) {
      JointDesc jd;
      jd.name = j;
      model_.joints.push_back(jd);
    }
    LinkDesc l;
    l.name = "m::l";
    for (const char* v : {"lamp_red", "lamp_green"}) {
      VisualDesc vd;
      vd.name = v;
      l.visuals.push_back(vd);
    }
    model_.links.push_back(l);
  }

  sdf::ElementPtr element(const std::string& plugins) {
    const std::string text =
        "<?xml version='1.0'?><sdf version='1.7'><model name='m'><link name='l'/>" + plugins +
        "</model></sdf>";
    sdf::Errors errors = root_.LoadSdfString(text);
    EXPECT_TRUE(errors.empty()) << (errors.empty() ? "" : errors[0].Message());
    EXPECT_NE(root_.Model(), nullptr);
    return root_.Model() ? root_.Model()->Element() : sdf::ElementPtr();
  }

  // read_plugins' error for `plugins` ("" if none).
  std::string error_of(const std::string& plugins) {
    sdf::ElementPtr e = element(plugins);
    if (!e) return "no element";
    ModelDesc md = model_;
    try {
      read_plugins(e, "m", kFile, &md);
    } catch (const std::runtime_error& err) {
      return err.what();
    }
    return "";
  }

  sdf::Root root_;
  ModelDesc model_;
};

TEST_F(WorldPlugins, ReadsEveryKind) {
  sdf::ElementPtr e = element(
      "<plugin name='jp' filename='NRPGazeboGrpcJointControllerPlugin.so'>"
      "<j1 P='2' I='0.5' D='0.1' Type='velocity' Target='3' IMax='4' IMin='-4'/>"
      "<j2 P='1' Type='position'/></plugin>"
      "<plugin name='brakes' filename='ConvoyBrakePlugin.so'><abs>false</abs><slip>0.2</slip>"
      "<j1 MaxTorque='800'/><j2/></plugin>"
      "<plugin name='convoy_class' filename='convoy_class'><class>truck</class></plugin>"
      "<plugin name='convoy_signal' filename='convoy_signal'><signal>42</signal>"
      "<lamp colour='red'>lamp_red</lamp><lamp colour='green'>lamp_green</lamp></plugin>"
      "<plugin name='lp' filename='NRPGazeboGrpcLinkControllerPlugin.so'/>"
      "<plugin name='other' filename='SomethingElse.so'/>");
  ASSERT_TRUE(e);
  ModelDesc md = model_;
  read_plugins(e, "m", kFile, &md);

  ASSERT_EQ(md.joint_plugins.size(), 1u);
  EXPECT_EQ(md.joint_plugins[0].first, "jp");
  const auto& pids = md.joint_plugins[0].second;
  ASSERT_EQ(pids.size(), 2u);
  EXPECT_EQ(pids[0].joint, "m::j1");
  EXPECT_DOUBLE_EQ(pids[0].p, 2);
  EXPECT_DOUBLE_EQ(pids[0].i, 0.5);
  EXPECT_DOUBLE_EQ(pids[0].d, 0.1);
  EXPECT_DOUBLE_EQ(pids[0].target, 3);
  EXPECT_DOUBLE_EQ(pids[0].i_max, 4);
  EXPECT_DOUBLE_EQ(pids[0].i_min, -4);
  EXPECT_TRUE(pids[0].velocity);
  EXPECT_EQ(pids[1].joint, "m::j2");
  EXPECT_DOUBLE_EQ(pids[1].i, 0);  // absent: 0
  EXPECT_FALSE(pids[1].velocity);

  ASSERT_EQ(md.brake_plugins.size(), 1u);
  const BrakePluginDesc& bp = md.brake_plugins[0];
  EXPECT_EQ(bp.name, "brakes");
  EXPECT_FALSE(bp.abs);
  EXPECT_DOUBLE_EQ(bp.slip, 0.2);
  ASSERT_EQ(bp.brakes.size(), 2u);
  EXPECT_EQ(bp.brakes[0].joint, "m::j1");
  EXPECT_DOUBLE_EQ(bp.brakes[0].max_torque, 800);
  EXPECT_DOUBLE_EQ(bp.brakes[1].max_torque, 1500);  // the default

  EXPECT_EQ(md.cls, "truck");

  ASSERT_EQ(md.signals.size(), 1u);
  EXPECT_EQ(md.signals[0].id, "42");
  ASSERT_EQ(md.signals[0].lamps.size(), 2u);
  EXPECT_EQ(md.signals[0].lamps[0].colour, "red");
  EXPECT_EQ(md.signals[0].lamps[0].link, "m::l");
  EXPECT_EQ(md.signals[0].lamps[1].visual, "lamp_green");

  EXPECT_EQ(md.link_plugins, std::vector<std::string>{"lp"});
}

TEST_F(WorldPlugins, AModelWithoutPluginsIsUnchanged) {
  sdf::ElementPtr e = element("");
  ASSERT_TRUE(e);
  ModelDesc md = model_;
  read_plugins(e, "m", kFile, &md);
  EXPECT_TRUE(md.joint_plugins.empty());
  EXPECT_TRUE(md.brake_plugins.empty());
  EXPECT_TRUE(md.signals.empty());
  EXPECT_TRUE(md.link_plugins.empty());
  EXPECT_EQ(md.cls, "");
}

TEST_F(WorldPlugins, JointControllerErrorsNameFileModelPluginAndJoint) {
  const std::string jp = "<plugin name='jp' filename='NRPGazeboGrpcJointControllerPlugin.so'>";
  EXPECT_EQ(error_of(jp + "<nope P='1' Type='position'/></plugin>"),
            "/worlds/plugins.sdf: model 'm' plugin 'jp': unknown joint 'nope'");
  EXPECT_EQ(error_of(jp + "<j1 P='x' Type='position'/></plugin>"),
            "/worlds/plugins.sdf: model 'm' plugin 'jp': joint 'j1': P='x' is not a number");
  EXPECT_EQ(error_of(jp + "<j1 P='1' Type='torque'/></plugin>"),
            "/worlds/plugins.sdf: model 'm' plugin 'jp': joint 'j1': Type must be position or "
            "velocity, got 'torque'");
}

TEST_F(WorldPlugins, BrakePluginErrorsNameFileModelAndPlugin) {
  const std::string brakes = "<plugin name='brakes' filename='ConvoyBrakePlugin.so'>";
  const std::string where = "/worlds/plugins.sdf: model 'm' plugin 'brakes': ";
  EXPECT_EQ(error_of(brakes + "<slip>2</slip></plugin>"), where + "<slip> must be in (0, 1)");
  EXPECT_EQ(error_of(brakes + "<slip>0.1x</slip></plugin>"),
            where + "<slip> '0.1x' is not a number");
  EXPECT_EQ(error_of(brakes + "<abs>yes</abs></plugin>"),
            where + "<abs> must be true or false, got 'yes'");
  EXPECT_EQ(error_of(brakes + "<nope/></plugin>"), where + "unknown joint 'nope'");
  EXPECT_EQ(error_of(brakes + "<j1 MaxTorque='-5'/></plugin>"),
            where + "joint 'j1': MaxTorque must be > 0");
  EXPECT_EQ(error_of(brakes + "<j1 MaxTorque='inf'/></plugin>"),
            where + "joint 'j1': MaxTorque 'inf' is not a number");
}

TEST_F(WorldPlugins, AnUnknownClassIsAnError) {
  EXPECT_EQ(error_of("<plugin name='convoy_class' filename='convoy_class'><class>hatchback</class>"
                     "</plugin>"),
            "/worlds/plugins.sdf: model 'm' plugin 'convoy_class': <class> 'hatchback' is not one "
            "of car, truck, bus, pedestrian, cyclist, building, tree, shrub, pole, "
            "traffic_light, sign, barrier, other");
}

TEST_F(WorldPlugins, SignalErrorsNameFileModelAndPlugin) {
  const std::string signal = "<plugin name='convoy_signal' filename='convoy_signal'>";
  const std::string where = "/worlds/plugins.sdf: model 'm' plugin 'convoy_signal': ";
  EXPECT_EQ(error_of(signal + "<signal>1</signal><lamp colour='blue'>lamp_red</lamp></plugin>"),
            where + "<lamp> 'lamp_red': colour 'blue' is not one of red, yellow, green");
  EXPECT_EQ(error_of(signal + "<signal>1</signal><lamp colour='red'>lamp_red</lamp>"
                              "<lamp colour='red'>lamp_green</lamp></plugin>"),
            where + "two red lamps");
  EXPECT_EQ(error_of(signal + "<signal>1</signal><lamp colour='red'>lamp_x</lamp></plugin>"),
            where + "<lamp> 'lamp_x' is no visual of the model's links");
  EXPECT_EQ(error_of(signal + "<lamp colour='red'>lamp_red</lamp></plugin>"),
            where + "no <signal> id");
}

// Through load_world: the error names the world file.
TEST(WorldPluginsInAWorld, ABrakePluginErrorNamesTheWorldFile) {
  const std::filesystem::path file =
      std::filesystem::path(::testing::TempDir()) / "brake_slip_world.sdf";
  std::ofstream(file) << R"(<?xml version='1.0'?><sdf version='1.7'><world name='w'>
    <model name='car'><link name='l'><inertial><mass>1</mass></inertial></link>
      <plugin name='car_brakes' filename='ConvoyBrakePlugin.so'><slip>2</slip></plugin>
    </model></world></sdf>)";
  try {
    load_world(file);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), std::filesystem::absolute(file).string() +
                                         ": model 'car' plugin 'car_brakes': <slip> must be in "
                                         "(0, 1)");
  }
}

}  // namespace
}  // namespace convoy::world
