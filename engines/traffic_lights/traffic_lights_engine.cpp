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
//   Leader     "self" (default: this engine's programs lead) | "sumo" (SUMO's lights lead)
//   SumoLightsDataPack  name under which a TF passes the sumo engine's traffic_lights datapack
//              in (default "sumo_traffic_lights"); it gives the TLS links, and with Leader
//              "sumo" their states
//   SumoOutDataPack  name of the datapack for the sumo engine's traffic_lights_in (default
//              "traffic_lights_in"), written once SUMO's links are known
//
// SUMO mapping (netconvert names a junction's TLS after the OpenDRIVE junction id): a TLS link
// whose incoming lane is on SUMO edge "-R[.s]" carries road R's traffic along s (a signal with
// orientation "+"), edge "R[.s]" the traffic against s ("-"). Link i of TLS J gets the state of
// the signal on that road and side switched by one of junction J's controllers (G, y, r, u);
// a link with no such signal is "O" (off), warned once.
//
// Datapacks written:
//   <DataPack>  JSON {"time_ns", "signals": {<OpenDRIVE signal id>: "red" | "yellow" | "green" |
//               "red_yellow" | "off"}, "junctions": {<junction id>: {"phase", "remaining_s"}}}.
//               Traffic lights (type 1000001) show their controller's state; pedestrian lights
//               (type 1000002) show "green" while their controller is green, else "red".
//               Dynamic signals switched by no junction's controller are "off".
//   <SumoOutDataPack>  JSON {"lights": {<SUMO TLS id>: {"state": "GrGr..."}}} (Leader "self").
// Datapacks read:
//   <SumoLightsDataPack>  the sumo engine's traffic_lights JSON ({lights: {<tls>: {state,
//               links: [{index, from}]}}}).
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
  std::string road;         // OpenDRIVE road id
  std::string orientation;  // "+", "-" or "none"
};

char sumo_char(const std::string& state) {
  if (state == "green") return 'G';
  if (state == "yellow") return 'y';
  if (state == "red") return 'r';
  if (state == "red_yellow") return 'u';
  return 'O';
}

std::string state_of_sumo(char c) {
  switch (c) {
    case 'G':
    case 'g':
      return "green";
    case 'y':
    case 'Y':
      return "yellow";
    case 'r':
    case 's':
      return "red";
    case 'u':
      return "red_yellow";
    default:
      return "off";
  }
}

// Road id and side ("+": along s) of a SUMO lane id made by netconvert from OpenDRIVE:
// "-R.s_i" / "R.s_i" (the ".s" part only for roads of several sections).
std::pair<std::string, std::string> road_of_sumo_lane(const std::string& lane) {
  std::string e = lane.substr(0, lane.rfind('_'));
  std::string side = "-";
  if (!e.empty() && e[0] == '-') {
    side = "+";
    e = e.substr(1);
  }
  const auto dot = e.find('.');
  if (dot != std::string::npos) e = e.substr(0, dot);
  return {e, side};
}

class TrafficLightsEngine final : public Engine {
 public:
  std::vector<engine::DataPackId> initialize(const std::string& name, const json& config,
                                             int64_t timestep_ns) override {
    name_ = name;
    (void)timestep_ns;
    dp_name_ = config.at("DataPack").get<std::string>();
    sumo_in_ = config.at("SumoLightsDataPack").get<std::string>();
    sumo_out_ = config.at("SumoOutDataPack").get<std::string>();
    const std::string leader = config.at("Leader").get<std::string>();
    if (leader != "self" && leader != "sumo")
      fail("Leader: expected \"self\" or \"sumo\", got \"" + leader + "\"");
    sumo_leads_ = leader == "sumo";
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
      s.road = g.road_id;
      s.orientation = g.signal->orientation;
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
    std::vector<engine::DataPackId> ids(sumo_leads_ ? 1 : 2);
    ids[0].set_name(dp_name_);
    if (!sumo_leads_) ids[1].set_name(sumo_out_);
    for (auto& id : ids) {
      id.set_type(std::string(datapack::kJsonType));
      id.set_engine_name(name);
    }
    return ids;
  }

  int64_t step(int64_t duration_ns) override {
    time_ns_ += duration_ns;
    return time_ns_;
  }

  void set_datapack(const datapack::View& dp) override {
    if (dp.empty()) return;
    if (dp.id().name() == sumo_in_) {
      if (!dp.is_json()) fail("datapack '" + sumo_in_ + "': expected JSON");
      read_sumo(datapack::read_json(dp));
      return;
    }
    if (warned_.insert(dp.id().name()).second) {
      std::fprintf(
          stderr, "warning: traffic_lights engine '%s': datapack '%s' ignored (it reads only %s)\n",
          name_.c_str(), dp.id().name().c_str(), sumo_in_.c_str());
    }
  }

  void get_datapack(const engine::DataPackId& id, datapack::Builder& out) override {
    if (id.name() == sumo_out_ && !sumo_leads_) {
      if (tls_links_.empty()) return;
      const json signals = states();
      json lights = json::object();
      for (const auto& [tls, links] : tls_links_) {
        std::string state(links.size(), 'O');
        for (size_t i = 0; i < links.size(); ++i) {
          if (!links[i].empty()) state[i] = sumo_char(signals.at(links[i]).get<std::string>());
        }
        lights[tls] = {{"state", state}};
      }
      datapack::write_json(out, json{{"lights", std::move(lights)}});
      return;
    }
    if (id.name() != dp_name_) return;
    json signals = states();
    json junctions = json::object();
    for (const auto& p : junctions_) {
      const auto [i, t] = phase_at(p);
      junctions[p.id] = {{"phase", i}, {"remaining_s", (p.phases[i].duration_ns - t) * 1e-9}};
    }
    json doc{{"time_ns", time_ns_},
             {"signals", std::move(signals)},
             {"junctions", std::move(junctions)}};
    if (sumo_leads_) doc["leader"] = "sumo";
    datapack::write_json(out, doc);
  }

  std::pair<size_t, int64_t> phase_at(const JunctionProgram& p) const {
    int64_t t = (time_ns_ - p.offset_ns) % p.cycle_ns;
    if (t < 0) t += p.cycle_ns;
    size_t i = 0;
    while (t >= p.phases[i].duration_ns) t -= p.phases[i++].duration_ns;
    return {i, t};
  }

  // Each signal's state: from the programs, or (Leader "sumo") from SUMO's last lights.
  json states() const {
    json signals = json::object();
    for (const auto& s : signals_) {
      if (!s.junction) {
        signals[s.id] = "off";
        continue;
      }
      std::string st = "red";
      if (sumo_leads_) {
        auto it = sumo_states_.find(s.id);
        st = it == sumo_states_.end() ? "off" : it->second;
      } else {
        const Phase& ph = s.junction->phases[phase_at(*s.junction).first];
        auto it = ph.lights.find(s.controller);
        st = light_name(it == ph.lights.end() ? Light::kRed : it->second);
      }
      if (s.pedestrian) st = st == "green" ? "green" : "red";
      signals[s.id] = st;
    }
    return signals;
  }

  // The OpenDRIVE signal (id) a SUMO TLS link is switched by; empty when none.
  std::string signal_of_link(const std::string& tls, const std::string& from_lane) {
    const auto [road, side] = road_of_sumo_lane(from_lane);
    for (const auto& s : signals_) {
      if (!s.junction || s.pedestrian || s.junction->id != tls || s.road != road) continue;
      if (s.orientation == side || s.orientation == "none") return s.id;
    }
    if (warned_.insert("link:" + tls + ":" + from_lane).second) {
      std::fprintf(stderr,
                   "warning: traffic_lights engine '%s': SUMO TLS '%s' link from '%s' matches "
                   "no signal of junction '%s' (road %s, orientation %s); it is off\n",
                   name_.c_str(), tls.c_str(), from_lane.c_str(), tls.c_str(), road.c_str(),
                   side.c_str());
    }
    return {};
  }

  void read_sumo(const json& j) {
    const json& lights = j.contains("lights") ? j["lights"] : j;
    if (!lights.is_object()) fail("datapack '" + sumo_in_ + "': expected {lights: {<tls>: ...}}");
    for (const auto& [tls, v] : lights.items()) {
      if (!v.is_object() || !v.contains("links") || !v["links"].is_array())
        fail("datapack '" + sumo_in_ + "': TLS '" + tls + "' has no links");
      if (!tls_links_.count(tls)) {
        std::vector<std::string> links;
        for (const auto& l : v["links"]) {
          const size_t i = l.at("index").get<size_t>();
          if (links.size() <= i) links.resize(i + 1);
          if (links[i].empty()) links[i] = signal_of_link(tls, l.at("from").get<std::string>());
        }
        tls_links_[tls] = std::move(links);
      }
      if (!sumo_leads_) continue;
      const std::string state = v.value("state", "");
      const auto& links = tls_links_[tls];
      for (size_t i = 0; i < links.size() && i < state.size(); ++i) {
        if (!links[i].empty()) sumo_states_[links[i]] = state_of_sumo(state[i]);
      }
    }
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

  std::string name_, dp_name_, sumo_in_, sumo_out_;
  bool sumo_leads_ = false;
  std::map<std::string, std::vector<std::string>> tls_links_;  // TLS -> link index -> signal
  std::map<std::string, std::string> sumo_states_;             // signal -> state (Leader sumo)
  opendrive::Network net_;
  std::vector<JunctionProgram> junctions_;
  std::vector<SignalOut> signals_;
  std::set<std::string> warned_;
  int64_t time_ns_ = 0;
};

}  // namespace

CONVOY_REGISTER_ENGINE("traffic_lights", TrafficLightsEngine);

}  // namespace convoy::engines::traffic_lights
