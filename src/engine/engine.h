// What an engine type implements, and how it registers itself.
//
// An engine is a simulator that advances in fixed steps of simulated time and exchanges
// datapacks with the coordinator. A new engine type is one class deriving from Engine plus
// one CONVOY_REGISTER_ENGINE line; convoy_add_engine() in CMake builds its server binary
// bin/convoy-engine-<type>.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "convoy/engine.pb.h"
#include "datapack/datapack.h"

namespace convoy::engines {

class Engine {
 public:
  virtual ~Engine() = default;

  // Start-up. `config` is the engine's object from the simulation config (paths absolute).
  // Returns the ids of the datapacks the engine provides.
  virtual std::vector<engine::DataPackId> initialize(const std::string& name,
                                                     const nlohmann::json& config,
                                                     int64_t timestep_ns) = 0;
  // Advances by `duration_ns`; returns the engine's time afterwards.
  virtual int64_t step(int64_t duration_ns) = 0;
  // Accepts a datapack sent by a transceiver function. Its blobs are read in place
  // (datapack/datapack.h): they stay valid until the end of the step that follows; an engine
  // that keeps them longer copies them.
  virtual void set_datapack(const datapack::View& datapack) = 0;
  // Fills `out` (whose id is set) with the datapack `id` through the codecs of src/datapack.
  // Leaves its payload unset (the empty datapack) for an id it does not know, or that has no
  // value yet.
  virtual void get_datapack(const engine::DataPackId& id, datapack::Builder& out) = 0;
  // True when datapack `id` has not changed since get_datapack last filled it (a camera
  // that has not rendered since): a step's reply may then leave it out, and the coordinator
  // keeps the one it has, as NRP-Core's camera controller returns no datapack between frames.
  virtual bool unchanged(const engine::DataPackId& id) { return false; }
  virtual void reset() {}
  virtual void shutdown() {}
  // Warnings of initialize (a broker that cannot be reached, say), each once: they go back in
  // the Initialize reply, and the coordinator shows them with the engine's name.
  virtual std::vector<std::string> take_warnings() { return {}; }
};

using EngineFactory = std::function<std::unique_ptr<Engine>()>;

// Registry of engine types linked into this binary.
bool register_engine(const std::string& type, EngineFactory factory);
std::unique_ptr<Engine> create_engine(const std::string& type);
std::vector<std::string> registered_engine_types();

}  // namespace convoy::engines

#define CONVOY_REGISTER_ENGINE(type_name, Class)                                           \
  static const bool convoy_engine_registered_##Class = ::convoy::engines::register_engine( \
      type_name,                                                                           \
      [] { return std::unique_ptr<::convoy::engines::Engine>(std::make_unique<Class>()); })
