// EngineType "traffic_lights": the traffic lights of an OpenDRIVE map, switched per junction.
//
// Each junction that names controllers (<junction><controller id=.../>) runs a fixed-time
// program: its controllers take turns, in the junction's sequence order; each turn is green
// (Green s), yellow (Yellow s), then all-red (AllRed s). A controller's signals share its
// state. Programs can also be given explicitly per junction. The state is a function of the
// simulated time only, so runs are deterministic.
//
// Config keys (schema.json):
//   Map        the .xodr
//   Green, Yellow, AllRed   default durations (s; Green > 0, the others >= 0)
//   Junctions  {<junction id>: {Green, Yellow, AllRed, Offset}}: per-junction overrides; the
//              junction's cycle starts at t = Offset (s, may be negative)
//   Programs   {<junction id>: [{Duration, Green: [controller ids], Yellow: [...],
//              RedYellow: [...]}]}: an explicit program (controllers not named are red)
//   DataPack   name of the datapack written (default "traffic_lights")
//
// Datapacks written:
//   <DataPack>  JSON {"time_ns", "signals": {<OpenDRIVE signal id>: "red" | "yellow" | "green" |
//               "red_yellow" | "off"}, "junctions": {<junction id>: {"phase", "remaining_s"}}}.
//               Traffic lights (type 1000001) show their controller's state; pedestrian lights
//               (type 1000002) show "green" while their controller is green, else "red".
//               Dynamic signals switched by no junction's controller are "off".
// Datapacks read: none.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "datapack/json.h"
#include "engine/engine.h"
#include "opendrive/lane_graph.h"
#include "opendrive/parser.h"

namespace convoy::engines::traffic_lights {
namespace {

using nlohmann::json;

enum class Light { kRed, kYellow, kGreen, kRedYellow };

const char* light_name(Light l) {
  switch (l) {
    case Light::kGreen:
      return "green";
    case Light::kYellow:
      return "yellow";
    case Light::kRedYellow:
      return "red_yellow";
    default:
      return "red";
  }
}

struct Phase {
  int64_t duration_ns = 0;
  std::map<std::string, Light> lights;  // controller id -> state (absent: red)
};

struct JunctionProgram {
  std::string id;
  std::vector<std::string> controllers;
  std::vector<Phase> phases;
  int64_t cycle_ns = 0;
  int64_t offset_ns = 0;
};

struct SignalOut {
  std::string id;
  std::string controller;  // empty: no junction's controller switches it
  const JunctionProgram* junction = nullptr;
  bool pedestrian = false;
};

class TrafficLightsEngine final : public Engine {
 public:
  std::vector<engine::DataPackId> initialize(const std::string& name, const json& config,
                                             int64_t timestep_ns) override {
    name_ = name;
    (void)timestep_ns;
    dp_name_ = config.at("DataPack").get<std::string>();
    if (!config.contains("Map")) fail("Map: the .xodr is required");
    const std::string map = config.at("Map").get<std::string>();
    try {
      net_ = opendrive::load(map);
    } catch (const std::exception& e) {
      fail(std::string("Map: ") + e.what());
    }
    std::unique_ptr<opendrive::LaneGraph> graph;
    try {
      graph = std::make_unique<opendrive::LaneGraph>(net_);
    } catch (const std::exception& e) {
      fail(std::string("Map: ") + e.what());
    }
    const double green = seconds(config, "Green", "Green", true);
    const double yellow = seconds(config, "Yellow", "Yellow", false);
    const double all_red = seconds(config, "AllRed", "AllRed", false);
    const json& overrides = config.at("Junctions");
    const json& programs = config.at("Programs");
    if (!overrides.is_object()) fail("Junctions: expected an object {<junction id>: {...}}");
    if (!programs.is_object()) fail("Programs: expected an object {<junction id>: [...]}");
    std::set<std::string> known;
    for (const auto& j : net_.junctions) known.insert(j.id);
    for (const auto& [id, v] : overrides.items()) {
      if (!known.count(id)) fail("Junctions." + id + ": no junction '" + id + "' in " + map);
      if (!v.is_object()) fail("Junctions." + id + ": expected an object");
      for (const auto& [k, x] : v.items()) {
        if (k != "Green" && k != "Yellow" && k != "AllRed" && k != "Offset")
          fail("Junctions." + id + "." + k + ": unknown key (Green, Yellow, AllRed, Offset)");
        if (!x.is_number()) fail("Junctions." + id + "." + k + ": expected a number");
      }
    }
    for (const auto& [id, v] : programs.items()) {
      if (!known.count(id)) fail("Programs." + id + ": no junction '" + id + "' in " + map);
    }

    for (const auto& j : net_.junctions) {
      if (j.controllers.empty()) continue;
      JunctionProgram p;
      p.id = j.id;
      p.controllers = j.controllers;
      const json ov = overrides.contains(j.id) ? overrides[j.id] : json::object();
      const std::string key = "Junctions." + j.id + ".";
      const double g = ov.contains("Green") ? seconds(ov, "Green", key + "Green", true) : green;
      const double y =
          ov.contains("Yellow") ? seconds(ov, "Yellow", key + "Yellow", false) : yellow;
      const double r =
          ov.contains("AllRed") ? seconds(ov, "AllRed", key + "AllRed", false) : all_red;
      p.offset_ns = ov.contains("Offset") ? std::llround(ov["Offset"].get<double>() * 1e9) : 0;
      if (programs.contains(j.id)) {
        p.phases = explicit_program(programs[j.id], "Programs." + j.id, j.controllers);
      } else {
        for (const auto& c : j.controllers) {
          for (auto [d, l] : {std::pair{g, Light::kGreen}, std::pair{y, Light::kYellow},
                              std::pair{r, Light::kRed}}) {
            Phase ph;
            ph.duration_ns = std::llround(d * 1e9);
            if (ph.duration_ns == 0) continue;
            if (l != Light::kRed) ph.lights[c] = l;
            p.phases.push_back(std::move(ph));
          }
        }
      }
      for (const auto& ph : p.phases) p.cycle_ns += ph.duration_ns;
      junctions_.push_back(std::move(p));
    }
    std::map<std::string, const JunctionProgram*> by_controller;
    for (const auto& p : junctions_)
      for (const auto& c : p.controllers) by_controller.emplace(c, &p);
    for (const auto& g : graph->signals()) {
      if (!g.traffic_light && !g.pedestrian_light) continue;
      SignalOut s;
      s.id = g.signal->id;
      s.pedestrian = g.pedestrian_light;
      for (const auto& c : g.controllers) {
        auto it = by_controller.find(c);
        if (it != by_controller.end()) {
          s.controller = c;
          s.junction = it->second;
          break;
        }
      }
      signals_.push_back(std::move(s));
    }
    std::fprintf(stderr, "traffic_lights engine '%s': %zu junctions, %zu signals from %s\n",
                 name.c_str(), junctions_.size(), signals_.size(), map.c_str());
    time_ns_ = 0;
    std::vector<engine::DataPackId> ids(1);
    ids[0].set_name(dp_name_);
    ids[0].set_type(std::string(datapack::kJsonType));
    ids[0].set_engine_name(name);
    return ids;
  }

  int64_t step(int64_t duration_ns) override {
    time_ns_ += duration_ns;
    return time_ns_;
  }

  void set_datapack(const datapack::View& dp) override {
    if (dp.empty()) return;
    if (warned_.insert(dp.id().name()).second) {
      std::fprintf(stderr,
                   "warning: traffic_lights engine '%s': datapack '%s' ignored (it reads none)\n",
                   name_.c_str(), dp.id().name().c_str());
    }
  }

  void get_datapack(const engine::DataPackId& id, datapack::Builder& out) override {
    if (id.name() != dp_name_) return;
    json signals = json::object();
    json junctions = json::object();
    std::map<const JunctionProgram*, const Phase*> current;
    for (const auto& p : junctions_) {
      int64_t t = (time_ns_ - p.offset_ns) % p.cycle_ns;
      if (t < 0) t += p.cycle_ns;
      size_t i = 0;
      while (t >= p.phases[i].duration_ns) t -= p.phases[i++].duration_ns;
      current[&p] = &p.phases[i];
      junctions[p.id] = {{"phase", i}, {"remaining_s", (p.phases[i].duration_ns - t) * 1e-9}};
    }
    for (const auto& s : signals_) {
      if (!s.junction) {
        signals[s.id] = "off";
        continue;
      }
      const Phase* ph = current.at(s.junction);
      auto it = ph->lights.find(s.controller);
      const Light l = it == ph->lights.end() ? Light::kRed : it->second;
      if (s.pedestrian)
        signals[s.id] = l == Light::kGreen ? "green" : "red";
      else
        signals[s.id] = light_name(l);
    }
    datapack::write_json(out, json{{"time_ns", time_ns_},
                                   {"signals", std::move(signals)},
                                   {"junctions", std::move(junctions)}});
  }

  void reset() override { time_ns_ = 0; }

 private:
  [[noreturn]] void fail(const std::string& what) const {
    throw std::runtime_error("traffic_lights engine '" + name_ + "': " + what);
  }

  double seconds(const json& obj, const char* k, const std::string& key, bool positive) const {
    const json& v = obj.at(k);
    if (!v.is_number()) fail(key + ": expected a number of seconds");
    const double d = v.get<double>();
    if (!std::isfinite(d) || d < 0 || (positive && d == 0))
      fail(key + ": must be " + (positive ? "> 0" : ">= 0") + " s, got " + v.dump());
    return d;
  }

  std::vector<Phase> explicit_program(const json& prog, const std::string& key,
                                      const std::vector<std::string>& controllers) const {
    if (!prog.is_array() || prog.empty()) fail(key + ": expected a non-empty list of phases");
    std::vector<Phase> out;
    for (size_t i = 0; i < prog.size(); ++i) {
      const std::string k = key + "[" + std::to_string(i) + "]";
      const json& p = prog[i];
      if (!p.is_object() || !p.contains("Duration")) fail(k + ": expected {Duration, Green, ...}");
      Phase ph;
      ph.duration_ns = std::llround(seconds(p, "Duration", k + ".Duration", true) * 1e9);
      for (const auto& [field, v] : p.items()) {
        if (field == "Duration") continue;
        Light l;
        if (field == "Green")
          l = Light::kGreen;
        else if (field == "Yellow")
          l = Light::kYellow;
        else if (field == "RedYellow")
          l = Light::kRedYellow;
        else
          fail(k + "." + field + ": unknown key (Duration, Green, Yellow, RedYellow)");
        if (!v.is_array()) fail(k + "." + field + ": expected a list of controller ids");
        for (const auto& c : v) {
          const std::string cid = c.is_string() ? c.get<std::string>() : c.dump();
          if (std::find(controllers.begin(), controllers.end(), cid) == controllers.end())
            fail(k + "." + field + ": controller '" + cid + "' is not one of the junction's");
          ph.lights[cid] = l;
        }
      }
      out.push_back(std::move(ph));
    }
    return out;
  }

  std::string name_, dp_name_;
  opendrive::Network net_;
  std::vector<JunctionProgram> junctions_;
  std::vector<SignalOut> signals_;
  std::set<std::string> warned_;
  int64_t time_ns_ = 0;
};

}  // namespace

CONVOY_REGISTER_ENGINE("traffic_lights", TrafficLightsEngine);

}  // namespace convoy::engines::traffic_lights
