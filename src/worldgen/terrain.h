// Where a map's roads leave the flat: collision boxes that follow the road surface (elevation
// and superelevation) for maps that are not flat, so that the ego and the agents drive on the
// road and not on the plane under it, and embankments from the roads' outer edges down to the
// ground so that no road floats.
#pragma once

#include "opendrive/network.h"
#include "worldgen/world_plan.h"

namespace convoy::worldgen {

// Whether every road surface lies within `tolerance` of z = 0.
bool is_flat(const opendrive::Network& net, double tolerance = 0.02);

// Thin boxes under every drawn lane that is level with the road (raised sidewalks and curbs
// left out), one per interval of the road's stations (at most 4 m), their tops on the
// surface, overlapping a little.
std::vector<BoxCollision> road_collision_boxes(const opendrive::Network& net);

// Slopes (1:1.5) from each road's outermost edges down to ground_z, where the road stands
// more than 0.1 m above it; into the road mesh as "embankment".
void add_embankments(const opendrive::Network& net, double ground_z, MeshSet& road);

}  // namespace convoy::worldgen
