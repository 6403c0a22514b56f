// A map's <object>s, <tunnel>s and <bridge>s in the world: crosswalks and parking bays as
// paint; buildings (from outlines or boxes), walls, barriers, railings and hedges as models of
// the generator's own geometry; poles, trees, bushes and street lights as catalog models.
// <repeat> records repeat an object every `distance` metres, or sweep it along the road when
// the distance is 0. An object the generator cannot build is skipped with a warning naming
// the road and the object.
#pragma once

#include "opendrive/network.h"
#include "worldgen/catalog.h"
#include "worldgen/world_plan.h"

namespace convoy::worldgen {

void place_objects(const opendrive::Network& net, const Catalog& catalog, WorldPlan& plan);
void build_spans(const opendrive::Network& net, WorldPlan& plan);

}  // namespace convoy::worldgen
