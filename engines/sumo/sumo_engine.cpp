// The sumo engine (sumo_engine.h): libsumo in-process.
#include "sumo_engine.h"

#include <google/protobuf/util/json_util.h>
#include <libsumo/libsumo.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include "datapack/json.h"
#include "datapack/proto.h"
#include "datapack/registry.h"

#ifndef CONVOY_SUMO_HOME
#define CONVOY_SUMO_HOME "/usr/share/sumo"
#endif

namespace convoy::engines::sumo {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// The fixed class set (docs/road_users.md) from SUMO's vehicle classes.
std::string category_of(const std::string& vclass) {
  if (vclass == "truck" || vclass == "trailer") return "truck";
  if (vclass == "bus" || vclass == "coach" || vclass == "tram" || vclass == "rail_urban")
    return "bus";
  if (vclass == "bicycle" || vclass == "moped" || vclass == "motorcycle") return "cyclist";
  if (vclass == "pedestrian") return "pedestrian";
  return "car";  // passenger, private, taxi, delivery (a van), emergency, evehicle, ...
}

// The vType an external road user gets in SUMO, by its category.
const char* vclass_of(const std::string& category) {
  if (category == "truck") return "truck";
  if (category == "bus") return "bus";
  if (category == "cyclist") return "bicycle";
  if (category == "pedestrian") return "pedestrian";
  return "passenger";
}

// SUMO's signal bits (TraCI's VEH_SIGNAL_*, which libsumo's headers do not carry).
enum SumoSignal : int {
  kBlinkerRight = 1,
  kBlinkerLeft = 2,
  kBlinkerEmergency = 4,
  kBrakeLight = 8,
  kFrontLight = 16,
  kBackDrive = 128,
};

// SUMO's signals -> RoadUser.lights.
uint32_t lights_of(int signals) {
  uint32_t l = 0;
  if (signals & kBlinkerRight) l |= data::RoadUser::INDICATOR_RIGHT;
  if (signals & kBlinkerLeft) l |= data::RoadUser::INDICATOR_LEFT;
  if (signals & kBlinkerEmergency) l |= data::RoadUser::HAZARD;
  if (signals & kBrakeLight) l |= data::RoadUser::BRAKE;
  if (signals & kFrontLight) l |= data::RoadUser::HEADLIGHTS;
  if (signals & kBackDrive) l |= data::RoadUser::REVERSE;
  return l;
}

int signals_of(uint32_t lights) {
  int s = 0;
  if (lights & data::RoadUser::INDICATOR_RIGHT) s |= kBlinkerRight;
  if (lights & data::RoadUser::INDICATOR_LEFT) s |= kBlinkerLeft;
  if (lights & data::RoadUser::HAZARD) s |= kBlinkerEmergency;
  if (lights & data::RoadUser::BRAKE) s |= kBrakeLight;
  if (lights & data::RoadUser::HEADLIGHTS) s |= kFrontLight;
  if (lights & data::RoadUser::REVERSE) s |= kBackDrive;
  return s;
}

constexpr const char* kExternalPrefix = "convoy_external:";
constexpr const char* kExternalRoute = "convoy_external_route";

std::vector<std::string> strings(const json& config, const char* key) {
  std::vector<std::string> out;
  if (config.contains(key)) {
    for (const auto& v : config.at(key)) out.push_back(v.get<std::string>());
  }
  return out;
}

std::string joined(const std::vector<std::string>& files) {
  std::string s;
  for (const auto& f : files) s += (s.empty() ? "" : ",") + f;
  return s;
}

}  // namespace

SumoEngine::~SumoEngine() { shutdown(); }

void SumoEngine::fail(const std::string& what) const {
  throw std::runtime_error("sumo engine '" + name_ + "': " + what);
}

void SumoEngine::warn_once(const std::string& key, const std::string& text) {
  if (warned_[key]) return;
  warned_[key] = true;
  std::fprintf(stderr, "warning: sumo engine '%s': %s\n", name_.c_str(), text.c_str());
  warnings_.push_back(text);
}

std::vector<engine::DataPackId> SumoEngine::initialize(const std::string& name, const json& config,
                                                       int64_t timestep_ns) {
  name_ = name;
  timestep_ns_ = timestep_ns;
  if (timestep_ns % 1000000 != 0) {
    fail("EngineTimestep must be a whole number of milliseconds for SUMO, got " +
         std::to_string(timestep_ns * 1e-9) + " s");
  }
  setenv("SUMO_HOME", CONVOY_SUMO_HOME, 0);

  const std::string net_file = config.value("NetFile", "");
  const std::string xodr = config.value("OpenDriveFile", "");
  if (net_file.empty() == xodr.empty()) {
    fail("give exactly one of NetFile and OpenDriveFile (got " +
         std::string(net_file.empty() ? "neither" : "both") + ")");
  }
  fs::path net = net_file;
  if (!xodr.empty()) {
    const std::string cache = config.at("NetCacheDir").get<std::string>();
    try {
      net = convert_opendrive(xodr, cache.empty() ? default_cache_dir() : fs::path(cache));
    } catch (const std::exception& e) {
      fail(std::string("OpenDriveFile: ") + e.what());
    }
    std::fprintf(stderr, "sumo engine '%s': network %s (from %s)\n", name.c_str(), net.c_str(),
                 xodr.c_str());
  }
  try {
    offset_ = read_net_offset(net);
  } catch (const std::exception& e) {
    fail(std::string(net_file.empty() ? "OpenDriveFile: " : "NetFile: ") + e.what());
  }

  args_ = {"-n",
           net.string(),
           "--step-length",
           std::to_string(timestep_ns / 1000000) + "ms",
           "--seed",
           std::to_string(config.at("Seed").get<int64_t>()),
           "--no-step-log",
           "true",
           "--duration-log.disable",
           "true"};
  // SUMO 1.15 reads "--step-length" in seconds: give it as a decimal.
  char step[32];
  std::snprintf(step, sizeof step, "%.3f", timestep_ns * 1e-9);
  args_[3] = step;
  if (auto routes = strings(config, "RouteFiles"); !routes.empty()) {
    args_.insert(args_.end(), {"-r", joined(routes)});
  }
  if (auto adds = strings(config, "AdditionalFiles"); !adds.empty()) {
    args_.insert(args_.end(), {"-a", joined(adds)});
  }
  for (auto& o : strings(config, "SumoOptions")) args_.push_back(o);

  vehicles_dp_ = config.at("VehiclesDataPack").get<std::string>();
  persons_dp_ = config.at("PersonsDataPack").get<std::string>();
  lights_dp_ = config.at("TrafficLightsDataPack").get<std::string>();
  ext_users_dp_ = config.at("ExternalRoadUsersDataPack").get<std::string>();
  ext_lights_dp_ = config.at("ExternalTrafficLightsDataPack").get<std::string>();
  lights_external_ = config.at("TrafficLightsLeader").get<std::string>() == "external";
  match_distance_ = config.at("ExternalMatchDistance").get<double>();

  load();

  std::vector<engine::DataPackId> ids(3);
  ids[0].set_name(vehicles_dp_);
  ids[0].set_type(std::string(datapack::type_name<data::RoadUsers>()));
  ids[1].set_name(lights_dp_);
  ids[1].set_type(std::string(datapack::kJsonType));
  ids[2].set_name(persons_dp_);
  ids[2].set_type(std::string(datapack::type_name<data::RoadUsers>()));
  for (auto& id : ids) id.set_engine_name(name);
  return ids;
}

void SumoEngine::load() {
  try {
    libsumo::Simulation::load(args_);
  } catch (const std::exception& e) {
    std::string args;
    for (const auto& a : args_) args += " " + a;
    fail(std::string("SUMO could not start (NetFile/OpenDriveFile, RouteFiles, AdditionalFiles "
                     "or SumoOptions; see the lines starting with \"Error:\" in its log): ") +
         e.what() + "; options:" + args);
  }
  if (!libsumo::Simulation::isLoaded()) fail("SUMO could not start; see its log");
  loaded_ = true;
  time_ns_ = 0;
  // External road users ride a route of one edge; moveToXY places them anywhere.
  const auto edges = libsumo::Edge::getIDList();
  for (const auto& e : edges) {
    if (!e.empty() && e[0] != ':') {
      libsumo::Route::add(kExternalRoute, {e});
      break;
    }
  }
  for (const char* cat : {"car", "truck", "bus", "cyclist", "pedestrian"}) {
    const std::string type = std::string("convoy_") + cat;
    libsumo::VehicleType::copy("DEFAULT_VEHTYPE", type);
    libsumo::VehicleType::setVehicleClass(type, vclass_of(cat));
  }
  for (const auto& tls : libsumo::TrafficLight::getIDList()) {
    json links = json::array();
    const auto controlled = libsumo::TrafficLight::getControlledLinks(tls);
    for (size_t i = 0; i < controlled.size(); ++i) {
      for (const auto& l : controlled[i]) {
        links.push_back({{"index", i}, {"from", l.fromLane}, {"to", l.toLane}, {"via", l.viaLane}});
      }
    }
    tls_links_[tls] = std::move(links);
  }
  persons_ = PersonReader(name_ + "/", offset_);
  read_vehicles();
  persons_.read(time_ns_, 0, persons_data_);
  read_traffic_lights();
}

const SumoEngine::TypeInfo& SumoEngine::type_info(const std::string& type_id) {
  auto it = types_.find(type_id);
  if (it != types_.end()) return it->second;
  TypeInfo t;
  t.category = category_of(libsumo::VehicleType::getVehicleClass(type_id));
  t.length = libsumo::VehicleType::getLength(type_id);
  t.width = libsumo::VehicleType::getWidth(type_id);
  t.height = libsumo::VehicleType::getHeight(type_id);
  return types_.emplace(type_id, std::move(t)).first->second;
}

void SumoEngine::read_vehicles() {
  const double dt = timestep_ns_ * 1e-9;
  std::vector<std::string> ids = libsumo::Vehicle::getIDList();
  // SUMO lists them in its map's order (sorted); tracked_ is sorted the same way, so both are
  // walked side by side instead of looked up.
  if (!std::is_sorted(ids.begin(), ids.end())) std::sort(ids.begin(), ids.end());
  vehicles_.Clear();
  vehicles_.set_time_ns(time_ns_);
  vehicles_.mutable_users()->Reserve(static_cast<int>(ids.size() + 8));
  // Vehicles that left since the last step: once as absent, first in the list.
  auto next = ids.begin();
  for (auto it = tracked_.begin(); it != tracked_.end();) {
    next = std::lower_bound(next, ids.end(), it->first);
    if (next == ids.end() || *next != it->first) {
      data::RoadUser* u = vehicles_.add_users();
      *u = std::move(it->second.last);
      u->set_absent(true);
      u->set_speed(0);
      u->set_acceleration(0);
      u->set_vx(0);
      u->set_vy(0);
      u->set_yaw_rate(0);
      u->set_time_ns(time_ns_);
      it = tracked_.erase(it);
    } else {
      ++it;
    }
  }
  const std::string prefix = name_ + "/";
  auto it = tracked_.begin();  // now every tracked vehicle is in `ids`, in the same order
  for (const auto& id : ids) {
    if (id.rfind(kExternalPrefix, 0) == 0) continue;
    const bool fresh = it == tracked_.end() || it->first != id;
    if (fresh) it = tracked_.emplace_hint(it, id, Tracked{});
    Tracked& tr = it->second;
    ++it;
    data::RoadUser& u = tr.last;
    if (fresh) {
      const std::string type = libsumo::Vehicle::getTypeID(id);
      const TypeInfo& t = type_info(type);
      u.set_id(prefix + id);
      u.set_category(t.category);
      u.set_model(type);
      u.set_length(t.length);
      u.set_width(t.width);
      u.set_height(t.height);
      u.set_length_offset(t.length * (0.5 - kRearAxleFraction));
    }
    const libsumo::TraCIPosition p = libsumo::Vehicle::getPosition3D(id);
    const double yaw = yaw_from_sumo_angle(libsumo::Vehicle::getAngle(id));
    const double speed = libsumo::Vehicle::getSpeed(id);
    const double back = u.length() * (1.0 - kRearAxleFraction);  // front bumper -> rear axle
    const double c = std::cos(yaw), s = std::sin(yaw);
    u.set_x(p.x - offset_.x - back * c);
    u.set_y(p.y - offset_.y - back * s);
    u.set_z(p.z);
    u.set_yaw_rate(fresh ? 0.0 : std::remainder(yaw - tr.yaw, 2 * M_PI) / dt);
    tr.yaw = yaw;
    u.set_yaw(yaw);
    // SUMO's acceleration is its speed's change over the step (Euler update): computed here,
    // one look-up less per vehicle; asked once when the vehicle appears.
    u.set_acceleration(fresh ? libsumo::Vehicle::getAcceleration(id) : (speed - u.speed()) / dt);
    u.set_speed(speed);
    u.set_vx(speed * c);
    u.set_vy(speed * s);
    u.set_lights(lights_of(libsumo::Vehicle::getSignals(id)));
    u.set_time_ns(time_ns_);
    *vehicles_.add_users() = u;
  }
}

void SumoEngine::read_traffic_lights() {
  json lights = json::object();
  for (const auto& [tls, links] : tls_links_) {
    lights[tls] = {{"state", libsumo::TrafficLight::getRedYellowGreenState(tls)},
                   {"phase", libsumo::TrafficLight::getPhase(tls)},
                   {"program", libsumo::TrafficLight::getProgram(tls)},
                   {"links", links}};
  }
  lights_ = {{"time_ns", time_ns_},
             {"leader", lights_external_ ? "external" : "sumo"},
             {"lights", std::move(lights)}};
}

void SumoEngine::apply_external_users() {
  for (auto& [id, u] : pending_users_) {
    auto in = in_sumo_.find(id);
    if (u.absent()) {
      if (in != in_sumo_.end()) {
        try {
          libsumo::Vehicle::remove(in->second);
        } catch (const std::exception&) {
          // Already gone (it left SUMO's network by itself).
        }
        in_sumo_.erase(in);
      }
      continue;
    }
    const std::string sumo_id = kExternalPrefix + id;
    const double length = u.length() > 0 ? u.length() : 4.5;
    const double c = std::cos(u.yaw()), s = std::sin(u.yaw());
    const double front =
        u.length() > 0 ? u.length_offset() + 0.5 * u.length() : length * (1.0 - kRearAxleFraction);
    const double x = u.x() + front * c + offset_.x, y = u.y() + front * s + offset_.y;
    const std::string category = u.category().empty() ? "car" : u.category();
    try {
      // SUMO places a vehicle far from every lane off-road, where it is removed at the next
      // step (and, added again, blocks its route's start): such a road user stays out.
      const libsumo::TraCIRoadPosition road =
          libsumo::Simulation::convertRoad(x, y, false, vclass_of(category));
      const libsumo::TraCIPosition on =
          road.edgeID.empty()
              ? libsumo::TraCIPosition()
              : libsumo::Simulation::convert2D(road.edgeID, road.pos, road.laneIndex);
      const double off = road.edgeID.empty() ? 1e9 : std::hypot(on.x - x, on.y - y);
      if (off > match_distance_) {
        throw std::runtime_error("its front is " + std::to_string(off) +
                                 " m from the nearest lane, more than ExternalMatchDistance " +
                                 std::to_string(match_distance_));
      }
      if (in == in_sumo_.end()) {
        libsumo::Vehicle::add(sumo_id, kExternalRoute, "convoy_" + category);
        in = in_sumo_.emplace(id, sumo_id).first;
        libsumo::Vehicle::setLength(sumo_id, length);
        if (u.width() > 0) libsumo::Vehicle::setWidth(sumo_id, u.width());
        libsumo::Vehicle::setSpeedMode(sumo_id, 0);  // its own engine drives it
        libsumo::Vehicle::setLaneChangeMode(sumo_id, 0);
      }
      // keepRoute 2: mapped onto the nearest lane whatever its route (as CARLA-SUMO does).
      libsumo::Vehicle::moveToXY(sumo_id, "", -1, x, y, sumo_angle_from_yaw(u.yaw()), 2);
      libsumo::Vehicle::setSpeed(sumo_id, std::max(0.0, u.speed()));
      libsumo::Vehicle::setSignals(sumo_id, signals_of(u.lights()));
    } catch (const std::exception& e) {
      // Not placed: taken out again, or SUMO would insert it at its route's start.
      if (in != in_sumo_.end()) {
        try {
          libsumo::Vehicle::remove(sumo_id);
        } catch (const std::exception&) {
        }
        in_sumo_.erase(in);
      }
      warn_once("place:" + id, "external road user '" + id + "' cannot be put into SUMO (" +
                                   e.what() + "); it is left out of SUMO while it is so");
    }
  }
  pending_users_.clear();
}

void SumoEngine::apply_external_lights() {
  for (const auto& [tls, state] : pending_lights_) {
    if (!tls_links_.count(tls)) {
      fail("datapack '" + ext_lights_dp_ + "': traffic light '" + tls +
           "' is not in SUMO's network");
    }
    try {
      libsumo::TrafficLight::setRedYellowGreenState(tls, state);
    } catch (const std::exception& e) {
      fail("datapack '" + ext_lights_dp_ + "': traffic light '" + tls + "': " + e.what());
    }
  }
  pending_lights_.clear();
}

int64_t SumoEngine::step(int64_t duration_ns) {
  apply_external_users();
  apply_external_lights();
  time_ns_ += duration_ns;
  const auto t0 = std::chrono::steady_clock::now();
  try {
    libsumo::Simulation::step(time_ns_ * 1e-9);
  } catch (const std::exception& e) {
    fail(std::string("step failed: ") + e.what());
  }
  const auto t1 = std::chrono::steady_clock::now();
  // A vehicle of SUMO's that an external one displaced may leave; an external one SUMO
  // removed (teleported away, arrived) is added again at its next state.
  for (const auto& id : libsumo::Simulation::getArrivedIDList()) {
    if (id.rfind(kExternalPrefix, 0) == 0) in_sumo_.erase(id.substr(std::strlen(kExternalPrefix)));
  }
  read_vehicles();
  persons_.read(time_ns_, timestep_ns_ * 1e-9, persons_data_);
  read_traffic_lights();
  const auto t2 = std::chrono::steady_clock::now();
  sumo_s_ += std::chrono::duration<double>(t1 - t0).count();
  read_s_ += std::chrono::duration<double>(t2 - t1).count();
  return time_ns_;
}

void SumoEngine::set_datapack(const datapack::View& dp) {
  if (dp.empty()) return;
  const std::string& name = dp.id().name();
  if (name == ext_users_dp_) {
    auto take = [&](const data::RoadUser& u) {
      if (u.id().empty()) fail("datapack '" + name + "': a road user without an id");
      pending_users_[u.id()] = u;
    };
    if (dp.is_proto() && dp.proto_type() == datapack::type_name<data::RoadUsers>()) {
      data::RoadUsers us;
      datapack::read_proto(dp, &us);
      for (const auto& u : us.users()) take(u);
    } else if (dp.is_proto() && dp.proto_type() == datapack::type_name<data::RoadUser>()) {
      data::RoadUser u;
      datapack::read_proto(dp, &u);
      take(u);
    } else if (dp.is_json()) {
      json j = datapack::read_json(dp);
      json list = j.is_array() ? j : j.contains("users") ? j["users"] : json::array({j});
      for (const auto& item : list) {
        data::RoadUser u;
        google::protobuf::util::JsonParseOptions opts;
        auto st = google::protobuf::util::JsonStringToMessage(item.dump(), &u, opts);
        if (!st.ok())
          fail("datapack '" + name + "': not a road user: " + std::string(st.message()));
        take(u);
      }
    } else {
      fail("datapack '" + name + "': expected convoy.data.RoadUsers or RoadUser, got " +
           (dp.is_proto() ? dp.proto_type() : std::string("another type")));
    }
    return;
  }
  if (name == ext_lights_dp_) {
    if (!lights_external_) {
      warn_once("lights_ignored",
                "datapack '" + name + "' ignored: TrafficLightsLeader is \"sumo\"");
      return;
    }
    if (!dp.is_json()) fail("datapack '" + name + "': expected JSON");
    json j = datapack::read_json(dp);
    const json& lights = j.contains("lights") ? j["lights"] : j;
    if (!lights.is_object())
      fail("datapack '" + name + "': expected {lights: {<tls id>: {state}}}");
    for (const auto& [tls, v] : lights.items()) {
      if (v.is_string()) {
        pending_lights_[tls] = v.get<std::string>();
      } else if (v.is_object() && v.contains("state") && v["state"].is_string()) {
        pending_lights_[tls] = v["state"].get<std::string>();
      } else {
        fail("datapack '" + name + "': traffic light '" + tls + "' has no state string");
      }
    }
    return;
  }
  warn_once("unknown_dp:" + name, "datapack '" + name + "' is not one the sumo engine reads (" +
                                      ext_users_dp_ + ", " + ext_lights_dp_ + "); ignored");
}

void SumoEngine::get_datapack(const engine::DataPackId& id, datapack::Builder& out) {
  if (!loaded_) return;
  if (id.name() == persons_dp_) {
    datapack::write_proto(out, persons_data_);
    return;
  }
  if (id.name() == vehicles_dp_) {
    const auto t0 = std::chrono::steady_clock::now();
    datapack::write_proto(out, vehicles_);
    write_s_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  } else if (id.name() == lights_dp_) {
    datapack::write_json(out, lights_);
  }
}

void SumoEngine::reset() {
  shutdown();
  tracked_.clear();
  persons_.reset();
  in_sumo_.clear();
  pending_users_.clear();
  pending_lights_.clear();
  tls_links_.clear();
  load();
}

void SumoEngine::shutdown() {
  if (!loaded_) return;
  loaded_ = false;
  // Where the engine's time went (its log): SUMO's own steps, reading the vehicles and
  // lights out of SUMO, writing the vehicles' datapack.
  std::fprintf(stderr,
               "sumo engine '%s': SUMO steps %.3f s, reading vehicles %.3f s, writing %.3f s\n",
               name_.c_str(), sumo_s_, read_s_, write_s_);
  try {
    libsumo::Simulation::close();
  } catch (const std::exception&) {
  }
}

CONVOY_REGISTER_ENGINE("sumo", SumoEngine);

}  // namespace convoy::engines::sumo
