// Shared by the command tests: the lane graph of tests/opendrive/data/lane_graph.xodr, loaded
// once, and the message a command parser rejects a command with.
#pragma once

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "opendrive/lane_graph.h"
#include "opendrive/parser.h"
#include "road_users/command_parts.h"

namespace convoy::road_users::testing {

struct Map {
  opendrive::Network net = opendrive::load(CONVOY_LANE_GRAPH_XODR);
  opendrive::LaneGraph graph{net};
};

inline const Map& map() {
  static const Map m;
  return m;
}

// The message `parse` rejects `j` with ("accepted" if it does not); what() is key: detail.
template <class Parse>
std::string rejection(Parse parse, const nlohmann::json& j) {
  try {
    parse(j);
  } catch (const CommandError& e) {
    EXPECT_EQ(std::string(e.what()), e.key() + ": " + e.detail());
    return e.what();
  }
  return "accepted";
}

}  // namespace convoy::road_users::testing
