// The road users around a driver, as it sees them, and the questions asked of them: who leads
// on its path, who leads and follows in a lane beside it (for MOBIL), whether a spot is free.
// The host fills the list from whatever it receives (a datapack, a spatial grid); nothing here
// knows the transport.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "road_users/mobil.h"
#include "road_users/path.h"

namespace convoy::road_users {

// Another road user: its id, reference point (a vehicle's rear axle), heading, speed and box.
struct Neighbour {
  std::string id;
  double x = 0, y = 0, yaw = 0;
  double speed = 0;
  double length = 0, width = 0;  // width 0: unknown
  double length_offset = 0;      // the box's centre, ahead of the reference point (m)
};

// The others present around it (not itself, not absent ones), in the order received: ties are
// settled by that order.
using Neighbours = std::vector<Neighbour>;

// The driver that looks: its id, reference point, heading, speed, and how far it looks.
struct Observer {
  std::string_view id;
  double x = 0, y = 0, yaw = 0;
  double speed = 0;
  double radius = 100;  // m
};

// The nearest one ahead in its lane along `path`, whose front bumper is at arc `front`: gap
// from that front to the other's rear (negative when they overlap) and its speed. Among those
// within me.radius of the observer, projected on poses [cursor - 10, cursor + radius /
// pose_spacing + 2), at most 1 m + half its width (1.8 m when unknown) to the side, with its
// front ahead of mine. Not found: gap +inf.
LaneNeighbour leader_on(const Path& path, size_t cursor, double front, double pose_spacing,
                        const Observer& me, const Neighbours& around);

// The leader and follower in a band of the road `half_width` m either side of the lateral
// offset `centre` (m, left positive) in the observer's frame, within me.radius along its
// heading. The observer's box spans [rear, front] along its heading (m from its reference
// point); one whose front is ahead of that front and rear ahead of that rear leads, any other
// follows (a negative gap: beside it).
LaneNeighbours lane_neighbours(const Observer& me, const Neighbours& around, double centre,
                               double half_width, double front, double rear);

// Whether nobody's reference point is within `clearance` m of (x, y): a respawn spot is free.
bool start_free(const Neighbours& around, double x, double y, double clearance);

}  // namespace convoy::road_users
