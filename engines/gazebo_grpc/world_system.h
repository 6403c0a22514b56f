// A world system: one capability of the world engine (joint controllers, brakes, actors,
// contacts...), behind one small interface, as gz-sim's System.hh splits a simulator into
// ISystemConfigure / ISystemPreUpdate / ISystemUpdate / ISystemPostUpdate.
//
// The engine (gazebo_engine.cpp) owns the world (the immutable WorldDesc, the PhysicsWorld,
// the CameraSensors and the clock), hands it to every system through a WorldContext, and
// calls the systems in their registration order:
//
//   initialize  configure(ctx, config) for each system; then provides() of each: the
//               engine's datapack list (a model's datapacks model by model, see ModelOf).
//   set_datapack  set_datapack(dp) of each system until one returns true (it is that
//               system's; a bad one throws); none: an error naming the engine and datapack.
//   get_datapack  get_datapack() of the system that provides the name (the first one).
//   step        before_step() once; then for each physics step pre_update(dt), update(dt),
//               the physics step, post_update(dt); then after_step() once.
//   reset       the engine makes the physics world and the cameras again from the
//               description and sets the clock to 0; then reset() of each system.
//
// A system that needs another (joint controllers ask the brakes which wheels brake) finds
// it with ctx.find<T>() in configure(). Registration order is part of the behaviour: it is
// the order of the calls above.
#pragma once

#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "datapack/datapack.h"

namespace convoy::world {

class CameraSensors;
class PhysicsWorld;
class WorldSystem;
struct WorldDesc;

// What every system sees of the world. The engine keeps it up to date: `physics` and
// `cameras` are made again by a reset, so systems go through the context, never keep them.
struct WorldContext {
  std::string engine;               // the engine's name, for messages
  const WorldDesc* desc = nullptr;  // immutable
  PhysicsWorld* physics = nullptr;
  CameraSensors* cameras = nullptr;  // never null (a world without cameras has no renderer)
  int64_t time_ns = 0;               // the engine's time: during a step, the step's end
  const std::vector<std::unique_ptr<WorldSystem>>* systems = nullptr;

  double time_s() const { return static_cast<double>(time_ns) * 1e-9; }
  // "engine 'NAME': datapack 'DATAPACK': ", the start of a message about a datapack.
  std::string where(const std::string& datapack) const {
    return "engine '" + engine + "': datapack '" + datapack + "': ";
  }
  // Another registered system of type T, or null.
  template <typename T>
  T* find() const {
    if (systems)
      for (const auto& s : *systems)
        if (auto* t = dynamic_cast<T*>(s.get())) return t;
    return nullptr;
  }
};

// A datapack a system provides: its name, its type (a protobuf type name or "json"), and
// the index of the model it belongs to in WorldDesc::models (-1: the world's). The engine
// lists a model's datapacks model by model, as NRP's Gazebo lists its plugins', then the
// world's, each in registration order.
struct ProvidedDataPack {
  std::string name, type;
  int model = -1;
};

class WorldSystem {
 public:
  virtual ~WorldSystem() = default;
  // A short name for messages and tests ("brakes", "actors").
  virtual const char* name() const = 0;

  // Start-up: reads the system's config keys and finds what it acts on. `ctx` outlives the
  // system. Throws std::runtime_error naming the key, model or plugin.
  virtual void configure(const WorldContext& ctx, const nlohmann::json& config) = 0;
  // The datapacks it serves through get_datapack (after configure).
  virtual std::vector<ProvidedDataPack> provides() const { return {}; }

  // A datapack sent to the engine: true if it is this system's (then taken). Throws
  // std::runtime_error (starting with ctx.where()) for one of its own that is malformed.
  virtual bool set_datapack(const datapack::View& dp) { return false; }
  // Fills `out` with datapack `name`, one of provides(); leaves it empty for none yet.
  virtual void get_datapack(const std::string& name, datapack::Builder& out) {}
  // True while datapack `name` has not changed since get_datapack last filled it.
  virtual bool unchanged(const std::string& name) { return false; }

  // Once per engine step, before its physics steps (ctx.time_ns is already the step's end).
  virtual void before_step() {}
  // Each physics step of `dt` seconds: pre_update, then update, then the step, post_update.
  virtual void pre_update(double dt) {}
  virtual void update(double dt) {}
  virtual void post_update(double dt) {}
  // Once per engine step, after its physics steps.
  virtual void after_step() {}

  // Back to the state after configure, on the new physics world and cameras of the context.
  virtual void reset() {}
};

}  // namespace convoy::world
