// The roads' surface as a height field, for the world engine's collision where a map is not
// flat (the road model's <heightmap> collision, docs/worlds.md).
#pragma once

#include <filesystem>
#include <vector>

#include "opendrive/network.h"

namespace convoy::worldgen {

// The roads' surface as a height field: a grid of `cell` metres over the roads' bounds plus
// `margin`, each cell the height of the road surface at its centre (the highest where roads
// overlap), cells off the roads the height of the nearest road within `reach` metres, else
// `ground_z`. Row 0 is the grid's smallest y, column 0 its smallest x.
struct HeightField {
  double x0 = 0, y0 = 0;  // the first cell's centre
  double cell = 1;
  int columns = 0, rows = 0;
  std::vector<float> heights;  // rows * columns, row-major

  double min() const;
  double max() const;
};

HeightField road_height_field(const opendrive::Network& net, double ground_z, double cell = 1.0,
                              double margin = 10.0, double reach = 6.0);

// Writes a height field as a 16-bit binary PGM (P5, big-endian, the first row of the image the
// grid's largest y, as Gazebo's heightmaps): value v stands for min + v / 65535 (max - min).
void write_pgm(const HeightField& field, const std::filesystem::path& file);

}  // namespace convoy::worldgen
