// Solids the world generator builds from a map's objects: prisms from outlines (buildings),
// ribbons along a road (walls, barriers, hedges), and the polygon checks they need.
#pragma once

#include <array>
#include <functional>
#include <vector>

#include "worldgen/mesh_set.h"

namespace convoy::worldgen {

using Vec2 = std::array<double, 2>;

// Twice the signed area (positive counter-clockwise).
double signed_area2(const std::vector<Vec2>& polygon);
// Whether two non-adjacent edges of a closed polygon cross.
bool self_intersects(const std::vector<Vec2>& polygon);
// Triangles (index triples) covering a simple polygon, by ear clipping; empty if it fails.
std::vector<std::array<size_t, 3>> triangulate(const std::vector<Vec2>& polygon);

// A vertical prism over a simple polygon: walls from base[i] up to base[i] + height[i], and a
// flat roof at the tallest corner's top. Walls get uvs in metres / `uv_metres` (for a
// façade texture repeating every uv_metres) when uv_metres > 0.
void add_prism(Part& walls, Part& roof, const std::vector<Vec3>& base,
               const std::vector<double>& height, double uv_metres = 0);

// A ribbon: a box-like solid swept along a path; at each station a centre point (its base),
// a width across and a height. Sides, top and the two end caps.
struct RibbonStation {
  Vec3 base;    // centre of the ribbon's foot
  Vec2 across;  // unit vector across the path (left)
  double width = 0;
  double height = 0;
};
void add_ribbon(Part& part, const std::vector<RibbonStation>& stations);

}  // namespace convoy::worldgen
