// The parts of a road user's config that both agents read alike: a lane "ROAD:LANE", a
// StartPose {x, y, yaw}, and where a point placed off its lanes is. Errors throw CommandError
// (key, detail) in the config validator's style; the host prefixes its name.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>

#include "opendrive/lane_graph.h"

namespace convoy::road_users {

// "ROAD:LANE" with a non-zero lane id -> (road, lane).
std::pair<std::string, int> parse_lane_ref(const std::string& key, const nlohmann::json& v);

// StartPose {x, y, yaw}: finite numbers, no other key.
opendrive::Pose2 parse_start_pose(const nlohmann::json& sp);

// "no road within 50 m", or "nearest lane ROAD:LANE (type) D m away" for `loc`.
std::string nearest_lane_text(const opendrive::LaneGraph& graph,
                              const std::optional<opendrive::LanePosition>& loc);

}  // namespace convoy::road_users
