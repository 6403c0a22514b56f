// The bounding box as the coarsest level of detail (render/box_level.h, Scene::add_mesh_levels).
#include "render/box_level.h"

#include <gtest/gtest.h>

#include <cmath>

#include "render/mesh.h"
#include "render/scene.h"

namespace convoy::render {
namespace {

// `m` moved by (dx, dy, dz).
MeshData moved(MeshData m, float dx, float dy, float dz) {
  for (size_t v = 0; v < m.vertex_count(); ++v) {
    m.positions[3 * v] += dx;
    m.positions[3 * v + 1] += dy;
    m.positions[3 * v + 2] += dz;
  }
  return m;
}

MeshData joined(const MeshData& a, const MeshData& b) {
  MeshData m = a;
  const auto base = static_cast<uint32_t>(a.vertex_count());
  m.positions.insert(m.positions.end(), b.positions.begin(), b.positions.end());
  m.normals.insert(m.normals.end(), b.normals.begin(), b.normals.end());
  for (uint32_t i : b.indices) m.indices.push_back(base + i);
  return m;
}

MeshData untextured_sphere(float r) {
  MeshData s = make_sphere(r, 16, 32);
  s.uvs.clear();
  return s;
}

// A box of 12 triangles around the mesh, each face turned outwards, its normals flat.
TEST(BoxLevel, TwelveOutwardTrianglesAroundTheMesh) {
  const auto box = box_level(moved(untextured_sphere(1.0f), 5, -2, 1));
  ASSERT_TRUE(box.has_value());
  const MeshData& m = box->mesh;
  EXPECT_NO_THROW(validate_mesh(m, "box"));
  ASSERT_EQ(m.triangle_count(), 12u);
  ASSERT_EQ(m.normals.size(), m.positions.size());
  for (size_t v = 0; v < m.vertex_count(); ++v) {
    EXPECT_NEAR(std::abs(m.positions[3 * v] - 5), 1.0, 1e-5);
    EXPECT_NEAR(std::abs(m.positions[3 * v + 1] + 2), 1.0, 1e-5);
    EXPECT_NEAR(std::abs(m.positions[3 * v + 2] - 1), 1.0, 1e-5);
  }
  const float centre[3] = {5, -2, 1};
  for (size_t t = 0; t < m.triangle_count(); ++t) {
    const float* a = &m.positions[3 * m.indices[3 * t]];
    const float* b = &m.positions[3 * m.indices[3 * t + 1]];
    const float* c = &m.positions[3 * m.indices[3 * t + 2]];
    const float e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const float e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const float n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                        e1[0] * e2[1] - e1[1] * e2[0]};
    float outward = 0, along_normal = 0;
    for (int k = 0; k < 3; ++k) {
      outward += n[k] * ((a[k] + b[k] + c[k]) / 3 - centre[k]);
      along_normal += n[k] * m.normals[3 * m.indices[3 * t] + k];
    }
    EXPECT_GT(outward, 0) << "triangle " << t << " faces inwards";
    EXPECT_GT(along_normal, 0) << "triangle " << t << " disagrees with its normal";
  }
}

// The error is the box's corner from the sphere: r (sqrt 3 - 1), a little more for the
// tessellated sphere, whose facets lie inside the true one.
TEST(BoxLevel, ErrorOfASphereIsItsCorner) {
  const auto box = box_level(untextured_sphere(2.0f));
  ASSERT_TRUE(box.has_value());
  EXPECT_GT(box->error, 2.0 * (std::sqrt(3.0) - 1) - 1e-3);
  EXPECT_LT(box->error, 2.0 * (std::sqrt(3.0) - 1) + 0.05);
}

// Two posts 4 m apart: the box spans the gap between them, and its error says so.
TEST(BoxLevel, ErrorCoversEmptySpaceInTheBox) {
  MeshData post = make_cylinder(0.5f, 3.0f, 16);
  post.uvs.clear();
  const auto box = box_level(joined(post, moved(post, 4, 0, 0)));
  ASSERT_TRUE(box.has_value());
  EXPECT_GT(box->error, 1.0f);  // the face centre (2, +-0.5, 0) is 1.5 m from either post
  const auto one = box_level(post);
  ASSERT_TRUE(one.has_value());
  EXPECT_LT(one->error, 0.5f * (std::sqrt(2.0f) - 1) + 0.02f);  // a round post: its corners
}

// No box where it would not pay or could not look the same.
TEST(BoxLevel, NoneForTexturedSmallOrHugeMeshes) {
  EXPECT_FALSE(box_level(make_sphere(1.0f, 16, 32)).has_value());  // textured
  EXPECT_FALSE(box_level(make_box(1, 1, 1)).has_value());          // 12 triangles already
  MeshData huge = untextured_sphere(1.0f);
  while (huge.triangle_count() <= kBoxLevelMaxTriangles) huge = joined(huge, huge);
  EXPECT_FALSE(box_level(huge).has_value());
}

// Scene::add_mesh_levels ends a mesh's levels with its box, its error not below theirs.
TEST(BoxLevel, TheSceneAddsItLast) {
  Scene scene;
  MeshLevels levels = sphere_levels(1.0f, 16, 32);
  for (auto& m : levels.meshes) m.uvs.clear();
  const int sphere = scene.add_mesh_levels(levels);
  const auto& lods = scene.mesh_lods()[sphere];
  ASSERT_EQ(lods.size(), levels.meshes.size());  // the coarser levels and the box
  EXPECT_EQ(scene.meshes()[lods.back().mesh].triangle_count(), 12u);
  EXPECT_GE(lods.back().error, lods[lods.size() - 2].error);
  const int cube = scene.add_mesh_levels(MeshLevels{{make_box(1, 1, 1)}, {0.0f}});
  EXPECT_TRUE(scene.mesh_lods()[cube].empty());
  levels.box = false;  // a road network's tile
  EXPECT_EQ(scene.mesh_lods()[scene.add_mesh_levels(levels)].size(), levels.meshes.size() - 1);
}

}  // namespace
}  // namespace convoy::render
