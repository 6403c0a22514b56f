// The road users of a datapack holding a convoy.data.RoadUsers (or one RoadUser), read in
// place (road_user_wire.h): what the road-user hosts do with their neighbours datapack.
#pragma once

#include <functional>

#include "datapack/datapack.h"
#include "road_user_wire/road_user_wire.h"

namespace convoy::road_user_wire {

// Calls `visit` for each user. Throws std::invalid_argument ("expected convoy.data.RoadUsers
// or RoadUser, got ...", "corrupt ...") when it holds another type (or JSON), or bytes that
// are not such a message; the caller names the datapack.
void for_each_user(const datapack::View& dp, const std::function<void(const UserFields&)>& visit);

}  // namespace convoy::road_user_wire
