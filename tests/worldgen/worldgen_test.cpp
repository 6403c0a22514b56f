// The world generator on esmini's 20 maps (tests/data/esmini/xodr): every map becomes a
// world, scenery stays off the road, the same seed gives the same files, signals and objects
// become models, and what cannot be built is a warning naming it.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include "opendrive/parser.h"
#include "worldgen/height_field.h"
#include "worldgen/markings.h"
#include "worldgen/scenery.h"
#include "worldgen/world_gen.h"

namespace fs = std::filesystem;
namespace odr = convoy::opendrive;
namespace wg = convoy::worldgen;

namespace {

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Every road tile's OBJ (meshes/road_I_J.obj), in name order.
std::vector<std::string> road_tiles(const fs::path& world_dir) {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(world_dir / "meshes")) {
    const std::string n = e.path().filename().string();
    if (n.rfind("road_", 0) == 0 && e.path().extension() == ".obj") files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  std::vector<std::string> out;
  for (const auto& f : files) out.push_back(slurp(f));
  return out;
}

class WorldGenTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("convoy_worldgen_test_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    catalog_ = wg::Catalog::load(CONVOY_WORLDGEN_TEST_CATALOG);
  }
  void TearDown() override { fs::remove_all(dir_); }

  static std::vector<fs::path> maps() {
    std::vector<fs::path> out;
    for (const auto& e : fs::directory_iterator(CONVOY_ESMINI_MAPS)) {
      if (e.path().extension() == ".xodr") out.push_back(e.path());
    }
    std::sort(out.begin(), out.end());
    return out;
  }

  wg::WorldStats make(const fs::path& map, const std::string& out, wg::Scenery scenery,
                      uint64_t seed = 1) {
    const odr::Network net = odr::load(map.string());
    return wg::generate_world(net, catalog_, {scenery, seed}, dir_ / out);
  }

  fs::path dir_;
  wg::Catalog catalog_;
};

}  // namespace

TEST_F(WorldGenTest, EveryEsminiMapBecomesAWorldWithItsMeshes) {
  const auto all = maps();
  ASSERT_EQ(all.size(), 20u);
  for (const fs::path& map : all) {
    SCOPED_TRACE(map.filename().string());
    const auto stats = make(map, map.stem().string(), wg::Scenery::kUrban);
    const fs::path world = dir_ / map.stem() / "world.sdf";
    ASSERT_TRUE(fs::exists(world));
    EXPECT_GT(stats.triangles, 500u);
    // every mesh of the generator's own that the world names is there
    const std::string text = slurp(world);
    const std::regex uri("<uri>(meshes/[^<]+)</uri>");
    int own = 0;
    for (auto it = std::sregex_iterator(text.begin(), text.end(), uri);
         it != std::sregex_iterator(); ++it) {
      EXPECT_TRUE(fs::exists(dir_ / map.stem() / (*it)[1].str())) << (*it)[1].str();
      ++own;
    }
    EXPECT_GE(own, 2);  // the road and the ground
    EXPECT_FALSE(
        fs::exists(dir_ / (map.stem().string() + ".partial-" + std::to_string(::getpid()))));
  }
}

TEST_F(WorldGenTest, SceneryNeverStandsOnALane) {
  for (const char* name :
       {"fabriksgatan.xodr", "e6mini.xodr", "multi_intersections.xodr", "curves.xodr"}) {
    SCOPED_TRACE(name);
    const odr::Network net = odr::load(std::string(CONVOY_ESMINI_MAPS) + "/" + name);
    const auto stats = wg::generate_world(net, catalog_, {wg::Scenery::kUrban, 7}, dir_ / "w");
    wg::Occupancy lanes(odr::network_bounds(net), 60);
    lanes.mark_roads(net, 0.0);
    const std::string text = slurp(dir_ / "w" / "world.sdf");
    const std::regex pose(
        "<model name='scenery_[0-9]+'>\\s*<static>true</static>\\s*<pose>([-0-9.]+) ([-0-9.]+)");
    int n = 0;
    for (auto it = std::sregex_iterator(text.begin(), text.end(), pose);
         it != std::sregex_iterator(); ++it) {
      const double x = std::stod((*it)[1].str()), y = std::stod((*it)[2].str());
      EXPECT_FALSE(lanes.taken(x, y)) << "scenery at " << x << ", " << y;
      ++n;
    }
    EXPECT_GT(n, 10);
  }
}

TEST_F(WorldGenTest, TheSameSeedGivesTheSameWorldAndAnotherSeedAnother) {
  const fs::path map = fs::path(CONVOY_ESMINI_MAPS) / "jolengatan.xodr";
  make(map, "a", wg::Scenery::kRoadside, 3);
  make(map, "b", wg::Scenery::kRoadside, 3);
  make(map, "c", wg::Scenery::kRoadside, 4);
  EXPECT_EQ(slurp(dir_ / "a/world.sdf"), slurp(dir_ / "b/world.sdf"));
  EXPECT_EQ(road_tiles(dir_ / "a"), road_tiles(dir_ / "b"));
  EXPECT_GT(road_tiles(dir_ / "a").size(), 4u);  // the road in tiles
  EXPECT_NE(slurp(dir_ / "a/world.sdf"), slurp(dir_ / "c/world.sdf"));
}

TEST_F(WorldGenTest, SignalsBecomeLightsSignsAndPaint) {
  const auto stats =
      make(fs::path(CONVOY_ESMINI_MAPS) / "multi_intersections.xodr", "m", wg::Scenery::kNone);
  const std::string text = slurp(dir_ / "m/world.sdf");
  EXPECT_NE(text.find("<plugin name='convoy_signal' filename='convoy_signal'><signal>"),
            std::string::npos);
  EXPECT_NE(text.find("<class>traffic_light</class>"), std::string::npos);
  EXPECT_NE(text.find("<class>sign</class>"), std::string::npos);
  EXPECT_GT(stats.signals, 50u);
  // stop lines and crosswalks are paint: more white triangles than the lane marks alone
  odr::MeshOptions plain;
  plain.lane_materials = true;
  const auto marks =
      odr::build_road_mesh(odr::load(std::string(CONVOY_ESMINI_MAPS) + "/multi_intersections.xodr"),
                           plain)
          .parts.at(odr::SurfaceKind::kMarkWhite)
          .triangles.size();
  size_t faces = 0;
  for (const std::string& obj : road_tiles(dir_ / "m")) {
    const size_t at = obj.find("o mark_white");
    if (at == std::string::npos) continue;
    const size_t end = obj.find("\no ", at + 1);
    const std::string part =
        obj.substr(at, end == std::string::npos ? std::string::npos : end - at);
    for (size_t p = part.find("\nf "); p != std::string::npos; p = part.find("\nf ", p + 1))
      ++faces;
  }
  EXPECT_GT(faces, marks + 100);
  // its lane arrows (VIRES' SgRMArrow*) are paint too, not warnings
  for (const auto& w : stats.warnings) EXPECT_EQ(w.find("Arrow"), std::string::npos) << w;
}

TEST_F(WorldGenTest, UnknownSignalsAreWarningsNamingTheRoadAndSignal) {
  const auto stats =
      make(fs::path(CONVOY_ESMINI_MAPS) / "straight_500m_signs.xodr", "s", wg::Scenery::kNone);
  bool named = false;
  for (const auto& w : stats.warnings)
    named |= w.find("road 1 signal 14 (overtaking_ban_begin)") == 0;
  EXPECT_TRUE(named);
  EXPECT_GE(stats.signals, 10u);
}

TEST_F(WorldGenTest, ObjectsTunnelsAndRepeatsBecomeModels) {
  make(fs::path(CONVOY_ESMINI_MAPS) / "tunnels.xodr", "t", wg::Scenery::kNone);
  const std::string tunnels = slurp(dir_ / "t/world.sdf");
  EXPECT_NE(tunnels.find("<model name='tunnel_1_1'>"), std::string::npos);
  make(fs::path(CONVOY_ESMINI_MAPS) / "e6mini.xodr", "e", wg::Scenery::kNone);
  const std::string e6 = slurp(dir_ / "e/world.sdf");
  EXPECT_NE(e6.find("<model name='object_0_4_sweep'>"),
            std::string::npos);  // a railing along the road
  EXPECT_NE(e6.find("<model name='object_0_2_posts'>"),
            std::string::npos);  // rail poles every 4 m, one model
  make(fs::path(CONVOY_ESMINI_MAPS) / "crest-curve.xodr", "c", wg::Scenery::kNone);
  const std::string crest = slurp(dir_ / "c/world.sdf");
  EXPECT_NE(crest.find("<class>building</class>"), std::string::npos);  // from an outline
}

TEST_F(WorldGenTest, LaneTypesHaveTheirOwnMaterialsAndSuperelevationTilts) {
  odr::MeshOptions look;
  look.lane_materials = true;
  const auto parking =
      odr::build_road_mesh(odr::load(std::string(CONVOY_ESMINI_MAPS) + "/parking_demo.xodr"), look);
  EXPECT_TRUE(parking.parts.count(odr::SurfaceKind::kBiking));
  EXPECT_TRUE(parking.parts.count(odr::SurfaceKind::kShoulder));
  const auto plain =
      odr::build_road_mesh(odr::load(std::string(CONVOY_ESMINI_MAPS) + "/parking_demo.xodr"));
  EXPECT_FALSE(plain.parts.count(odr::SurfaceKind::kBiking));  // the shipped maps' look is kept
  const odr::Network velodrome = odr::load(std::string(CONVOY_ESMINI_MAPS) + "/velodrome.xodr");
  const odr::Road& road = velodrome.roads.front();
  double tilt = 0;
  for (double s = 0; s < road.length; s += 10)
    tilt = std::max(tilt, std::abs(road.superelevation_at(s)));
  EXPECT_GT(tilt, 0.1);
  const auto mesh = odr::build_road_mesh(velodrome, look);
  double zmin = 1e9, zmax = -1e9;
  for (const auto& p : mesh.parts.at(odr::SurfaceKind::kAsphalt).positions) {
    zmin = std::min(zmin, p[2]), zmax = std::max(zmax, p[2]);
  }
  EXPECT_GT(zmax - zmin, 1.0);
}

TEST_F(WorldGenTest, AMapThatCannotBeParsedIsAnErrorNamingFileAndLine) {
  try {
    odr::load(std::string(CONVOY_OPENDRIVE_TEST_DATA) + "/malformed.xodr");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("malformed.xodr:"), std::string::npos) << e.what();
  }
}

TEST_F(WorldGenTest, WhatCannotBeBuiltIsSkippedWithAWarningNamingIt) {
  odr::LoadOptions lenient;
  lenient.skip_bad_roads = true;
  const fs::path map = fs::path(CONVOY_WORLDGEN_TEST_DATA) / "bad_parts.xodr";
  EXPECT_THROW(odr::load(map.string()), std::runtime_error);  // strict: the whole map fails
  const odr::Network net = odr::load(map.string(), lenient);
  ASSERT_EQ(net.roads.size(), 1u);
  bool road2 = false;
  for (const auto& w : net.warnings)
    road2 |= w.find("road 2") != std::string::npos && w.find("skipped") != std::string::npos;
  EXPECT_TRUE(road2);
  const auto stats = wg::generate_world(net, catalog_, {wg::Scenery::kRoadside, 1}, dir_ / "bad");
  auto said = [&](const std::string& what) {
    for (const auto& w : stats.warnings) {
      if (w.find(what) != std::string::npos) return true;
    }
    return false;
  };
  EXPECT_TRUE(said("road 1 lane section 0 lane 2 (shoulder): width 0"));
  EXPECT_TRUE(said("road 1 object 7 (building) outline 0: the outline intersects itself"));
  EXPECT_TRUE(said("road 1 signal 9 (): unknown signal type 'zz99'"));
  EXPECT_TRUE(fs::exists(dir_ / "bad" / "world.sdf"));
  EXPECT_EQ(stats.signals, 1u);  // the stop sign
}

TEST_F(WorldGenTest, HillyMapsCollideAsAHeightFieldOfTheirRoads) {
  const odr::Network crest = odr::load(std::string(CONVOY_ESMINI_MAPS) + "/crest-curve.xodr");
  const wg::HeightField f = wg::road_height_field(crest, -0.04);
  const odr::Road& road = crest.roads.front();
  double worst = 0;
  for (double s = 5; s < road.length - 5; s += 7.3) {
    for (double t : {-3.0, -1.0, 1.0, 3.0}) {
      const auto p = road.offset_point(s, t);
      // between the samples the field is linear (as Bullet's triangles are): bilinear here
      const double u = (p.x - f.x0) / f.cell, v = (p.y - f.y0) / f.cell;
      const int c = static_cast<int>(std::floor(u)), r = static_cast<int>(std::floor(v));
      auto h = [&](int rr, int cc) { return f.heights[static_cast<size_t>(rr) * f.columns + cc]; };
      const double a = u - c, b = v - r;
      const double z = (1 - a) * (1 - b) * h(r, c) + a * (1 - b) * h(r, c + 1) +
                       (1 - a) * b * h(r + 1, c) + a * b * h(r + 1, c + 1);
      worst = std::max(worst, std::abs(z - road.surface_z(s, t)));
    }
  }
  EXPECT_LT(worst, 0.03);
  EXPECT_GT(f.max() - f.min(), 5.0);  // the crest
  make(fs::path(CONVOY_ESMINI_MAPS) / "crest-curve.xodr", "hill", wg::Scenery::kNone);
  const std::string hill = slurp(dir_ / "hill/world.sdf");
  EXPECT_NE(hill.find("<heightmap><uri>meshes/road_heights.pgm</uri>"), std::string::npos);
  EXPECT_EQ(
      slurp(dir_ / "hill/meshes/road_heights.pgm")
          .rfind("P5\n" + std::to_string(f.columns) + " " + std::to_string(f.rows) + "\n65535\n",
                 0),
      0u);
  make(fs::path(CONVOY_ESMINI_MAPS) / "straight_500m.xodr", "flat", wg::Scenery::kNone);
  EXPECT_EQ(slurp(dir_ / "flat/world.sdf").find("<heightmap>"), std::string::npos);
}

TEST_F(WorldGenTest, AMapFarApartGetsCoarserGridsNotAllTheMemory) {
  const fs::path map = fs::path(CONVOY_WORLDGEN_TEST_DATA) / "far_apart.xodr";
  const auto stats = make(map, "far", wg::Scenery::kRoadside);
  EXPECT_GT(stats.placements, 4u);
  const std::string pgm = slurp(dir_ / "far/meshes/road_heights.pgm");
  EXPECT_LT(pgm.size(), 25u * 1000 * 1000);  // at most 10 M samples of 2 bytes, and a header
}

TEST(SceneryTest, TheSceneryKindIsCheckedByName) {
  EXPECT_EQ(wg::parse_scenery("urban"), wg::Scenery::kUrban);
  EXPECT_THROW(wg::parse_scenery("forest"), std::invalid_argument);
}

TEST(MarkingsTest, ArrowsPointAlongTheirTrafficWithTheirHeadsOnTheirSide) {
  // straight_500m: road 1 runs along +x from the origin.
  const odr::Network net = odr::load(std::string(CONVOY_ESMINI_MAPS) + "/straight_500m.xodr");
  const odr::Road& road = net.roads.front();
  auto extent = [&](int dir, const char* kind) {
    wg::Part p;
    wg::paint_arrow(p, road, 100, -1.75, dir, kind);
    std::array<double, 4> box{1e9, -1e9, 1e9, -1e9};  // x min, max; y min, max
    for (const auto& v : p.positions) {
      box = {std::min(box[0], v[0]), std::max(box[1], v[0]), std::min(box[2], v[1]),
             std::max(box[3], v[1])};
    }
    return std::make_pair(box, p.triangles.size());
  };
  const auto [straight, n] = extent(+1, "straight");
  EXPECT_GT(n, 2u);
  EXPECT_NEAR(straight[0], 97.5, 1e-6);  // 5 m long, centred on s = 100
  EXPECT_NEAR(straight[1], 102.5, 1e-6);
  EXPECT_NEAR(0.5 * (straight[2] + straight[3]), -1.75, 1e-6);  // symmetric about its lane
  const auto [left, nl] = extent(+1, "left");
  EXPECT_GT(left[3], -1.75 + 0.8);                  // its head reaches out to the left (+y)...
  EXPECT_NEAR(left[2], -1.75 - 0.12, 1e-6);         // ...and nothing to the right of the shaft
  const auto [back_left, nb] = extent(-1, "left");  // traffic against s: its left is -y
  EXPECT_LT(back_left[2], -1.75 - 0.8);
  EXPECT_NEAR(back_left[3], -1.75 + 0.12, 1e-6);
}
