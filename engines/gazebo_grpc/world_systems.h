// The world as the engine runs it: the description, the physics world and the cameras made
// from it, the clock, and the registered systems (world_system.h), each call made on every
// system in registration order. The engine (gazebo_engine.cpp) is a thin adapter around one;
// tests run one in-process with the systems they test.
//
//   WorldSystems world(load_world("w.sdf"), /*seed=*/0, "gazebo");
//   auto& brakes = world.add<Brakes>();
//   world.configure(config);           // the datapacks the systems provide
//   world.set_datapack(view);          // the first system that takes it
//   world.step(20'000'000);            // 20 ms: before_step, 20 x (pre_update, update,
//                                      // physics step, post_update), after_step
#pragma once

#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <unordered_map>
#include <vector>

#include "camera_sensors.h"
#include "physics_world.h"
#include "world_description.h"
#include "world_system.h"

namespace convoy::world {

class WorldSystems {
 public:
  // Makes the physics world and the cameras (their noise from `seed`); `engine` names the
  // engine in messages.
  WorldSystems(WorldDesc desc, uint64_t seed, const std::string& engine);
  WorldSystems(const WorldSystems&) = delete;
  WorldSystems& operator=(const WorldSystems&) = delete;

  // Registers a system (before configure()); its calls come after those registered before.
  template <typename System>
  System& add() {
    systems_.push_back(std::make_unique<System>());
    return static_cast<System&>(*systems_.back());
  }
  // Configures every system; returns the datapacks they provide: the models' model by model
  // (as NRP lists its plugins'), then the world's, each in registration order.
  std::vector<ProvidedDataPack> configure(const nlohmann::json& config);

  // Advances the clock by `duration_ns` and the physics by as many steps as keep its clock
  // within half a step of it; returns the time.
  int64_t step(int64_t duration_ns);
  // Gives a datapack to the first system that takes it; throws if none does.
  void set_datapack(const datapack::View& dp);
  // The datapack `name` from the first system that provides it (left empty if none does).
  void get_datapack(const std::string& name, datapack::Builder& out);
  bool unchanged(const std::string& name);
  // The world as loaded: the physics and cameras made again (mesh files, the renderer and
  // the cameras' noise tables kept from before: the same, and costly to make), the clock at
  // 0, every system reset.
  void reset();

  const WorldContext& context() const { return ctx_; }
  PhysicsWorld& physics() { return *physics_; }
  CameraSensors& cameras() { return *cameras_; }
  // Seconds it took to make the physics world and the cameras.
  double physics_s() const { return physics_s_; }
  double cameras_s() const { return cameras_s_; }

 private:
  void make_world();

  WorldDesc desc_;
  uint64_t seed_;
  std::unique_ptr<PhysicsWorld> physics_;
  std::unique_ptr<CameraSensors> cameras_;
  render::MeshFileCache mesh_files_;  // read once for every world made again
  WorldContext ctx_;
  std::vector<std::unique_ptr<WorldSystem>> systems_;
  std::unordered_map<std::string, WorldSystem*> provider_;  // datapack name -> system
  int64_t physics_steps_ = 0;
  double physics_s_ = 0, cameras_s_ = 0;
};

}  // namespace convoy::world
