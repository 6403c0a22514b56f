// gazebo_grpc (alias gazebo_json): the world engine. Loads an SDF world, simulates it with
// DART (Bullet collisions), renders its cameras and serves NRP-Core's Gazebo plugin
// datapacks. This file is the adapter between the Engine interface and the world's systems
// (world_system.h, world_systems.h): it loads the world, registers the systems, one line
// each, and forwards to them. Each system's header lists its config keys and datapacks.
//
// Config keys of the adapter: GazeboWorldFile, GazeboSDFModels [{Name, File, InitPose,
// InitSpeed}] (model_inserts.h), Sensors (LiDARs, IMUs, GNSS mounted by config:
// sensor_config.h), GazeboRNGSeed (the camera noise), WorldLoadTime (accepted;
// loading is synchronous), EngineTimestep. The systems, in registration order (the order of their
// calls):
//   weather              systems/weather_input.h        <WeatherDataPack> (JSON, written)
//   traffic_light_state  systems/traffic_light_state.h  <TrafficLightsDataPack> (JSON, written)
//   joint_controllers    systems/joint_controllers.h    <joint plugin>::<joint>, <model>::<joint>
//   initial_speeds       systems/initial_speeds.h       (none: GazeboSDFModels' InitSpeed)
//   brakes               systems/brakes.h               <brake plugin>::<joint>
//   link_states          systems/link_states.h          <link plugin>::<link>, <model>::<link>
//   actors               systems/road_user_actors.h     RoadUser(s) datapacks, any name
//   cameras              systems/camera_datapacks.h     <camera plugin>::<sensor>[::depth|...]
//   lidars               systems/lidar_sensors.h        <model>::<link>::<sensor> (PointCloud)
//   nav_sensors          systems/nav_sensors.h          <model>::<link>::<sensor> (Imu, NavSat)
//   ego_state            systems/ego_state.h            <model>::road_user
//   contacts             systems/contacts.h             collisions
#include <chrono>
#include <cstdio>
#include <memory>

#include "core/error.h"
#include "engine/engine.h"
#include "model_inserts.h"
#include "sensor_config.h"
#include "systems/brakes.h"
#include "systems/camera_datapacks.h"
#include "systems/contacts.h"
#include "systems/ego_state.h"
#include "systems/initial_speeds.h"
#include "systems/joint_controllers.h"
#include "systems/lidar_sensors.h"
#include "systems/link_states.h"
#include "systems/nav_sensors.h"
#include "systems/radar_sensors.h"
#include "systems/road_user_actors.h"
#include "systems/traffic_light_state.h"
#include "systems/weather_input.h"
#include "systems/wheel_odometry.h"
#include "world_cache.h"
#include "world_systems.h"

namespace convoy::engines {
namespace {

// The world file and the extra models (GazeboSDFModels), through the parsed-world cache;
// `log` gets what the load took.
world::WorldDesc load(const nlohmann::json& config, std::string* log) {
  std::filesystem::path file = config.value("GazeboWorldFile", "");
  if (file.empty()) throw std::runtime_error("GazeboWorldFile is not set");
  const std::vector<world::ModelInsert> extra = world::read_model_inserts(config);
  const auto t0 = std::chrono::steady_clock::now();
  world::CacheResult cache;
  world::WorldDesc desc = world::load_world_cached(file, extra, &cache);
  char text[512];
  std::snprintf(text, sizeof text, "world %s loaded in %.3f s (cache: %s, %s)",
                file.filename().c_str(),
                std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
                world::to_string(cache), world::cache_dir().c_str());
  *log = text;
  return desc;
}

class GazeboEngine final : public Engine {
 public:
  std::vector<engine::DataPackId> initialize(const std::string& name, const nlohmann::json& config,
                                             int64_t timestep_ns) override {
    std::string loaded;
    world::WorldDesc desc;
    try {  // the world file, its models and the config's sensors: the user's input (exit 2)
      desc = load(config, &loaded);
      world::mount_config_sensors(config, timestep_ns * 1e-9, &desc);  // "Sensors"
    } catch (const std::runtime_error& e) {
      throw UserError(e.what());
    }
    world_ = std::make_unique<world::WorldSystems>(std::move(desc),
                                                   config.value("GazeboRNGSeed", 0u), name);
    std::fprintf(stderr, "convoy: engine '%s': %s; physics %.3f s, cameras %.3f s\n", name.c_str(),
                 loaded.c_str(), world_->physics_s(), world_->cameras_s());
    world_->add<world::WeatherInput>();
    world_->add<world::TrafficLightState>();  // before the actors, which take any JSON
    world_->add<world::JointControllers>();
    world_->add<world::InitialSpeeds>();  // after the joint controllers: holds the wheels' spin
    world_->add<world::Brakes>();
    world_->add<world::LinkStates>();
    world_->add<world::RoadUserActors>();
    world_->add<world::CameraDatapacks>();
    world_->add<world::LidarSensors>();
    world_->add<world::NavSensors>();
    world_->add<world::RadarSensors>();
    world_->add<world::WheelOdometry>();
    world_->add<world::EgoState>();
    world_->add<world::Contacts>();
    std::vector<world::ProvidedDataPack> provided;
    try {  // the systems' config keys and the sensors' parameters: the user's input
      provided = world_->configure(config);
    } catch (const std::runtime_error& e) {
      throw UserError(e.what());
    }
    std::vector<engine::DataPackId> ids;
    for (const auto& p : provided) {
      engine::DataPackId& id = ids.emplace_back();
      id.set_name(p.name);
      id.set_engine_name(name);
      id.set_type(p.type);
    }
    return ids;
  }

  // The world as loaded: the models at their initial poses, the clock and the camera noise
  // from the start, each system back at its start (world_systems.h).
  void reset() override { world_->reset(); }
  int64_t step(int64_t duration_ns) override { return world_->step(duration_ns); }
  void set_datapack(const datapack::View& dp) override { world_->set_datapack(dp); }
  bool unchanged(const engine::DataPackId& id) override { return world_->unchanged(id.name()); }
  void get_datapack(const engine::DataPackId& id, datapack::Builder& out) override {
    world_->get_datapack(id.name(), out);
  }

 private:
  std::unique_ptr<world::WorldSystems> world_;
};

CONVOY_REGISTER_ENGINE("gazebo_grpc", GazeboEngine);

}  // namespace
}  // namespace convoy::engines
