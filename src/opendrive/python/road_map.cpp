#include "opendrive/python/road_map.h"

#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>
#include <stdexcept>

#include "opendrive/parser.h"
#include "opendrive/python/json_py.h"
#include "opendrive/query.h"

namespace convoy::opendrive::python {

namespace {

// The lane next to `n` on the side of +t (plus_t) or -t, across the centre lane too; None at
// the road's edge.
py::object beside(const LaneNode& n, bool plus_t) {
  const int step = plus_t ? 1 : -1;
  int id = n.lane_id + step;
  if (id == 0) id += step;
  if (!n.road->sections[n.section].find_lane(id)) return py::none();
  return py::int_(id);
}

}  // namespace

RoadMap::RoadMap(const std::string& path)
    : path_(path), name_(std::filesystem::path(path).filename().string()) {
  py::gil_scoped_release unlocked;
  net_ = std::make_unique<Network>(load(path));
  graph_ = std::make_unique<LaneGraph>(*net_);
  for (const Road& r : net_->roads) roads_.emplace(r.id, &r);
}

std::vector<std::string> RoadMap::warnings() const {
  std::vector<std::string> out = net_->warnings;
  out.insert(out.end(), graph_->warnings().begin(), graph_->warnings().end());
  return out;
}

const Road& RoadMap::road(const std::string& id) const {
  auto it = roads_.find(id);
  if (it == roads_.end()) throw std::runtime_error(path_ + ": no road with id '" + id + "'");
  return *it->second;
}

std::vector<std::string> RoadMap::road_ids() const {
  std::vector<std::string> out;
  for (const Road& r : net_->roads) out.push_back(r.id);
  return out;
}

double RoadMap::road_length(const std::string& id) const { return road(id).length; }

const std::string& RoadMap::road_junction(const std::string& id) const { return road(id).junction; }

py::tuple RoadMap::lane_pose(const std::string& road_id, int lane, double s, double t) const {
  const LaneIndex i = graph_->require(road_id, lane, s);
  const LaneNode& n = graph_->lane(i);
  const WorldPose p = graph_->world_pose(road_id, lane, s, t);
  double dz = 0;
  evaluate(n.road->elevation_profile, s, &dz);
  const double pitch = 0.0 - std::atan(n.forward ? dz : -dz);  // 0, not -0, when flat
  return py::make_tuple(p.x, p.y, p.z, p.heading, pitch);
}

py::tuple RoadMap::road_pose(const std::string& road_id, double s, double t) const {
  const Road& r = road(road_id);
  const Pose2 p = r.offset_point(s, t);
  return py::make_tuple(p.x, p.y, r.surface_z(s, t), p.heading);
}

py::dict RoadMap::lane_info(const std::string& road_id, int lane, double s) const {
  const LaneNode& n = graph_->lane(graph_->require(road_id, lane, s));
  const LaneBorders b = n.road->lane_borders(n.section, std::clamp(s, n.s0, n.s1), lane);
  py::dict out;
  out["type"] = n.type;
  out["width"] = std::abs(b.outer - b.inner);
  out["s0"] = n.s0;
  out["s1"] = n.s1;
  out["forward"] = n.forward;
  out["junction"] = n.junction;
  out["left"] = beside(n, n.forward);
  out["right"] = beside(n, !n.forward);
  out["change_left"] = n.left() != kNoLane && n.change_left();
  out["change_right"] = n.right() != kNoLane && n.change_right();
  out["centre_t"] = 0.5 * (b.inner + b.outer);
  return out;
}

std::vector<int> RoadMap::lanes_at(const std::string& road_id, double s) const {
  const Road& r = road(road_id);
  const LaneSection& sec = r.sections[r.section_index(std::clamp(s, 0.0, r.length))];
  std::vector<int> out;
  for (const Lane& l : sec.lanes) {
    if (l.id != 0) out.push_back(l.id);
  }
  std::sort(out.rbegin(), out.rend());
  return out;
}

py::list RoadMap::neighbours(const std::vector<LaneIndex>& lanes, bool entry) const {
  py::list out;
  for (LaneIndex i : lanes) {
    const LaneNode& n = graph_->lane(i);
    py::dict d;
    d["road"] = n.road->id;
    d["lane"] = n.lane_id;
    d["s"] = (n.forward == entry) ? n.s0 : n.s1;
    d["forward"] = n.forward;
    d["junction"] = n.junction;
    d["type"] = n.type;
    out.append(std::move(d));
  }
  return out;
}

py::list RoadMap::next_lanes(const std::string& road_id, int lane, double s) const {
  return neighbours(graph_->successors(graph_->require(road_id, lane, s)), true);
}

py::list RoadMap::prev_lanes(const std::string& road_id, int lane, double s) const {
  return neighbours(graph_->predecessors(graph_->require(road_id, lane, s)), false);
}

py::object RoadMap::locate(double x, double y, std::optional<double> heading, double max_distance,
                           const std::optional<std::vector<std::string>>& lane_types) const {
  std::optional<LanePosition> p;
  if (lane_types) {
    const std::set<std::string> types(lane_types->begin(), lane_types->end());
    p = graph_->locate_if(x, y, heading, max_distance,
                          [&](const LaneNode& n, double) { return types.count(n.type) > 0; });
  } else {
    p = graph_->locate(x, y, heading, max_distance);
  }
  if (!p) return py::none();
  const LaneNode& n = graph_->lane(p->lane);
  py::dict out;
  out["road"] = p->road_id;
  out["lane"] = p->lane_id;
  out["s"] = p->s;
  out["t"] = p->t;
  out["road_t"] = p->road_t;
  out["heading"] = p->heading;
  out["z"] = n.road->surface_z(p->s, p->road_t);
  out["distance"] = p->distance;
  out["type"] = n.type;
  out["junction"] = n.junction;
  return out;
}

nlohmann::json RoadMap::ask(const nlohmann::json& request) const {
  py::gil_scoped_release unlocked;
  return opendrive::query(*graph_, request);
}

py::object RoadMap::route(const py::sequence& from, const py::sequence& to, double ds) const {
  return from_json(
      ask({{"op", "route"}, {"from", to_json(from)}, {"to", to_json(to)}, {"ds", ds}}));
}

py::object RoadMap::follow(const std::string& road_id, int lane, double s, double length,
                           double ds) const {
  return from_json(ask({{"op", "follow"},
                        {"road", road_id},
                        {"lane", lane},
                        {"s", s},
                        {"length", length},
                        {"ds", ds}}));
}

py::object RoadMap::query(const py::dict& request) const {
  const nlohmann::json q = to_json(request);
  nlohmann::json reply;
  try {
    reply = ask(q);
  } catch (const std::exception& e) {
    const std::string op =
        q.contains("op") && q["op"].is_string() ? q["op"].get<std::string>() : "None";
    throw std::runtime_error(name_ + ": " + op + ": " + e.what());
  }
  return from_json(reply);
}

}  // namespace convoy::opendrive::python
