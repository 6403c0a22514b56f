// Traffic lights that show their state (systems/traffic_light_state.h): the convoy_signal
// plugin as parsed and cached, which lamps each state lights, how they look in the camera,
// the datapack's name and errors, and a reset.
#include "systems/traffic_light_state.h"

#include <array>

#include "datapack/camera.h"
#include "systems/camera_datapacks.h"
#include "test_world.h"
#include "world_cache.h"

namespace convoy::world {
namespace {

using namespace testing;

nlohmann::json lights(const std::string& vehicle, const std::string& pedestrian) {
  return {{"time_ns", 0}, {"signals", {{"7", vehicle}, {"8", pedestrian}}}, {"junctions", {}}};
}

class WorldTrafficLights : public ::testing::Test {
 protected:
  void start(const nlohmann::json& config = nlohmann::json::object()) {
    world_ = make_world(data_file("traffic_light_world.sdf"));
    lights_ = &world_->add<TrafficLightState>();
    world_->add<CameraDatapacks>();
    world_->configure(config);
  }
  // Which lamps are lit: signal 7's red, yellow, green, signal 8's red, green.
  std::array<bool, 5> lit() const {
    return {lights_->lit("signal_7", "red"), lights_->lit("signal_7", "yellow"),
            lights_->lit("signal_7", "green"), lights_->lit("signal_8", "red"),
            lights_->lit("signal_8", "green")};
  }
  // The mean RGB of a 3 x 3 patch of the camera's image about (u, v).
  std::array<double, 3> colour(int u, int v) {
    Got got(*world_, "rig_camera::cam");
    const auto image = datapack::read_camera(got.view());
    std::array<double, 3> sum{};
    for (int y = v - 1; y <= v + 1; ++y)
      for (int x = u - 1; x <= u + 1; ++x)
        for (int c = 0; c < 3; ++c)
          sum[c] += static_cast<uint8_t>(image.pixels[(y * image.width + x) * 3 + c]) / 9.0;
    return sum;
  }
  std::unique_ptr<WorldSystems> world_;
  TrafficLightState* lights_ = nullptr;
};

// The lamps' centres in the image: f = 160 / tan(0.4), the lamps' faces 7.82 m ahead.
constexpr int kRightU = 208, kLeftU = 112;  // signal 7 (1 m right), signal 8 (1 m left)
constexpr int kRedV = 105, kYellowV = 120, kGreenV = 135, kPedRedV = 119, kPedGreenV = 135;

TEST(WorldTrafficLightSignals, ThePluginIsParsedAndCached) {
  const WorldDesc w = load_world(data_file("traffic_light_world.sdf"));
  const ModelDesc& m = w.models[2];
  ASSERT_EQ(m.name, "signal_7");
  ASSERT_EQ(m.signals.size(), 1u);
  EXPECT_EQ(m.signals[0].id, "7");
  ASSERT_EQ(m.signals[0].lamps.size(), 3u);
  EXPECT_EQ(m.signals[0].lamps[0].colour, "green");
  EXPECT_EQ(m.signals[0].lamps[0].visual, "lamp_green");
  EXPECT_EQ(m.signals[0].lamps[0].link, "signal_7::link");
  EXPECT_EQ(class_of(m), "traffic_light");  // ground truth as before
  const WorldDesc again = deserialize_world(serialize_world(w));
  EXPECT_EQ(serialize_world(again), serialize_world(w));
  ASSERT_EQ(again.models[3].signals.size(), 1u);
  EXPECT_EQ(again.models[3].signals[0].id, "8");
  EXPECT_EQ(again.models[3].signals[0].lamps[1].link, "signal_8::link");
}

TEST(WorldTrafficLightSignals, ALampThatIsNoVisualOrHasAnUnknownColourIsAnError) {
  auto world = [](const std::string& plugin) {
    return "<?xml version='1.0'?><sdf version='1.7'><world name='w'><model name='tl'>"
           "<static>true</static><link name='link'><visual name='lamp_red'><geometry><box>"
           "<size>1 1 1</size></box></geometry></visual></link>"
           "<plugin name='convoy_signal' filename='convoy_signal'>" +
           plugin + "</plugin></model></world></sdf>";
  };
  const auto missing = write_world(world("<signal>3</signal><lamp colour='red'>lamp_x</lamp>"));
  EXPECT_EQ(error_of([&] { load_world(missing); }),
            missing.string() +
                ": model 'tl' plugin 'convoy_signal': <lamp> 'lamp_x' is no visual "
                "of the model's links");
  const auto colour = write_world(world("<signal>3</signal><lamp colour='blue'>lamp_red</lamp>"));
  EXPECT_EQ(error_of([&] { load_world(colour); }),
            colour.string() +
                ": model 'tl' plugin 'convoy_signal': <lamp> 'lamp_red': colour "
                "'blue' is not one of red, yellow, green");
  const auto no_id = write_world(world("<lamp colour='red'>lamp_red</lamp>"));
  EXPECT_EQ(error_of([&] { load_world(no_id); }),
            no_id.string() + ": model 'tl' plugin 'convoy_signal': no <signal> id");
}

TEST_F(WorldTrafficLights, BeforeAnyStateTheLightsShowRed) {
  start();
  EXPECT_EQ(lights_->datapack_name(), "traffic_lights");
  EXPECT_EQ(lights_->state("7"), "red");
  EXPECT_EQ(lit(), (std::array<bool, 5>{true, false, false, true, false}));
}

TEST_F(WorldTrafficLights, EachStateLightsItsLamps) {
  start();
  const struct {
    const char *vehicle, *pedestrian;
    std::array<bool, 5> lit;
  } cases[] = {
      {"green", "red", {false, false, true, true, false}},
      {"yellow", "red", {false, true, false, true, false}},
      {"red", "green", {true, false, false, false, true}},
      {"red_yellow", "red", {true, true, false, true, false}},
      {"off", "off", {false, false, false, false, false}},
      {"flashing", "green", {false, false, false, false, true}},  // unknown: dark
  };
  for (const auto& c : cases) {
    send_json(*world_, "traffic_lights", lights(c.vehicle, c.pedestrian));
    EXPECT_EQ(lit(), c.lit) << c.vehicle << " " << c.pedestrian;
    EXPECT_EQ(lights_->state("7"), c.vehicle);
  }
  // A signal the datapack does not name is dark.
  send_json(*world_, "traffic_lights", {{"signals", {{"8", "green"}}}});
  EXPECT_EQ(lit(), (std::array<bool, 5>{false, false, false, false, true}));
  EXPECT_EQ(lights_->state("7"), "");
}

TEST_F(WorldTrafficLights, TheCameraSeesALitLampBrightAndADarkOneDark) {
  start();
  send_json(*world_, "traffic_lights", lights("red", "green"));
  world_->step(10 * kMs);
  const auto red_on = colour(kRightU, kRedV), green_off = colour(kRightU, kGreenV);
  const auto ped_green_on = colour(kLeftU, kPedGreenV), ped_red_off = colour(kLeftU, kPedRedV);
  EXPECT_GT(red_on[0], 230);
  EXPECT_LT(red_on[1], 100);
  EXPECT_GT(ped_green_on[1], 230);
  EXPECT_LT(ped_green_on[0], 100);
  for (const auto& dark : {green_off, ped_red_off})
    for (double c : dark) EXPECT_LT(c, 60);
  send_json(*world_, "traffic_lights", lights("green", "red"));
  world_->step(10 * kMs);
  const auto red_off = colour(kRightU, kRedV), green_on = colour(kRightU, kGreenV);
  EXPECT_LT(red_off[0], 60);
  EXPECT_GT(green_on[1], 230);
  EXPECT_GT(colour(kLeftU, kPedRedV)[0], 230);
  // The yellow lamp stays dark in both.
  EXPECT_LT(colour(kRightU, kYellowV)[0], 60);
}

TEST_F(WorldTrafficLights, TheDatapacksNameIsConfigurableAndItIsTakenWithoutSignals) {
  start({{"TrafficLightsDataPack", "lights"}});
  send_json(*world_, "lights", lights("green", "green"));
  EXPECT_TRUE(lights_->lit("signal_7", "green"));
  EXPECT_EQ(error_of([&] { send_json(*world_, "traffic_lights", lights("red", "red")); }),
            "engine 'test' has no writable datapack 'traffic_lights' (joint datapacks are "
            "<joint plugin>::<joint>)");
  // A world without signals takes the datapack too (and ignores it).
  auto plain = make_world(data_file("wheel_robot.sdf"));
  plain->add<TrafficLightState>();
  plain->configure(nlohmann::json::object());
  send_json(*plain, "traffic_lights", lights("red", "red"));
}

TEST_F(WorldTrafficLights, AMalformedDatapackIsAnErrorNamingEngineAndDatapack) {
  start();
  const std::string format =
      "engine 'test': datapack 'traffic_lights': expected the traffic_lights engine's JSON "
      "{\"signals\": {<signal id>: \"red\" | \"yellow\" | \"green\" | \"red_yellow\" | \"off\"}}";
  EXPECT_EQ(error_of([&] { send_json(*world_, "traffic_lights", {{"7", "red"}}); }), format);
  EXPECT_EQ(error_of([&] { send_json(*world_, "traffic_lights", {{"signals", {1, 2}}}); }), format);
  EXPECT_EQ(error_of([&] {
              send_json(*world_, "traffic_lights", {{"signals", {{"7", 3}}}});
            }),
            "engine 'test': datapack 'traffic_lights': signal '7': the state must be a string, "
            "got 3");
  Sent empty("traffic_lights");  // ignored
  world_->set_datapack(empty.view());
  EXPECT_EQ(lights_->state("7"), "red");
}

TEST_F(WorldTrafficLights, ResetShowsRedAgain) {
  start();
  send_json(*world_, "traffic_lights", lights("green", "green"));
  world_->reset();
  EXPECT_EQ(lit(), (std::array<bool, 5>{true, false, false, true, false}));
  world_->step(10 * kMs);
  EXPECT_GT(colour(kRightU, kRedV)[0], 230);
  EXPECT_LT(colour(kRightU, kGreenV)[1], 60);
}

TEST(WorldTrafficLightLooks, LitGlowsInItsColourDarkIsDim) {
  render::Material lens;
  lens.diffuse = lens.ambient = {0.3f, 0.04f, 0.03f, 1};
  lens.texture = 2;
  const render::Material on = TrafficLightState::lit_look(lens, "red");
  EXPECT_GT(on.emissive[0], 0.9f);
  EXPECT_LT(on.emissive[1], 0.2f);
  EXPECT_TRUE(on.textured_emissive);  // a pictured lens: its picture glows
  EXPECT_EQ(on.texture, 2);
  const render::Material off = TrafficLightState::dark_look(lens, "red");
  EXPECT_EQ(off.emissive[0], 0.0f);
  for (int k = 0; k < 3; ++k) EXPECT_LT(off.diffuse[k], 0.12f);
  EXPECT_TRUE(TrafficLightState::lit_in("red_yellow", "yellow"));
  EXPECT_FALSE(TrafficLightState::lit_in("off", "red"));
}

}  // namespace
}  // namespace convoy::world
