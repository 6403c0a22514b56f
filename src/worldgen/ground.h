// The ground and the horizon around a generated world: a ground plane well beyond the roads
// (so that a camera never looks past its edge) just below the lowest road, and a ring of low
// hills far out, their heights drawn by seed, so the sky meets land rather than a void.
#pragma once

#include <cstdint>

#include "opendrive/sampling.h"
#include "worldgen/mesh_set.h"

namespace convoy::worldgen {

struct GroundOptions {
  double margin = 600;       // m beyond the roads' bounds
  double below_road = 0.04;  // m under the lowest road surface
  bool urban = false;        // a paved grey-brown ground instead of grass
};

// Returns the ground's height.
double build_ground(const opendrive::Bounds& roads, const GroundOptions& options, uint64_t seed,
                    MeshSet& out);

}  // namespace convoy::worldgen
