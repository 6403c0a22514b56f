// Tests of the renderer's CPU side: primitive shapes, poses, mesh files, image files.
// No OpenGL needed.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include "render/image_io.h"
#include "render/mesh_loader.h"
#include "render/scene.h"

namespace convoy::render {
namespace {

namespace fs = std::filesystem;

class MeshFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("convoy_mesh_test_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) {
    const fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary) << text;
    return p.string();
  }
  fs::path dir_;
};

std::array<float, 3> min_corner(const MeshData& m) {
  std::array<float, 3> lo{1e30f, 1e30f, 1e30f};
  for (size_t i = 0; i < m.positions.size(); ++i) lo[i % 3] = std::min(lo[i % 3], m.positions[i]);
  return lo;
}

std::array<float, 3> max_corner(const MeshData& m) {
  std::array<float, 3> hi{-1e30f, -1e30f, -1e30f};
  for (size_t i = 0; i < m.positions.size(); ++i) hi[i % 3] = std::max(hi[i % 3], m.positions[i]);
  return hi;
}

// Every triangle's winding agrees with its vertices' normals (faces point outwards).
void expect_outward_winding(const MeshData& m) {
  for (size_t t = 0; t < m.indices.size(); t += 3) {
    const float* a = &m.positions[3 * m.indices[t]];
    const float* b = &m.positions[3 * m.indices[t + 1]];
    const float* c = &m.positions[3 * m.indices[t + 2]];
    const float e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const float e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const float n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                        e1[0] * e2[1] - e1[1] * e2[0]};
    const float* vn = &m.normals[3 * m.indices[t]];
    ASSERT_GT(n[0] * vn[0] + n[1] * vn[1] + n[2] * vn[2], 0) << "triangle " << t / 3;
  }
}

// A flat grid of n x n squares of `size` metres from (x0, y0), two triangles each, with uvs.
MeshData grid(int n, float size, float x0, float y0) {
  MeshData m;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      m.positions.insert(m.positions.end(), {x0 + i * size, y0 + j * size, 0.0f});
      m.uvs.insert(m.uvs.end(), {i * 1.0f, j * 1.0f});
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const uint32_t a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
      m.indices.insert(m.indices.end(), {a, b, d, a, d, c});
    }
  return m;
}

TEST(MeshTiles, EveryTriangleGoesToTheTileOfItsCentroid) {
  const MeshData road = grid(50, 2.0f, -50, -50);  // 100 m x 100 m, 5,000 triangles
  EXPECT_FLOAT_EQ(horizontal_extent(road), 100.0f);
  const auto tiles = split_into_tiles(road, 40.0f);
  ASSERT_EQ(tiles.size(), 16u);  // cells -2..1 in x and y
  size_t triangles = 0;
  for (const MeshData& t : tiles) {
    triangles += t.triangle_count();
    EXPECT_EQ(t.uvs.size() / 2, t.vertex_count());
    float lo = 1e9f, hi = -1e9f;
    for (size_t i = 0; i < t.vertex_count(); ++i) {
      lo = std::min(lo, t.positions[3 * i]);
      hi = std::max(hi, t.positions[3 * i]);
    }
    EXPECT_LE(hi - lo, 40.0f + 2.0f);  // a tile, and the triangles that stick out of it
    for (uint32_t v : t.indices) ASSERT_LT(v, t.vertex_count());
  }
  EXPECT_EQ(triangles, road.triangle_count());
  EXPECT_THROW(split_into_tiles(road, 0.0f), std::invalid_argument);
}

TEST(MeshTiles, AWideMeshIsDrawnAsTilesAndASmallOneWithItsLevels) {
  LoadedMesh wide;
  wide.mesh = grid(100, 2.0f, 0, 0);  // 200 m
  const auto& tiles = wide.drawables();
  EXPECT_EQ(tiles.size(), 25u);  // 5 x 5 tiles of 40 m
  for (const MeshLevels& t : tiles) {
    EXPECT_EQ(t.meshes.size(), 1u);  // full detail only: tiles meet without cracks
    EXPECT_EQ(t.meshes[0].normals.size(), t.meshes[0].positions.size());
  }
  LoadedMesh small;
  small.mesh = grid(10, 2.0f, 0, 0);
  EXPECT_EQ(small.drawables().size(), 1u);
}

TEST(PrimitivesTest, ShapesHaveTheirSizesAndFaceOutwards) {
  const MeshData box = make_box(1, 2, 3);
  EXPECT_EQ(box.triangle_count(), 12u);
  EXPECT_EQ(min_corner(box), (std::array<float, 3>{-0.5f, -1, -1.5f}));
  EXPECT_EQ(max_corner(box), (std::array<float, 3>{0.5f, 1, 1.5f}));
  expect_outward_winding(box);

  const MeshData cyl = make_cylinder(0.5f, 2, 16);
  EXPECT_EQ(cyl.triangle_count(), 4u * 16);
  EXPECT_NEAR(max_corner(cyl)[2], 1, 1e-6);
  EXPECT_NEAR(max_corner(cyl)[0], 0.5, 1e-6);
  expect_outward_winding(cyl);

  const MeshData sphere = make_sphere(2, 8, 12);
  EXPECT_EQ(sphere.triangle_count(), 2u * 12 * 7);
  for (size_t i = 0; i < sphere.positions.size(); i += 3) {
    EXPECT_NEAR(std::hypot(sphere.positions[i], sphere.positions[i + 1], sphere.positions[i + 2]),
                2, 1e-5);
  }
  expect_outward_winding(sphere);

  const MeshData plane = make_plane(4, 2);
  EXPECT_EQ(plane.triangle_count(), 2u);
  EXPECT_EQ(plane.normals[2], 1);
  expect_outward_winding(plane);

  EXPECT_THROW(make_box(0, 1, 1), std::invalid_argument);
  EXPECT_THROW(make_sphere(1, 1, 3), std::invalid_argument);
}

TEST(PrimitivesTest, SceneComputesMissingNormalsAndRejectsBadMeshes) {
  MeshData tri;
  tri.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  tri.indices = {0, 1, 2};
  Scene scene;
  scene.add_mesh(tri);
  EXPECT_EQ(scene.meshes()[0].normals, (std::vector<float>{0, 0, 1, 0, 0, 1, 0, 0, 1}));
  tri.indices = {0, 1, 3};
  EXPECT_THROW(scene.add_mesh(tri), std::invalid_argument);
}

TEST(PoseTest, RollPitchYawAndQuaternionAgree) {
  const Pose a = make_pose(1, 2, 3, 0.3, -0.2, 1.1);
  // The same rotation as a quaternion: q = qz(yaw) * qy(pitch) * qx(roll).
  const double cr = std::cos(0.15), sr = std::sin(0.15), cp = std::cos(-0.1), sp = std::sin(-0.1),
               cy = std::cos(0.55), sy = std::sin(0.55);
  const Pose b =
      make_pose_quat({1, 2, 3}, {cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy,
                                 cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy});
  for (int i = 0; i < 16; ++i) EXPECT_NEAR(a[i], b[i], 1e-12) << i;
  // Yaw 90 degrees turns +X into +Y.
  const Pose yaw = make_pose(0, 0, 0, 0, 0, std::numbers::pi / 2);
  EXPECT_NEAR(yaw[1], 1, 1e-12);
  const Pose c = compose(make_pose(1, 0, 0), with_scale(identity_pose(), 2, 3, 4));
  EXPECT_EQ(c[0], 2);
  EXPECT_EQ(c[5], 3);
  EXPECT_EQ(c[10], 4);
  EXPECT_EQ(c[12], 1);
}

TEST_F(MeshFiles, TheCacheReadsAFileOnceForEachScaleAndKeepsNoFailure) {
  const std::string obj = write("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  MeshFileCache cache;
  const auto& first = cache.load(obj);
  EXPECT_EQ(&cache.load(obj), &first);  // the same parts, not read again
  EXPECT_EQ(cache.files_read(), 1u);
  EXPECT_EQ(max_corner(cache.load(obj, {2, 2, 2})[0].mesh), (std::array<float, 3>{2, 2, 0}));
  EXPECT_EQ(cache.files_read(), 2u);
  EXPECT_EQ(&first[0].drawables(), &first[0].drawables());  // simplified once
  EXPECT_EQ(first[0].drawables().at(0).meshes.at(0).triangle_count(), 1u);
  EXPECT_THROW(cache.load((dir_ / "missing.obj").string()), std::runtime_error);
  EXPECT_THROW(cache.load((dir_ / "missing.obj").string()), std::runtime_error);  // tried again
  EXPECT_EQ(cache.files_read(), 2u);
}

TEST_F(MeshFiles, LoadsObjWithMaterialAndScale) {
  write("part.mtl", "newmtl paint\nKd 0.2 0.4 0.6\nKs 0.5 0.5 0.5\nNs 50\n");
  const std::string obj = write("part.obj",
                                "mtllib part.mtl\n"
                                "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\n"
                                "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                                "usemtl paint\n"
                                "f 1/1 4/4 3/3 2/2\n"  // the bottom square, facing -z
                                "f 1 2 5\n");
  const auto parts = load_mesh(obj, {2, 3, 0.5f});
  ASSERT_EQ(parts.size(), 1u);
  const LoadedMesh& p = parts[0];
  EXPECT_EQ(p.mesh.triangle_count(), 3u);
  EXPECT_EQ(max_corner(p.mesh), (std::array<float, 3>{2, 3, 0.5f}));
  EXPECT_EQ(min_corner(p.mesh), (std::array<float, 3>{0, 0, 0}));
  EXPECT_FLOAT_EQ(p.diffuse[0], 0.2f);
  EXPECT_FLOAT_EQ(p.diffuse[1], 0.4f);
  EXPECT_FLOAT_EQ(p.diffuse[2], 0.6f);
  EXPECT_FLOAT_EQ(p.shininess, 50);
  EXPECT_EQ(p.mesh.normals.size(), p.mesh.positions.size());
  EXPECT_EQ(p.mesh.uvs.size(), 2 * p.mesh.vertex_count());
  const Material m = p.material(4);
  EXPECT_EQ(m.texture, 4);
  EXPECT_EQ(m.diffuse, p.diffuse);
}

TEST_F(MeshFiles, LoadsStlWithScale) {
  const std::string stl = write("wedge.stl",
                                "solid wedge\n"
                                " facet normal 0 0 1\n  outer loop\n"
                                "   vertex 0 0 0\n   vertex 1 0 0\n   vertex 0 1 0\n"
                                "  endloop\n endfacet\n"
                                " facet normal 0 -1 0\n  outer loop\n"
                                "   vertex 0 0 0\n   vertex 1 0 0\n   vertex 0 0 1\n"
                                "  endloop\n endfacet\n"
                                "endsolid wedge\n");
  const auto parts = load_mesh(stl, {0.001f, 0.001f, 0.001f});  // millimetres, as CAD exports
  ASSERT_EQ(parts.size(), 1u);
  EXPECT_EQ(parts[0].mesh.triangle_count(), 2u);
  const auto hi = max_corner(parts[0].mesh);
  EXPECT_FLOAT_EQ(hi[0], 0.001f);
  EXPECT_FLOAT_EQ(hi[2], 0.001f);
  expect_outward_winding(parts[0].mesh);
  // A mirroring scale (SDF allows negative ones) keeps the faces pointing out.
  const auto mirrored = load_mesh(stl, {-1, 1, 1});
  EXPECT_FLOAT_EQ(min_corner(mirrored[0].mesh)[0], -1);
  expect_outward_winding(mirrored[0].mesh);
}

TEST_F(MeshFiles, ColladaIsTurnedZUpLikeGazebo) {
  auto dae = [&](const std::string& up) {
    return write(
        up + ".dae",
        "<?xml version=\"1.0\"?>\n"
        "<COLLADA xmlns=\"http://www.collada.org/2005/11/COLLADASchema\" version=\"1.4.1\">"
        "<asset><unit meter=\"0.01\"/><up_axis>" +
            up +
            "</up_axis></asset>"
            "<library_geometries><geometry id=\"g\"><mesh>"
            "<source id=\"p\"><float_array id=\"pa\" count=\"9\">0 0 0 100 0 0 0 0 200"
            "</float_array><technique_common><accessor source=\"#pa\" count=\"3\" stride=\"3\">"
            "<param name=\"X\" type=\"float\"/><param name=\"Y\" type=\"float\"/>"
            "<param name=\"Z\" type=\"float\"/></accessor></technique_common></source>"
            "<vertices id=\"v\"><input semantic=\"POSITION\" source=\"#p\"/></vertices>"
            "<triangles count=\"1\"><input semantic=\"VERTEX\" source=\"#v\" offset=\"0\"/>"
            "<p>0 1 2</p></triangles></mesh></geometry></library_geometries>"
            "<library_visual_scenes><visual_scene id=\"s\"><node id=\"n\">"
            "<instance_geometry url=\"#g\"/></node></visual_scene></library_visual_scenes>"
            "<scene><instance_visual_scene url=\"#s\"/></scene></COLLADA>\n");
  };
  // Z_UP: axes kept; centimetres become metres.
  auto z_up = load_mesh(dae("Z_UP"));
  ASSERT_EQ(z_up.size(), 1u);
  EXPECT_NEAR(max_corner(z_up[0].mesh)[0], 1, 1e-6);
  EXPECT_NEAR(max_corner(z_up[0].mesh)[2], 2, 1e-6);
  // Y_UP: the file's up (+Y) becomes +Z, its +Z becomes -Y.
  auto y_up = load_mesh(dae("Y_UP"), {1, 1, 1});
  ASSERT_EQ(y_up.size(), 1u);
  EXPECT_NEAR(min_corner(y_up[0].mesh)[1], -2, 1e-6);
  EXPECT_NEAR(max_corner(y_up[0].mesh)[2], 0, 1e-6);
}

TEST_F(MeshFiles, ErrorsNameTheFile) {
  const std::string missing = (dir_ / "nope.obj").string();
  try {
    load_mesh(missing);
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
  }
  const std::string junk = write("junk.stl", "this is not a mesh");
  try {
    load_mesh(junk);
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(junk), std::string::npos) << e.what();
  }
  EXPECT_THROW(load_mesh(write("x.fbx", "")), std::runtime_error);
}

TEST_F(MeshFiles, ImageFilesRoundTrip) {
  const uint8_t rgb[12] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
  const std::string ppm = (dir_ / "a.ppm").string();
  write_ppm(ppm, 2, 2, rgb);
  const Image back = read_ppm(ppm);
  EXPECT_EQ(back.width, 2);
  EXPECT_EQ(back.height, 2);
  EXPECT_EQ(back.data, std::vector<uint8_t>(rgb, rgb + 12));

  // 2x2 RGB PNG: red green / blue white.
  const unsigned char png[] = {
      0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48, 0x44,
      0x52, 0x00, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00, 0x02, 0x08, 0x02, 0x00, 0x00, 0x00, 0xfd,
      0xd4, 0x9a, 0x73, 0x00, 0x00, 0x00, 0x12, 0x49, 0x44, 0x41, 0x54, 0x78, 0x9c, 0x63, 0xf8,
      0xcf, 0xc0, 0xc0, 0x00, 0xc2, 0x0c, 0xff, 0x81, 0x00, 0x00, 0x1f, 0xee, 0x05, 0xfb, 0x0b,
      0xd9, 0x68, 0x8b, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82};
  const std::string png_path =
      write("t.png", std::string(reinterpret_cast<const char*>(png), sizeof png));
  Scene scene;
  try {
    const Image image = load_image_rgba(png_path);
    EXPECT_EQ(image.width, 2);
    EXPECT_EQ(image.channels, 4);
    EXPECT_EQ(image.data, (std::vector<uint8_t>{255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255,
                                                255, 255, 255}));
    EXPECT_EQ(scene.add_texture_file(png_path), 0);
  } catch (const std::runtime_error& e) {
    // Only acceptable when the library was built without libpng.
    EXPECT_NE(std::string(e.what()).find("libpng not found"), std::string::npos) << e.what();
  }
  EXPECT_THROW(scene.add_texture_file(write("bad.png", "not an image")), std::runtime_error);
}

// The error each level claims bounds how far its surface strays from the true shape: sample
// every triangle (corners, edge midpoints, centroid) and measure the distance to the sphere
// or to the cylinder's side.
TEST(LevelsTest, ErrorsBoundTheDistanceToTheTrueShape) {
  auto max_gap = [](const MeshData& m, auto distance) {
    double worst = 0;
    for (size_t t = 0; t < m.indices.size(); t += 3) {
      std::array<std::array<double, 3>, 3> v;
      for (int k = 0; k < 3; ++k)
        for (int c = 0; c < 3; ++c) v[k][c] = m.positions[3 * m.indices[t + k] + c];
      const double w[7][3] = {{1, 0, 0},
                              {0, 1, 0},
                              {0, 0, 1},
                              {.5, .5, 0},
                              {0, .5, .5},
                              {.5, 0, .5},
                              {1. / 3, 1. / 3, 1. / 3}};
      for (const auto& b : w) {
        std::array<double, 3> p{};
        for (int k = 0; k < 3; ++k)
          for (int c = 0; c < 3; ++c) p[c] += b[k] * v[k][c];
        worst = std::max(worst, distance(p));
      }
    }
    return worst;
  };
  const MeshLevels spheres = sphere_levels(0.4f, 24, 48);
  ASSERT_EQ(spheres.meshes.size(), 3u);  // 48, 24 and 12 slices
  EXPECT_EQ(spheres.meshes[0].triangle_count(), make_sphere(0.4f, 24, 48).triangle_count());
  for (size_t i = 0; i < spheres.meshes.size(); ++i) {
    const double gap = max_gap(spheres.meshes[i], [](const std::array<double, 3>& p) {
      return 0.4 - std::hypot(p[0], p[1], p[2]);
    });
    EXPECT_LE(gap, spheres.errors[i] * 1.0001) << "level " << i;
    EXPECT_GE(gap, spheres.errors[i] * 0.5) << "level " << i;  // and not far too pessimistic
    if (i > 0) {
      EXPECT_GT(spheres.errors[i], spheres.errors[i - 1]);
      EXPECT_LT(spheres.meshes[i].triangle_count(), spheres.meshes[i - 1].triangle_count());
    }
  }
  const MeshLevels cylinders = cylinder_levels(0.3f, 1.0f, 32);
  ASSERT_EQ(cylinders.meshes.size(), 3u);  // 32, 16 and 8 segments
  for (size_t i = 0; i < cylinders.meshes.size(); ++i) {
    const double gap = max_gap(cylinders.meshes[i], [](const std::array<double, 3>& p) {
      return std::abs(p[2]) < 0.5 - 1e-6 ? 0.3 - std::hypot(p[0], p[1]) : 0.0;
    });
    EXPECT_LE(gap, cylinders.errors[i] * 1.0001) << "level " << i;
    EXPECT_GE(gap, cylinders.errors[i] * 0.99) << "level " << i;
  }
}

// Levels for meshes from files: fewer triangles each, the error growing, every coarse vertex
// within its level's error of the true surface; the finest level untouched.
TEST(MeshLevels, SimplifiedByVertexClustering) {
  MeshData sphere = make_sphere(1.0f, 32, 64);
  sphere.uvs.clear();
  const MeshLevels levels = simplified_levels(sphere);
  ASSERT_GE(levels.meshes.size(), 3u);
  EXPECT_EQ(levels.meshes[0].indices, sphere.indices);
  EXPECT_EQ(levels.errors[0], 0.0f);
  for (size_t i = 1; i < levels.meshes.size(); ++i) {
    const MeshData& m = levels.meshes[i];
    EXPECT_NO_THROW(validate_mesh(m, "level"));
    EXPECT_LE(m.triangle_count(), 0.6 * levels.meshes[i - 1].triangle_count()) << i;
    EXPECT_GT(levels.errors[i], levels.errors[i - 1]) << i;
    EXPECT_LT(levels.errors[i], 1.2f) << i;  // a cell's diagonal: cells of at most 1/5 of 3.46 m
    ASSERT_EQ(m.normals.size(), m.positions.size());
    for (size_t v = 0; v < m.vertex_count(); ++v) {
      const double r =
          std::hypot(m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]);
      EXPECT_LE(1.0 - r, levels.errors[i] + 1e-5) << "level " << i << " vertex " << v;
      EXPECT_LE(r, 1.0 + 1e-5);
    }
  }
  // Textured meshes keep their one level; tiny ones too.
  MeshData textured = sphere;
  textured.uvs.assign(2 * textured.vertex_count(), 0.5f);
  EXPECT_EQ(simplified_levels(textured).meshes.size(), 1u);
  EXPECT_EQ(simplified_levels(make_box(1, 1, 1)).meshes.size(), 1u);
  // A road user from the actor library: a sedan's body.
  const auto parts = load_mesh(std::string(CONVOY_ACTOR_MESH_DIR) + "/sedan_paint.obj");
  ASSERT_FALSE(parts.empty());
  const MeshLevels sedan = simplified_levels(parts[0].mesh);
  ASSERT_GE(sedan.meshes.size(), 2u);
  EXPECT_LE(sedan.meshes.back().triangle_count(), sedan.meshes[0].triangle_count() / 3);
  EXPECT_LT(sedan.errors.back(), 1.2f);  // cells of at most 1/5 of its ~5 m diagonal
}

// Foliage: normals scattered every way barely merge by facing; the last levels merge across it
// and give the level smooth normals of its own.
TEST(MeshLevels, ScatteredNormalsStillSimplify) {
  MeshData blob = make_sphere(1.0f, 32, 64);
  blob.uvs.clear();
  for (size_t v = 0; v < blob.vertex_count(); ++v) {
    const float flip = (v * 2654435761u) % 3 == 0 ? -1.0f : 1.0f;
    for (int k = 0; k < 3; ++k) blob.normals[3 * v + k] *= flip;
    std::swap(blob.normals[3 * v], blob.normals[3 * v + (v % 3)]);
  }
  const MeshLevels levels = simplified_levels(blob);
  ASSERT_GE(levels.meshes.size(), 2u);
  const MeshData& coarsest = levels.meshes.back();
  EXPECT_LE(coarsest.triangle_count(), blob.triangle_count() / 4);
  EXPECT_LT(levels.errors.back(), 1.2f);  // a cell's diagonal: cells of 1/5 of 3.46 m
  for (size_t v = 0; v < coarsest.vertex_count(); ++v) {
    const float* p = &coarsest.positions[3 * v];
    const float* n = &coarsest.normals[3 * v];
    EXPECT_NEAR(std::hypot(n[0], n[1], n[2]), 1.0, 1e-4);
    EXPECT_GT(p[0] * n[0] + p[1] * n[1] + p[2] * n[2], 0) << "vertex " << v << " faces inwards";
  }
}

}  // namespace
}  // namespace convoy::render
