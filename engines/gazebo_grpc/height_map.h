// SDF <heightmap> collisions: a grey image (binary PGM, 8 or 16 bits, as convoy-odr world
// writes the roads' surface) spanning <size> x and y around <pos>, its values 0 .. max standing
// for pos.z .. pos.z + size.z (Gazebo's reading). The world engine collides with it through
// DART's HeightmapShape (Bullet's height field).
#pragma once

#include <Eigen/Geometry>
#include <dart/dynamics/HeightmapShape.hpp>
#include <filesystem>
#include <memory>
#include <vector>

namespace convoy::world {

struct HeightMapData {
  int width = 0;               // samples along x
  int depth = 0;               // samples along -y: the image's first row is the largest y
  std::vector<float> heights;  // metres above pos.z, width * depth, image row by row
};

// Reads a binary PGM (P5, maxval up to 65535) into heights scaled to [0, size_z]; throws
// std::runtime_error naming the file for anything else.
HeightMapData read_height_map(const std::filesystem::path& file, double size_z);

// The shape for `data` spanning size x, y, and where it sits in its collision's frame so that
// the samples span [pos - size / 2, pos + size / 2] in x and y with heights above pos.z.
struct HeightMapShape {
  std::shared_ptr<dart::dynamics::HeightmapShapef> shape;
  Eigen::Isometry3d offset = Eigen::Isometry3d::Identity();
};
HeightMapShape make_height_map(const HeightMapData& data, const Eigen::Vector3d& size,
                               const Eigen::Vector3d& pos);

}  // namespace convoy::world
