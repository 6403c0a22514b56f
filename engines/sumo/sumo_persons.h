// SUMO's persons (walking its sidewalks, crossings and walking areas) as pedestrian road users,
// for the sumo engine's PersonsDataPack (sumo_engine.h).
//
// Each person SUMO has after a step is a RoadUser "<engine>/<person id>", category
// "pedestrian", model its vType, its size from the vType, at its position (SUMO's position of
// a walking person, taken as its centre) in the map's frame, its heading and speed; a person
// that left the simulation, or boarded a vehicle (then the vehicle carries it), appears once
// with `absent`, then no more. Persons are listed sorted by id, the departed first.
#pragma once

#include <map>
#include <string>
#include <unordered_map>

#include "convoy/road_users.pb.h"
#include "sumo_net.h"

namespace convoy::engines::sumo {

class PersonReader {
 public:
  PersonReader() = default;
  PersonReader(std::string prefix, NetOffset offset)
      : prefix_(std::move(prefix)), offset_(offset) {}

  // `out` becomes every person after the step ending at `time_ns` (`dt` s long).
  void read(int64_t time_ns, double dt, data::RoadUsers& out);
  void reset() { tracked_.clear(); }

 private:
  struct Tracked {
    double yaw = 0;
    data::RoadUser last;
  };
  struct Size {
    double length = 0, width = 0, height = 0;
  };
  const Size& size_of(const std::string& type);

  std::string prefix_;
  NetOffset offset_;
  std::map<std::string, Tracked> tracked_;
  std::unordered_map<std::string, Size> sizes_;
};

}  // namespace convoy::engines::sumo
