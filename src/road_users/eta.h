// When a driver reaches a point: for junction yielding (first come, first served).
#pragma once

namespace convoy::road_users {

// Time (s) to cover d m from speed v (a negative v counts as 0), accelerating at a up to v0
// and then keeping v0; one already faster than v0 keeps its speed. 0 for d <= 0.
double eta(double d, double v, double a, double v0);

}  // namespace convoy::road_users
