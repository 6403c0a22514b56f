#include <cmath>

#include "worldgen/world_plan.h"

namespace convoy::worldgen {

Vec3 road_point(const opendrive::Road& road, double s, double t, double dz) {
  const opendrive::Pose2 p = road.offset_point(s, t);
  return {p.x, p.y, road.surface_z(s, t) + dz};
}

}  // namespace convoy::worldgen
