// Weather input (systems/weather_input.h): the weather engine's JSON is taken under its name
// and applied to the wheels and the wind; a bad one is an error naming engine, datapack and
// key; a reset keeps it.
#include "systems/weather_input.h"

#include "convoy/datapacks.pb.h"
#include "test_world.h"

namespace convoy::world {
namespace {

using namespace testing;

class WorldWeatherInput : public ::testing::Test {
 protected:
  void start(const nlohmann::json& config) {
    world_ = make_world(data_file("wheel_robot.sdf"));
    weather_ = &world_->add<WeatherInput>();
    world_->configure(config);
  }
  std::unique_ptr<WorldSystems> world_;
  WeatherInput* weather_ = nullptr;
};

TEST_F(WorldWeatherInput, TheWeatherIsAppliedToFrictionAndWind) {
  start(nlohmann::json::object());
  EXPECT_EQ(weather_->datapack_name(), "weather");
  EXPECT_FALSE(weather_->weather());
  send_json(*world_, "weather", {{"mu", 0.3}, {"wind", {0.0, 20.0}}});
  ASSERT_TRUE(weather_->weather());
  EXPECT_DOUBLE_EQ(weather_->weather()->mu, 0.3);
  world_->step(10 * kMs);
  // A side wind pushes the robot (a moving model with wheels) along +y.
  EXPECT_GT(world_->physics().wind_force(0).y(), 0);
  // After a reset the same weather holds on the new physics world.
  world_->reset();
  world_->step(10 * kMs);
  EXPECT_GT(world_->physics().wind_force(0).y(), 0);
}

TEST_F(WorldWeatherInput, ItsNameIsConfigurableAndOtherNamesAreNotTaken) {
  start({{"WeatherDataPack", "sky"}});
  EXPECT_EQ(error_of([&] {
              send_json(*world_, "weather", {{"mu", 0.3}});
            }),
            "engine 'test' has no writable datapack 'weather' (joint datapacks are <joint "
            "plugin>::<joint>)");
  send_json(*world_, "sky", {{"mu", 0.3}});
  EXPECT_TRUE(weather_->weather());
}

TEST_F(WorldWeatherInput, ABadWeatherDatapackIsAnErrorNamingTheKey) {
  start(nlohmann::json::object());
  const std::string bad_key = error_of([&] { send_json(*world_, "weather", {{"mu", "wet"}}); });
  EXPECT_EQ(bad_key.rfind("engine 'test': datapack 'weather': ", 0), 0u) << bad_key;
  EXPECT_NE(bad_key.find("mu"), std::string::npos) << bad_key;
  Sent proto("weather");
  data::Joint joint;  // a protobuf message: not the weather engine's JSON
  EXPECT_EQ(error_of([&] { world_->set_datapack(proto.proto(joint).view()); }),
            "engine 'test': datapack 'weather': expected the weather engine's JSON");
  EXPECT_FALSE(weather_->weather());
  // An empty one is ignored.
  Sent empty("weather");
  world_->set_datapack(empty.view());
  EXPECT_FALSE(weather_->weather());
}

}  // namespace
}  // namespace convoy::world
