// convoy-odr query: the answer to each request (cmd_query in convoy_odr.cpp reads them a line
// at a time from stdin and writes the replies). The ops are the library's
// (src/opendrive/query.h), which Python's RoadMap.query answers in-process as well.
#include "opendrive/query.h"

#include <nlohmann/json.hpp>

nlohmann::json query_one(const convoy::opendrive::LaneGraph& g, const nlohmann::json& q) {
  return convoy::opendrive::query(g, q);
}
