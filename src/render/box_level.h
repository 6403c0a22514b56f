// The coarsest level of detail a mesh can have: its axis-aligned bounding box.
//
// Far away, a tree of 950 triangles or a walker of 1,400 covers a pixel or two, and a small
// camera (a learning agent's 84 x 84) sees dozens of them: their triangles, not their pixels,
// cost the frame on a CPU rasteriser. Within the renderer's pixel error (Renderer::
// set_lod_pixel_error) such a mesh is indistinguishable from a box of its material, 12
// triangles. Scene::add_mesh_levels appends this level after a mesh's own coarser ones.
#pragma once

#include <optional>

#include "render/mesh.h"

namespace convoy::render {

struct BoxLevel {
  MeshData mesh;  // 12 triangles, flat normals, counter-clockwise seen from outside
  float error;    // metres: the largest distance between the box's surface and the mesh's
};

// The box of `mesh` and its geometric error, or nullopt when it would not pay: a textured mesh
// (a box has no texture mapping), fewer than kMinTriangles triangles, or more than
// kMaxTriangles (the error's cost). The error is measured, not bounded: the larger of the
// farthest of the mesh's vertices and triangle centroids from the box's surface and the
// farthest of 26 points of the box's surface (corners, edge midpoints, face centres) from the
// mesh's triangles.
std::optional<BoxLevel> box_level(const MeshData& mesh);

constexpr size_t kBoxLevelMinTriangles = 24;
constexpr size_t kBoxLevelMaxTriangles = 20000;

}  // namespace convoy::render
