// Lane lookups as JSON requests and replies: what `convoy-odr query` answers a line at a time
// (tools/opendrive) and what Python's RoadMap.query answers in-process
// (src/opendrive/python, python/convoy_scenario/roads.py). Both call query() below, so their
// replies are the same.
//
// Requests (a JSON object with "op") and replies (a JSON object; errors are thrown):
//   {"op": "pose", "road", "lane", "s", "offset"}      -> x, y, z, heading (driving direction)
//   {"op": "locate", "x", "y"[, "yaw"][, "max_distance"]} -> found, road, lane, s, t, road_t, z,
//                                                         heading, distance, type, junction (or
//                                                         "found": false)
//   {"op": "follow", "road", "lane", "s", "length"[, "ds"]}
//        -> points [[x, y, heading], ...]: the lane followed onward from s in its driving
//           direction for `length` m, at each junction the successor whose heading changes
//           least (straight on), ties by lane index; "length" the length reached (shorter at a
//           dead end), "lanes" [[road, lane], ...] the lanes passed
//   {"op": "route", "from": [road, lane, s], "to": [road, lane, s][, "ds"][, "lane_changes"]}
//        -> points, length: the shortest route between two lane positions
//   {"op": "info"} -> roads [{"id", "length", "junction"}], signals (traffic lights' ids)
//   {"op": "stop_lines"} -> stop_lines [{"id", "road", "x", "y", "heading", "t_min", "t_max",
//                        "entry_x", "entry_y"}]: for every traffic light (dynamic signal of
//                        type 1000001) the reference line's point at its s with the heading of
//                        the traffic it is for (the road's, turned round for orientation "-"),
//                        the lateral span of its lanes along that heading (left positive) and
//                        the end of its road that traffic drives into (the junction's edge).
//
// Needs convoy_worldgen (the signals' lane spans): the library is convoy_opendrive_query.
#pragma once

#include <nlohmann/json.hpp>

#include "opendrive/lane_graph.h"

namespace convoy::opendrive {

// The reply to one request. Throws std::runtime_error (a bad op, an unknown road or lane, no
// route) or nlohmann::json::exception (a missing or mistyped field) with the message the
// query tool sends back as "error".
nlohmann::json query(const LaneGraph& graph, const nlohmann::json& request);

}  // namespace convoy::opendrive
