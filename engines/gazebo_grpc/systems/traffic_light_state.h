// Traffic lights that show their state: the lamps of every signal model (a convoy_signal
// plugin, world_description.h's SignalDesc) look lit or dark in the cameras, as the
// traffic_lights engine's datapack says (docs/architecture.md, Traffic lights).
//
// Config key: TrafficLightsDataPack, the datapack's name (default "traffic_lights").
// Datapacks: <TrafficLightsDataPack>, JSON, written: {"signals": {<signal id>: "red" |
// "yellow" | "green" | "red_yellow" | "off"}, ...} (other keys ignored). An empty one is
// ignored; one that is not JSON, has no "signals" object or a state that is not a string is
// an error naming the engine and the datapack.
//
// Lit: the red lamp on red and red_yellow, the yellow lamp on yellow and red_yellow, the
// green lamp on green; a pedestrian light (red and green lamps) likewise. Everything is dark
// on "off", on a state it does not know and for a signal the datapack does not name (each
// warned once in the engine's log). Before any state arrives, and after a reset, the lights
// show red. A lit lamp glows in its colour (emissive, times its texture if it has one: a
// pedestrian light's figure); a dark one is a very dim grey of its colour. Ground truth is
// unchanged.
#pragma once

#include <set>
#include <string>
#include <vector>

#include "render/scene.h"
#include "world_system.h"

namespace convoy::world {

class TrafficLightState final : public WorldSystem {
 public:
  const char* name() const override { return "traffic_light_state"; }
  void configure(const WorldContext& ctx, const nlohmann::json& config) override;
  bool set_datapack(const datapack::View& dp) override;
  void reset() override;

  const std::string& datapack_name() const { return datapack_; }
  // Whether the `colour` lamp of signal model `model` is lit now (false: no such lamp).
  bool lit(const std::string& model, const std::string& colour) const;
  // The state signal `id` shows ("red" before any datapack; "" for an unknown id).
  std::string state(const std::string& id) const;

  // How lamps look (from the lamp's material as loaded: its texture and specular stay).
  static render::Material lit_look(render::Material m, const std::string& colour);
  static render::Material dark_look(render::Material m, const std::string& colour);
  // Whether the `colour` lamp is lit in `state`.
  static bool lit_in(const std::string& state, const std::string& colour);

 private:
  struct Lamp {
    std::string model, colour;
    size_t signal;                                        // in signals_
    std::vector<int> instances;                           // scene instances of its visual
    std::vector<render::Material> lit_looks, dark_looks;  // by instance
    int shown = -1;                                       // 1 lit, 0 dark, -1 as loaded
  };
  struct Signal {
    std::string id, state;
  };
  void find_lamps();
  void read_states(const std::string& dp_name, const nlohmann::json& signals);
  void warn_once(const std::string& key, const std::string& message);
  void apply();

  const WorldContext* ctx_ = nullptr;
  std::string datapack_ = "traffic_lights";
  std::vector<Signal> signals_;
  std::vector<Lamp> lamps_;
  std::set<std::string> warned_;
};

}  // namespace convoy::world
