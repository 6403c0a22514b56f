// Mesh files (SDF <mesh><uri>) through Assimp: COLLADA (.dae), Wavefront (.obj), STL.
//
// A file becomes one LoadedMesh per material: node transforms are baked into the vertices.
// COLLADA files are turned Z-up as Gazebo does (a Y_UP file's +Y becomes +Z; a Z_UP file keeps
// its axes) and their <unit> honoured; OBJ and STL vertices are taken as they are. Then
// `scale` (SDF <mesh><scale>) multiplies x, y and z; a mirroring scale keeps faces outward.
#pragma once

#include <array>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "render/mesh.h"
#include "render/scene.h"

namespace convoy::render {

struct LoadedMesh {
  MeshData mesh;
  // The file's material for this part (Material's defaults where the file says nothing).
  Rgba diffuse{0.7f, 0.7f, 0.7f, 1.0f};
  Rgba ambient{0.7f, 0.7f, 0.7f, 1.0f};
  Rgba specular{0.0f, 0.0f, 0.0f, 1.0f};
  Rgba emissive{0.0f, 0.0f, 0.0f, 0.0f};
  float shininess = 32.0f;
  // The diffuse texture's file, resolved against the mesh file's folder; empty if none.
  // Textures embedded in the file are not supported (left empty).
  std::string texture_path;

  // The part's material, drawn with the given Scene texture (-1: none).
  Material material(int texture = -1) const;
  // What the renderer draws for it, made on the first call and kept: simplified_levels(mesh);
  // or, for a mesh wider than kTileAbove metres (a road network), its tiles of kTile metres
  // (split_into_tiles), each at full detail (simplified alone, neighbouring tiles would not
  // meet), so that what is out of a camera's view is left out.
  static constexpr float kTileAbove = 120.0f;
  static constexpr float kTile = 40.0f;
  const std::vector<MeshLevels>& drawables() const;

 private:
  mutable std::shared_ptr<const std::vector<MeshLevels>> drawables_;
};

// Throws std::runtime_error naming the file if it cannot be read or holds no triangles.
std::vector<LoadedMesh> load_mesh(const std::string& path,
                                  const std::array<float, 3>& scale = {1, 1, 1});

// load_mesh's results kept for the life of the cache (as Gazebo's MeshManager keeps a
// process's meshes): a world made again (a reset) reads each file once, not once a reset.
// A file that fails is not kept (the next call reads it again and throws again).
class MeshFileCache {
 public:
  const std::vector<LoadedMesh>& load(const std::string& path,
                                      const std::array<float, 3>& scale = {1, 1, 1});
  size_t files_read() const { return files_read_; }

 private:
  std::map<std::pair<std::string, std::array<float, 3>>, std::vector<LoadedMesh>> meshes_;
  size_t files_read_ = 0;
};

}  // namespace convoy::render
