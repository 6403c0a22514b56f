// Triangle meshes for the renderer and the primitive shapes of SDF geometry.
//
// A MeshData is what the renderer uploads once per Scene: flat arrays, indexed triangles,
// counter-clockwise front faces, metres. Texture coordinates follow OpenGL's convention
// (v = 0 is the bottom row of the image), as Assimp and OBJ files do.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace convoy::render {

struct MeshData {
  std::vector<float> positions;   // x y z per vertex
  std::vector<float> normals;     // x y z per vertex, or empty (computed by compute_normals)
  std::vector<float> uvs;         // u v per vertex, or empty (no texture mapping)
  std::vector<uint32_t> indices;  // three per triangle, counter-clockwise seen from outside

  size_t vertex_count() const { return positions.size() / 3; }
  size_t triangle_count() const { return indices.size() / 3; }
};

// SDF <box>: an axis-aligned box of the given full sizes, centred on the origin.
MeshData make_box(float sx, float sy, float sz);
// SDF <cylinder>: axis z, centred on the origin, `segments` facets around the axis.
MeshData make_cylinder(float radius, float length, int segments = 32);
// SDF <sphere>: centred on the origin, poles on the z axis.
MeshData make_sphere(float radius, int stacks = 16, int slices = 32);
// SDF <plane>: a rectangle of sx by sy in the xy plane, centred, facing +z.
MeshData make_plane(float sx, float sy);

// The mesh cut into square tiles of `tile` metres in x and y (each triangle goes to the tile
// of its centroid; its vertices are copied into that tile), the non-empty ones in row order.
// A large static mesh (a road network) drawn as tiles lets the renderer leave out what is
// behind or beside the camera. Throws std::invalid_argument for a tile size <= 0.
std::vector<MeshData> split_into_tiles(const MeshData& mesh, float tile);
// Its extent in x and y (the larger one), metres.
float horizontal_extent(const MeshData& mesh);

// A mesh and coarser versions of it, each with its geometric error: the largest distance
// between its surface and the true shape's, in metres. The renderer's levels of detail (see
// Scene::add_mesh_levels).
struct MeshLevels {
  std::vector<MeshData> meshes;  // finest first
  std::vector<float> errors;     // growing
  // Whether Scene::add_mesh_levels may add the bounding box as the coarsest level (box_level.h):
  // not for the tiles of a road network, which meet without cracks at full detail.
  bool box = true;
};
// make_sphere(radius, stacks, slices), then stacks and slices halved while slices stay >= 8.
MeshLevels sphere_levels(float radius, int stacks, int slices);
// make_cylinder(radius, length, segments), then segments halved while they stay >= 8.
MeshLevels cylinder_levels(float radius, float length, int segments);

// `mesh`, then coarser versions of it by vertex clustering, for meshes loaded from files:
// the vertices in a grid cell that face the same way (the same dominant axis of their normal)
// merge into their mean, and triangles that collapse go. Cells of 1/48, 1/24 and 1/12 of the
// mesh's bounding-box diagonal, then 1/8 and 1/5 merging whatever way vertices face (smooth
// normals computed afresh); a level is kept only when it has at most 60 % of the previous
// one's triangles. Its error is the farthest any vertex moved. A textured mesh (uvs) keeps its
// one level: merging would tear its texture mapping.
MeshLevels simplified_levels(MeshData mesh);

// Fills `mesh->normals` with area-weighted smooth vertex normals.
void compute_normals(MeshData* mesh);

// Throws std::invalid_argument naming `what` if the arrays are inconsistent (sizes, indices
// out of range, non-finite positions).
void validate_mesh(const MeshData& mesh, const char* what);

}  // namespace convoy::render
