// Where a map's roads leave the flat: whether they do, and embankments from the roads' outer
// edges down to the ground so that no road floats (the surface's collision: height_field.h).
#pragma once

#include "opendrive/network.h"
#include "worldgen/world_plan.h"

namespace convoy::worldgen {

// Whether every road surface lies within `tolerance` of z = 0.
bool is_flat(const opendrive::Network& net, double tolerance = 0.02);

// Slopes (1:1.5) from each road's outermost edges down to ground_z, where the road stands
// more than 0.1 m above it; into the road mesh as "embankment".
void add_embankments(const opendrive::Network& net, double ground_z, MeshSet& road);

}  // namespace convoy::worldgen
