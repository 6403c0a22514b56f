// EngineType "sumo" (registered in sumo_engine.cpp): SUMO background traffic, run in-process by
// libsumo (SUMO::libsumocpp). One engine holds SUMO's whole crowd of vehicles.
//
// Config keys (schema.json):
//   NetFile              SUMO network (.net.xml); or
//   OpenDriveFile        an .xodr, converted by netconvert at initialize and cached (sumo_net.h)
//   NetCacheDir          where converted networks are kept ("" = $XDG_CACHE_HOME/convoy/sumo,
//                        else ~/.cache/convoy/sumo)
//   RouteFiles           SUMO demand files: routes, trips or flows (a list)
//   AdditionalFiles      SUMO additional files (vTypes, detectors, TLS programs...) (a list)
//   Seed                 SUMO's random seed (default 42): the same seed gives the same run
//   SumoOptions          extra SUMO command-line options, e.g. ["--lateral-resolution", "0.8"]
//   VehiclesDataPack     name of the RoadUsers datapack written (default "vehicles")
//   PersonsDataPack      name of the RoadUsers datapack of SUMO's persons ("persons")
//   TrafficLightsDataPack name of the traffic-light JSON datapack written ("traffic_lights")
//   TrafficLightsLeader  "sumo" (SUMO runs its programs) | "external" (a datapack sets them)
//   ExternalRoadUsersDataPack  name of the datapack of road users put into SUMO
//                        ("external_road_users")
//   ExternalMatchDistance  an external road user whose front is farther than this from every
//                        lane SUMO lets its class use is left out of SUMO (m, default 5)
//   ExternalTrafficLightsDataPack  name of the datapack setting the lights when they are led
//                        from outside ("traffic_lights_in")
// SUMO's step length is the EngineTimestep.
//
// Datapacks written:
//   <VehiclesDataPack>   convoy.data.RoadUsers: every SUMO vehicle after the last step, as a
//                        RoadUser "<engine>/<sumo id>" in the map's frame; a vehicle that left
//                        appears once with `absent`, then no more. External road users are
//                        not in it (they publish themselves).
//   <PersonsDataPack>    convoy.data.RoadUsers: every walking SUMO person, as a pedestrian
//                        "<engine>/<person id>" (sumo_persons.h).
//   <TrafficLightsDataPack> JSON {time_ns, leader, lights: {<tls id>: {state, phase, program,
//                        links: [{index, from, to, via}]}}} (docs/architecture.md).
// Datapacks read:
//   <ExternalRoadUsersDataPack>  convoy.data.RoadUsers or RoadUser (or the same as JSON):
//                        each road user is added to SUMO as a vehicle the first time, moved
//                        with moveToXY each step, removed when absent; SUMO's vehicles react
//                        to it.
//   <ExternalTrafficLightsDataPack> JSON {lights: {<tls id>: {state: "GrGr"}}} or
//                        {<tls id>: "GrGr"}, applied with setRedYellowGreenState when
//                        TrafficLightsLeader is "external".
#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <unordered_map>
#include <vector>

#include "convoy/road_users.pb.h"
#include "engine/engine.h"
#include "sumo_net.h"
#include "sumo_persons.h"

namespace convoy::engines::sumo {

class SumoEngine final : public Engine {
 public:
  ~SumoEngine() override;
  std::vector<engine::DataPackId> initialize(const std::string& name, const nlohmann::json& config,
                                             int64_t timestep_ns) override;
  int64_t step(int64_t duration_ns) override;
  void set_datapack(const datapack::View& dp) override;
  void get_datapack(const engine::DataPackId& id, datapack::Builder& out) override;
  void reset() override;
  void shutdown() override;
  std::vector<std::string> take_warnings() override { return std::move(warnings_); }

 private:
  struct TypeInfo {
    std::string category;
    double length = 0, width = 0, height = 0;
  };
  struct Tracked {
    double yaw = 0;
    data::RoadUser last;
  };

  void load();
  void apply_external_users();
  void apply_external_lights();
  void read_vehicles();
  void read_traffic_lights();
  const TypeInfo& type_info(const std::string& type_id);
  void warn_once(const std::string& key, const std::string& text);
  [[noreturn]] void fail(const std::string& what) const;

  std::string name_;
  std::vector<std::string> args_;
  NetOffset offset_;
  int64_t timestep_ns_ = 0;
  int64_t time_ns_ = 0;
  bool loaded_ = false;
  bool lights_external_ = false;
  double match_distance_ = 5.0;
  std::string vehicles_dp_, persons_dp_, lights_dp_, ext_users_dp_, ext_lights_dp_;

  std::unordered_map<std::string, TypeInfo> types_;
  std::map<std::string, Tracked> tracked_;  // SUMO's own vehicles seen so far
  data::RoadUsers vehicles_;
  PersonReader persons_;  // SUMO's persons as pedestrians (sumo_persons.h)
  data::RoadUsers persons_data_;
  nlohmann::json lights_;
  std::map<std::string, nlohmann::json> tls_links_;  // per TLS, its controlled links

  std::map<std::string, data::RoadUser> pending_users_;  // external, received since last step
  std::map<std::string, std::string> in_sumo_;           // external id -> SUMO id
  std::map<std::string, std::string> pending_lights_;
  std::map<std::string, bool> warned_;
  std::vector<std::string> warnings_;
  double sumo_s_ = 0, read_s_ = 0, write_s_ = 0;  // time spent, for the log
};

}  // namespace convoy::engines::sumo
