// A serialized convoy.data.RoadUsers (proto/convoy/road_users.proto) read in place: the
// fields a road user's behaviour looks at, for each user, without building protobuf messages.
// An agent at 100 Hz reads ~100 neighbours a step; this reads them at a fraction of the cost
// of parsing the messages (docs/road_users.md, "Road-user processes").
//
// Protobuf's rules hold: unknown fields are skipped, a field given twice keeps its last
// value, a missing one is its default (0, false, "").
#pragma once

#include <functional>
#include <string_view>

namespace convoy::road_user_wire {

struct UserFields {
  std::string_view id, category;  // into the bytes read
  bool absent = false;
  double x = 0, y = 0, yaw = 0, speed = 0;
  double length = 0, width = 0, length_offset = 0;
};

// One serialized convoy.data.RoadUser. False when the bytes are not a valid message.
bool read_user(std::string_view bytes, UserFields* out);

// Each user of a serialized convoy.data.RoadUsers, in order. False (after the users before
// the fault) when the bytes are not a valid message.
bool for_each_user(std::string_view bytes, const std::function<void(const UserFields&)>& visit);

}  // namespace convoy::road_user_wire
