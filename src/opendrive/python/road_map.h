// One OpenDRIVE map loaded in-process for Python: the network, its lane graph and the lookups
// python/convoy_scenario/roads.py's RoadMap offers (road ids are strings, lane ids ints,
// angles rad, lengths m). Typed lookups build their Python results directly (a lane_pose is
// a few microseconds); query() answers the JSON ops of `convoy-odr query` (opendrive/query.h).
//
// Every error is a C++ exception whose message names the file (and the line, for the
// parser's), the road and the lane; module.cpp raises it in Python as
// convoy_scenario.xmltree.ScenarioError.
#pragma once

#include <pybind11/pybind11.h>

#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "opendrive/lane_graph.h"

namespace convoy::opendrive::python {

namespace py = pybind11;

class RoadMap {
 public:
  // Loads and checks the file (the lane graph's links as well); throws naming it.
  explicit RoadMap(const std::string& path);

  const std::string& path() const { return path_; }
  // The parser's and the lane graph's non-fatal findings ("file: junction 4 ...").
  std::vector<std::string> warnings() const;

  std::vector<std::string> road_ids() const;
  double road_length(const std::string& road) const;
  const std::string& road_junction(const std::string& road) const;

  // (x, y, z, heading, pitch): t from the lane centre (OpenDRIVE t, left of the reference
  // direction positive), heading of the lane's driving direction at s, pitch of the road in
  // that direction (OpenSCENARIO's sign: positive nose down, so uphill is negative).
  py::tuple lane_pose(const std::string& road, int lane, double s, double t) const;
  // (x, y, z, heading): t from the reference line, heading of the reference line.
  py::tuple road_pose(const std::string& road, double s, double t) const;
  // type, width, s0, s1, forward, junction, left, right (the lane ids beside it to the left /
  // right of its driving direction, across the centre lane too; None at the road's edge),
  // change_left, change_right (a lane change there is allowed: a lane driven the same way and
  // a road mark between that may be crossed), centre_t (of the lane centre, from the
  // reference line).
  py::dict lane_info(const std::string& road, int lane, double s) const;
  // Lane ids of the section at s, left to right (highest id first), without the centre lane.
  std::vector<int> lanes_at(const std::string& road, double s) const;
  // [dict(road, lane, s, forward, junction, type)] of the lanes that follow / precede in the
  // driving direction: s where a next lane is entered (its section's start if forward, else
  // its end) and where a previous lane is left (its end if forward, else its start).
  py::list next_lanes(const std::string& road, int lane, double s) const;
  py::list prev_lanes(const std::string& road, int lane, double s) const;
  // dict(road, lane, s, t, road_t, heading, z, distance, type, junction) or None.
  py::object locate(double x, double y, std::optional<double> heading, double max_distance,
                    const std::optional<std::vector<std::string>>& lane_types) const;
  // The query ops "route" and "follow" (their replies as dicts).
  py::object route(const py::sequence& from, const py::sequence& to, double ds) const;
  py::object follow(const std::string& road, int lane, double s, double length, double ds) const;
  // Any query op: request is a dict with "op"; errors read "file: op: message".
  py::object query(const py::dict& request) const;

 private:
  const Road& road(const std::string& id) const;
  py::list neighbours(const std::vector<LaneIndex>& lanes, bool entry) const;
  nlohmann::json ask(const nlohmann::json& request) const;

  std::string path_;
  std::string name_;  // the file's base name, for query errors
  std::unique_ptr<Network> net_;
  std::unique_ptr<LaneGraph> graph_;
  std::unordered_map<std::string, const Road*> roads_;
};

}  // namespace convoy::opendrive::python
