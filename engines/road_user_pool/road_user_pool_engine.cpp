// EngineType "road_user_pool": N vehicles in one engine process (issue 26's pooled host), each
// with its own parameters, seed and policy. The behaviour (IDM, MOBIL, junctions, lights, the
// neighbour grid) is src/traffic_pool; this file only reads the config and writes the datapack.
//
// Config keys (schema.json): Map, Vehicles (listed), Count or Density + Seed + Policy +
// DesiredSpeed + KeepClear (spawned), Pedestrians or PedestrianDensity (walkers on the
// sidewalks, src/traffic_pool/pool_walkers.h), RoadUsersDataPack, ExternalDataPack,
// CommandDataPack (JSON {"<road user id>": command}, the agents' command contract),
// TrafficLightsDataPack (the traffic_lights engine's JSON {"signals": {"<OpenDRIVE signal id>":
// "red"|"yellow"|"green"|"red_yellow"|"off"}}: when set, the lights its vehicles and walkers obey
// are these signals' states instead of its own cycle; a signal not in it is green, and so is every
// signal until the first one comes, as for vehicle_agent; a datapack without "signals" or with a
// state that is not one of those strings stops the run, exit 3, naming the engine, datapack and
// signal). In:
// <ExternalDataPack> convoy.data.RoadUsers (or one RoadUser), the road users it does not drive (the
// ego, agents): obstacles its vehicles follow, keep gaps to and yield to, kept until the next one;
// a malformed one stops the run (exit 2) naming the field. Out: <RoadUsersDataPack>
// convoy.data.RoadUsers, every vehicle's state after the last step (reference point: the rear axle,
// a quarter of the length ahead of the rear bumper), then every walker's (category pedestrian,
// model walker, walk_phase; the centre of its feet), ids "<engine>/<id>"; protobuf's binary
// form, not JSON. Bad input (an unknown policy, two road users on one spot, a count the map cannot
// hold, a destination with no path) fails initialize with one message naming the road user.
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <stdexcept>

#include "convoy/road_users.pb.h"
#include "core/error.h"
#include "datapack/json.h"
#include "datapack/proto.h"
#include "datapack/registry.h"
#include "engine/engine.h"
#include "opendrive/lane_graph.h"
#include "opendrive/parser.h"
#include "traffic_pool/pool.h"

namespace convoy::engines::road_user_pool {

namespace tp = convoy::traffic_pool;
using nlohmann::json;

namespace {
constexpr double kRearAxleFraction = 0.25;

double number(const json& v, const char* key, double fallback, const std::string& who) {
  if (!v.contains(key)) return fallback;
  if (!v.at(key).is_number()) {
    throw std::runtime_error(who + ": " + key + " must be a number, got " + v.at(key).dump());
  }
  return v.at(key).get<double>();
}

tp::VehicleSpec listed(const json& v, size_t k) {
  const std::string where = "Vehicles[" + std::to_string(k) + "]";
  if (!v.is_object()) throw std::runtime_error(where + " must be an object");
  tp::VehicleSpec s;
  if (!v.contains("Id") || !v.at("Id").is_string()) {
    throw std::runtime_error(where + ": Id (a string) is required");
  }
  s.id = v.at("Id").get<std::string>();
  const std::string who = "road user '" + s.id + "'";
  if (!v.contains("Road") || !v.contains("Lane")) {
    throw std::runtime_error(who + ": Road and Lane are required");
  }
  s.road = v.at("Road").is_string() ? v.at("Road").get<std::string>() : v.at("Road").dump();
  s.lane = static_cast<int>(number(v, "Lane", 0, who));
  s.s = number(v, "S", 10, who);
  s.speed = number(v, "Speed", 0, who);
  if (v.contains("Policy"))
    s.policy =
        v.at("Policy").is_string() ? v.at("Policy").get<std::string>() : v.at("Policy").dump();
  s.seed = static_cast<uint64_t>(number(v, "Seed", static_cast<double>(k), who));
  s.length = number(v, "Length", s.length, who);
  s.width = number(v, "Width", s.width, who);
  s.idm.v0 = number(v, "DesiredSpeed", s.idm.v0, who);
  s.idm.T = number(v, "TimeHeadway", s.idm.T, who);
  s.idm.s0 = number(v, "MinGap", s.idm.s0, who);
  s.idm.a = number(v, "MaxAcceleration", s.idm.a, who);
  s.idm.b = number(v, "ComfortableDeceleration", s.idm.b, who);
  s.mobil.politeness = number(v, "Politeness", s.mobil.politeness, who);
  if (v.contains("To")) {
    const json& to = v.at("To");
    if (!to.is_object() || !to.contains("Road") || !to.contains("Lane")) {
      throw std::runtime_error(who + ": To must be {\"Road\": ..., \"Lane\": ...}");
    }
    s.to = std::make_pair(
        to.at("Road").is_string() ? to.at("Road").get<std::string>() : to.at("Road").dump(),
        static_cast<int>(number(to, "Lane", 0, who)));
  }
  return s;
}
// The external road users' boxes (centre = reference point + length_offset along the heading);
// absent ones left out. A field that is not finite, or a size that is not positive, throws
// naming the road user and the field.
std::vector<tp::ExternalUser> external_users(const data::RoadUsers& users) {
  std::vector<tp::ExternalUser> out;
  for (int k = 0; k < users.users_size(); ++k) {
    const data::RoadUser& u = users.users(k);
    if (u.absent()) continue;
    const std::string who = "users[" + std::to_string(k) + "] ('" + u.id() + "')";
    const auto finite = [&](const char* field, double v) {
      if (!std::isfinite(v)) {
        throw std::runtime_error(who + ": " + field + " must be finite, got " + std::to_string(v));
      }
    };
    const auto positive = [&](const char* field, double v) {
      if (!(v > 0 && v < 1000)) {
        throw std::runtime_error(who + ": " + field + " must be > 0 m (the box), got " +
                                 std::to_string(v));
      }
    };
    if (u.id().empty()) throw std::runtime_error(who + ": id is empty");
    finite("x", u.x());
    finite("y", u.y());
    finite("yaw", u.yaw());
    finite("speed", u.speed());
    finite("length_offset", u.length_offset());
    positive("length", u.length());
    positive("width", u.width());
    tp::ExternalUser e;
    e.id = u.id();
    e.yaw = u.yaw();
    e.x = u.x() + u.length_offset() * std::cos(u.yaw());
    e.y = u.y() + u.length_offset() * std::sin(u.yaw());
    e.speed = u.speed();
    e.length = u.length();
    e.width = u.width();
    out.push_back(std::move(e));
  }
  return out;
}

// The traffic_lights engine's {"signals": {"<signal id>": state}}; anything else throws naming
// `where` (and the signal).
road_users::LightStates light_states(const json& j, const std::string& where) {
  if (!j.is_object() || !j.contains("signals") || !j.at("signals").is_object()) {
    throw std::runtime_error(where + ": expected {\"signals\": {\"<signal id>\": state}}, got " +
                             j.dump().substr(0, 200));
  }
  road_users::LightStates out;
  for (const auto& [id, v] : j.at("signals").items()) {
    using road_users::Light;
    const std::string st = v.is_string() ? v.get<std::string>() : "";
    const Light l = st == "red"          ? Light::kRed
                    : st == "red_yellow" ? Light::kRedYellow
                    : st == "yellow"     ? Light::kYellow
                    : st == "green"      ? Light::kGreen
                                         : Light::kOff;
    if (l == Light::kOff && st != "off") {
      throw std::runtime_error(where + ": signals." + id +
                               ": expected \"red\", \"yellow\", \"green\", \"red_yellow\" or "
                               "\"off\", got " +
                               v.dump());
    }
    out.emplace(id, l);
  }
  return out;
}
}  // namespace

class RoadUserPoolEngine final : public Engine {
 public:
  std::vector<engine::DataPackId> initialize(const std::string& name, const json& config,
                                             int64_t timestep_ns) override {
    name_ = name;
    config_ = config;
    dp_name_ = config.value("RoadUsersDataPack", "road_users");
    ext_name_ = config.value("ExternalDataPack", "external_users");
    cmd_name_ = config.value("CommandDataPack", "commands");
    lights_name_ = config.value("TrafficLightsDataPack", "");
    try {
      map_ = std::make_unique<opendrive::Network>(opendrive::load(config.at("Map")));
      graph_ = std::make_unique<opendrive::LaneGraph>(*map_);
      net_ = std::make_unique<tp::PoolNetwork>(*graph_);
      build();
    } catch (const std::exception& e) {  // the map or the road users given: exit 2
      throw UserError("road_user_pool engine '" + name + "': " + e.what());
    }
    (void)timestep_ns;
    std::vector<engine::DataPackId> ids(1);
    ids[0].set_name(dp_name_);
    ids[0].set_type(std::string(datapack::type_name<data::RoadUsers>()));
    ids[0].set_engine_name(name);
    return ids;
  }

  int64_t step(int64_t duration_ns) override {
    try {
      pool_->step(duration_ns * 1e-9);
    } catch (const tp::PoolError& e) {  // a command's (a route with no path): as set_commands
      throw std::runtime_error("road_user_pool engine '" + name_ + "': datapack '" + cmd_name_ +
                               "': " + e.what());
    }
    time_ns_ += duration_ns;
    publish();
    return time_ns_;
  }

  void set_datapack(const datapack::View& dp) override {
    if (!dp.empty() && dp.id().name() == cmd_name_) return set_commands(dp);
    if (!dp.empty() && !lights_name_.empty() && dp.id().name() == lights_name_) {
      return set_lights(dp);
    }
    if (dp.empty() || dp.id().name() != ext_name_) return;
    const std::string where = "road_user_pool engine '" + name_ + "': datapack '" + ext_name_ + "'";
    data::RoadUsers users;
    try {
      if (dp.is_proto() && dp.proto_type() == datapack::type_name<data::RoadUsers>()) {
        datapack::read_proto(dp, &users);
      } else if (dp.is_proto() && dp.proto_type() == datapack::type_name<data::RoadUser>()) {
        datapack::read_proto(dp, users.add_users());
      } else {
        throw std::runtime_error(std::string("expected convoy.data.RoadUsers or RoadUser, got ") +
                                 (dp.is_proto() ? dp.proto_type() : std::string("JSON")));
      }
      pool_->set_external(external_users(users));
    } catch (const std::exception& e) {
      throw UserError(where + ": " + e.what());
    }
  }

  // <CommandDataPack>: {"<road user id>": command}, the agents' command contract, for the next
  // step. Bad content stops the run as it does an agent's (exit 3), naming the road user.
  void set_commands(const datapack::View& dp) {
    const std::string where = "road_user_pool engine '" + name_ + "': datapack '" + cmd_name_ + "'";
    if (!dp.is_json()) throw std::runtime_error(where + ": expected a JSON datapack of commands");
    try {
      pool_->set_commands(datapack::read_json(dp), where, name_ + "/", 0.5 - kRearAxleFraction);
    } catch (const tp::PoolError& e) {
      throw std::runtime_error(e.what());
    }
  }

  // <TrafficLightsDataPack>: the signals' states the pool's lights follow from now on.
  void set_lights(const datapack::View& dp) {
    const std::string where =
        "road_user_pool engine '" + name_ + "': datapack '" + lights_name_ + "'";
    if (!dp.is_json()) {
      throw std::runtime_error(where + ": expected the traffic_lights engine's JSON datapack");
    }
    pool_->set_light_states(light_states(datapack::read_json(dp), where));
  }

  void get_datapack(const engine::DataPackId& id, datapack::Builder& out) override {
    if (id.name() == dp_name_) datapack::write_proto(out, users_);
  }

  void reset() override {
    time_ns_ = 0;
    build();
  }

 private:
  void build() {
    std::vector<tp::VehicleSpec> specs;
    const json& list = config_.value("Vehicles", json::array());
    if (!list.is_array()) throw std::runtime_error("Vehicles must be a list");
    for (size_t k = 0; k < list.size(); ++k) specs.push_back(listed(list[k], k));
    tp::VehicleSpec base;
    base.policy = config_.value("Policy", "idm_mobil");
    base.idm.v0 = config_.value("DesiredSpeed", 13.9);
    const std::vector<tp::ClearZone> clear = keep_clear();
    const size_t count = spawn_count(base, clear);
    if (count > 0) {
      auto more = tp::spawn(*net_, count, config_.value("Seed", 1), base, "pool/", clear);
      specs.insert(specs.end(), more.begin(), more.end());
    }
    pool_ = std::make_unique<tp::Pool>(*net_, std::move(specs));
    if (!lights_name_.empty()) pool_->set_light_states({});  // all green until the first states
    const size_t walkers = walker_count(clear);
    if (walkers > 0) {
      pool_->set_walkers(
          tp::spawn_walkers(*net_, walkers, config_.value("Seed", 1), "walker/", clear));
    }
    users_.Clear();
    for (size_t i = 0; i < pool_->size(); ++i) {
      const tp::VehicleSpec& s = pool_->spec(i);
      add_user(s.id, "car", "sedan", s.length, s.width, 1.45)
          ->set_length_offset(s.length * (0.5 - kRearAxleFraction));
    }
    const tp::PoolWalkers* w = pool_->walkers();
    for (size_t i = 0; w && i < w->size(); ++i) {
      const tp::WalkerSpec& s = w->spec(i);
      add_user(s.id, "pedestrian", "walker", s.length, s.width, s.height);
    }
    publish();
  }

  data::RoadUser* add_user(const std::string& id, const char* category, const char* model,
                           double length, double width, double height) {
    data::RoadUser* u = users_.add_users();
    u->set_id(name_ + "/" + id);
    u->set_category(category);
    u->set_model(model);
    u->set_length(length);
    u->set_width(width);
    u->set_height(height);
    return u;
  }

  std::vector<tp::ClearZone> keep_clear() const {
    std::vector<tp::ClearZone> out;
    const json& list = config_.value("KeepClear", json::array());
    for (size_t k = 0; k < list.size(); ++k) {
      const std::string who = "KeepClear[" + std::to_string(k) + "]";
      if (!list[k].is_object()) throw std::runtime_error(who + " must be {X, Y, Radius}");
      tp::ClearZone z;
      z.x = number(list[k], "X", 0, who);
      z.y = number(list[k], "Y", 0, who);
      z.radius = number(list[k], "Radius", 0, who);
      if (!(z.radius > 0)) throw std::runtime_error(who + ": Radius must be > 0 m");
      out.push_back(z);
    }
    return out;
  }

  // How many to spawn: the count key, or the density key (per km of `where`) times the map's km
  // of it, rounded; a density the map cannot hold names the key and the map's capacity.
  struct CountKeys {
    const char *count, *density, *what, *per, *where;
    double km, spacing;
    std::function<size_t()> capacity;
  };
  size_t count_of(const CountKeys& k) const {
    const size_t given = config_.value(k.count, 0);
    if (!config_.contains(k.density)) return given;
    const json& d = config_.at(k.density);
    if (!d.is_number() || !(d.get<double>() >= 0)) {
      throw std::runtime_error(std::string(k.density) + " must be a number >= 0 (" + k.what +
                               " per km of " + k.per + "), got " + d.dump());
    }
    const std::string density_key = k.density;
    if (d.get<double>() == 0) return given;  // 0: unused, the count counts
    if (given != 0) {
      throw std::runtime_error("give " + std::string(k.count) + " or " + density_key +
                               ", not both (or " + density_key + " 0)");
    }
    const double density = d.get<double>();
    const auto count = static_cast<size_t>(std::llround(density * k.km));
    const size_t capacity = k.capacity();
    if (count > capacity) {
      char m[400];
      std::snprintf(m, sizeof m,
                    "%s %g %s/km cannot fit the map %s: %zu %s on its %.2f km of %s, which hold "
                    "at most %zu (%.1f %s/km, %.1f m apart)",
                    k.density, density, k.what, config_.value("Map", "").c_str(), count, k.what,
                    k.km, k.where, capacity, k.km > 0 ? capacity / k.km : 0.0, k.what, k.spacing);
      throw std::runtime_error(m);
    }
    return count;
  }

  // Count, or Density (vehicles per km of driving lane outside junctions).
  size_t spawn_count(const tp::VehicleSpec& base, const std::vector<tp::ClearZone>& clear) const {
    return count_of({"Count", "Density", "vehicles", "driving lane",
                     "driving lanes outside junctions", tp::driving_km(*net_),
                     base.length + base.idm.s0 + 2,
                     [&] { return tp::spawn_capacity(*net_, base, clear); }});
  }

  // Pedestrians, or PedestrianDensity (walkers per km of sidewalk).
  size_t walker_count(const std::vector<tp::ClearZone>& clear) const {
    return count_of({"Pedestrians", "PedestrianDensity", "pedestrians", "sidewalk", "sidewalk",
                     tp::sidewalk_km(*net_), tp::kWalkerSpacing,
                     [&] { return tp::walker_capacity(*net_, clear); }});
  }

  void publish() {
    users_.set_time_ns(time_ns_);
    for (size_t i = 0; i < pool_->size(); ++i) {
      data::RoadUser* u = users_.mutable_users(static_cast<int>(i));
      const double yaw = pool_->yaw(i), c = std::cos(yaw), sn = std::sin(yaw);
      const double back = u->length_offset(), v = pool_->speed(i);
      u->set_x(pool_->x(i) - back * c);
      u->set_y(pool_->y(i) - back * sn);
      u->set_yaw(yaw);
      u->set_speed(v);
      u->set_acceleration(pool_->acceleration(i));
      u->set_vx(v * c);
      u->set_vy(v * sn);
      u->set_lights(pool_->acceleration(i) < -0.5 ? data::RoadUser::BRAKE : 0);
      u->set_time_ns(time_ns_);
      if (pool_->standing(i)) {  // put off the lanes by a command
        u->set_road("");
        u->set_lane(0);
        u->set_s(0);
        continue;
      }
      const tp::PoolLane& lane = net_->lane(pool_->lane(i));
      const opendrive::LaneNode& node = graph_->lane(lane.graph_lane);
      u->set_road(lane.road_id);
      u->set_lane(lane.lane_id);
      u->set_s(node.forward ? node.s0 + pool_->s(i) : node.s1 - pool_->s(i));
    }
    const tp::PoolWalkers* w = pool_->walkers();
    for (size_t i = 0; w && i < w->size(); ++i) {
      data::RoadUser* u = users_.mutable_users(static_cast<int>(pool_->size() + i));
      const double yaw = w->yaw(i), v = w->speed(i);
      u->set_x(w->x(i));
      u->set_y(w->y(i));
      u->set_yaw(yaw);
      u->set_speed(v);
      u->set_acceleration(w->acceleration(i));
      u->set_vx(v * std::cos(yaw));
      u->set_vy(v * std::sin(yaw));
      u->set_walk_phase(w->walk_phase(i));
      u->set_time_ns(time_ns_);
    }
  }

  std::string name_, dp_name_, ext_name_, cmd_name_, lights_name_;
  json config_;
  std::unique_ptr<opendrive::Network> map_;
  std::unique_ptr<opendrive::LaneGraph> graph_;
  std::unique_ptr<tp::PoolNetwork> net_;
  std::unique_ptr<tp::Pool> pool_;
  data::RoadUsers users_;
  int64_t time_ns_ = 0;
};

CONVOY_REGISTER_ENGINE("road_user_pool", RoadUserPoolEngine);

}  // namespace convoy::engines::road_user_pool
