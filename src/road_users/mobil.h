// MOBIL (Kesting, Treiber, Helbing 2007), the lane-change decision: change when the driver's
// own gain in IDM acceleration, plus `politeness` times the gain of the followers it affects,
// exceeds a threshold, and the new follower would not have to brake harder than b_safe.
// Finding the neighbours is the caller's business; this is the arithmetic.
#pragma once

#include <cmath>

#include "road_users/idm.h"

namespace convoy::road_users {

// A driver's MOBIL parameters.
struct Mobil {
  double politeness = 0.3;  // weight of the others' gain against its own
  double threshold = 0.2;   // m/s^2 the weighted gain must exceed
  double b_safe = 4.0;      // m/s^2 the new follower may at most be made to brake
};

// The nearest road user ahead (or behind) in one lane: gap bumper to bumper (m; negative: it
// overlaps, beside the driver) and its speed. Not found: free, gap +inf.
struct LaneNeighbour {
  bool found = false;
  double gap = INFINITY;
  double speed = 0;
};

// The leader and the follower in one lane, around the driver.
struct LaneNeighbours {
  LaneNeighbour leader, follower;
};

enum class LaneChange {
  kChange,    // worth it and safe
  kBlocked,   // someone beside it in the target lane
  kUnsafe,    // the new follower would brake harder than b_safe
  kNotWorth,  // the incentive is not above the threshold
};

struct MobilDecision {
  LaneChange outcome = LaneChange::kNotWorth;
  double incentive = 0;  // m/s^2; computed for kChange and kNotWorth only
};

// Whether a driver at speed v (desired speed v0_here, length `length` m) changes from the
// lane with `current` neighbours to the one with `target` neighbours. The followers' desired
// speed is taken as idm.v0.
MobilDecision decide_lane_change(const Idm& idm, const Mobil& mobil, double v, double v0_here,
                                 double length, const LaneNeighbours& current,
                                 const LaneNeighbours& target);

}  // namespace convoy::road_users
