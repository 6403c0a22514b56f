#include "systems/traffic_light_state.h"

#include <cstdio>
#include <map>
#include <stdexcept>

#include "camera_sensors.h"
#include "datapack/json.h"
#include "world_description.h"

namespace convoy::world {
namespace {

const char* const kInitialState = "red";
const char* const kFormat =
    R"(expected the traffic_lights engine's JSON {"signals": {<signal id>: "red" | "yellow" | )"
    R"("green" | "red_yellow" | "off"}})";

bool known_state(const std::string& s) {
  return s == "red" || s == "yellow" || s == "green" || s == "red_yellow" || s == "off";
}

// A lit lamp's colour (linear RGB).
render::Rgba glow(const std::string& colour) {
  if (colour == "red") return {1.0f, 0.12f, 0.04f, 1.0f};
  if (colour == "yellow") return {1.0f, 0.66f, 0.04f, 1.0f};
  return {0.08f, 1.0f, 0.5f, 1.0f};  // green
}

}  // namespace

render::Material TrafficLightState::lit_look(render::Material m, const std::string& colour) {
  m.emissive = glow(colour);
  m.textured_emissive = m.texture >= 0;  // a pictured lens: the picture glows
  return m;
}

render::Material TrafficLightState::dark_look(render::Material m, const std::string& colour) {
  const render::Rgba c = glow(colour);
  for (int k = 0; k < 3; ++k) m.diffuse[k] = m.ambient[k] = 0.05f + 0.06f * c[k];
  m.emissive = {0, 0, 0, 0};
  m.textured_emissive = false;
  return m;
}

bool TrafficLightState::lit_in(const std::string& state, const std::string& colour) {
  if (colour == "red") return state == "red" || state == "red_yellow";
  if (colour == "yellow") return state == "yellow" || state == "red_yellow";
  return colour == "green" && state == "green";
}

void TrafficLightState::configure(const WorldContext& ctx, const nlohmann::json& config) {
  ctx_ = &ctx;
  datapack_ = config.value("TrafficLightsDataPack", std::string("traffic_lights"));
  find_lamps();
  apply();
}

void TrafficLightState::reset() {
  find_lamps();  // on the new cameras
  apply();
}

void TrafficLightState::find_lamps() {
  signals_.clear();
  lamps_.clear();
  std::map<std::string, size_t> index;
  for (const auto& model : ctx_->desc->models) {
    for (const auto& s : model.signals) {
      auto [it, fresh] = index.try_emplace(s.id, signals_.size());
      if (fresh) signals_.push_back({s.id, kInitialState});
      for (const auto& lamp : s.lamps) {
        Lamp l;
        l.model = model.name;
        l.colour = lamp.colour;
        l.signal = it->second;
        l.instances = ctx_->cameras->visual_instances(lamp.link, lamp.visual);
        for (int i : l.instances) {
          l.lit_looks.push_back(lit_look(ctx_->cameras->material(i), lamp.colour));
          l.dark_looks.push_back(dark_look(ctx_->cameras->material(i), lamp.colour));
        }
        lamps_.push_back(std::move(l));
      }
    }
  }
}

bool TrafficLightState::set_datapack(const datapack::View& dp) {
  const std::string& name = dp.id().name();
  if (name != datapack_) return false;
  if (dp.empty()) return true;
  if (!dp.is_json()) throw std::runtime_error(ctx_->where(name) + kFormat);
  const nlohmann::json j = datapack::read_json(dp);
  if (!j.is_object() || !j.contains("signals") || !j["signals"].is_object())
    throw std::runtime_error(ctx_->where(name) + kFormat);
  read_states(name, j["signals"]);
  apply();
  return true;
}

void TrafficLightState::read_states(const std::string& dp_name, const nlohmann::json& states) {
  for (auto& s : signals_) {
    auto it = states.find(s.id);
    if (it == states.end()) {
      s.state.clear();
      warn_once("missing " + s.id, "signal '" + s.id + "' is not in it: its lamps are dark");
      continue;
    }
    if (!it->is_string())
      throw std::runtime_error(ctx_->where(dp_name) + "signal '" + s.id +
                               "': the state must be a string, got " + it->dump());
    s.state = it->get<std::string>();
    if (!known_state(s.state))
      warn_once("state " + s.state, "signal '" + s.id + "': state '" + s.state +
                                        "' is not one of red, yellow, green, red_yellow, off: "
                                        "its lamps are dark");
  }
}

void TrafficLightState::warn_once(const std::string& key, const std::string& message) {
  if (!warned_.insert(key).second) return;
  std::fprintf(stderr, "convoy: warning: %s%s\n", ctx_->where(datapack_).c_str(), message.c_str());
}

void TrafficLightState::apply() {
  for (auto& l : lamps_) {
    const int on = lit_in(signals_[l.signal].state, l.colour) ? 1 : 0;
    if (on == l.shown) continue;
    for (size_t k = 0; k < l.instances.size(); ++k)
      ctx_->cameras->set_material(l.instances[k], on ? l.lit_looks[k] : l.dark_looks[k]);
    l.shown = on;
  }
}

bool TrafficLightState::lit(const std::string& model, const std::string& colour) const {
  for (const auto& l : lamps_)
    if (l.model == model && l.colour == colour) return l.shown == 1;
  return false;
}

std::string TrafficLightState::state(const std::string& id) const {
  for (const auto& s : signals_)
    if (s.id == id) return s.state;
  return "";
}

}  // namespace convoy::world
