// The Parkring ring road, routes along its lanes and road meshes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <set>

#include "opendrive/mesh_io.h"
#include "opendrive/parser.h"
#include "opendrive/road_mesh.h"
#include "opendrive/sampling.h"

namespace convoy::opendrive {
namespace {

const std::string kData = CONVOY_OPENDRIVE_TEST_DATA;

const Network& parkring() {
  static const Network net = load(CONVOY_PARKRING_XODR);
  return net;
}

// Distance from (x, y) to a polyline.
double distance_to(const std::vector<Pose2>& line, double x, double y) {
  double best = INFINITY;
  for (size_t i = 0; i + 1 < line.size(); ++i) {
    const double ax = line[i].x, ay = line[i].y;
    const double dx = line[i + 1].x - ax, dy = line[i + 1].y - ay;
    const double len2 = dx * dx + dy * dy;
    const double t = len2 > 0 ? std::clamp(((x - ax) * dx + (y - ay) * dy) / len2, 0.0, 1.0) : 0;
    best = std::min(best, std::hypot(ax + t * dx - x, ay + t * dy - y));
  }
  return best;
}

TEST(Parkring, LoadsAsAClosedRingOfAboutOneKilometre) {
  const Network& net = parkring();
  EXPECT_TRUE(net.warnings.empty()) << net.warnings.front();
  ASSERT_EQ(net.roads.size(), 4u);
  EXPECT_GE(net.total_length(), 900);
  EXPECT_LE(net.total_length(), 1200);
  // Every road ends where its successor starts.
  for (const Road& r : net.roads) {
    const Road& next = net.road(r.successor.element_id);
    const Pose2 a = r.reference(r.length), b = next.reference(0);
    EXPECT_LT(std::hypot(a.x - b.x, a.y - b.y), 0.01) << "road " << r.id;
    EXPECT_LT(std::abs(std::remainder(a.heading - b.heading, 2 * std::numbers::pi)), 1e-4);
  }
  const Route loop = plan_route(net, "1", 0, Travel::kReferenceDirection);
  EXPECT_TRUE(loop.closed);
  EXPECT_EQ(loop.legs.size(), 4u);
  EXPECT_LT(loop.closure_gap, 0.01);
  EXPECT_LT(std::abs(loop.closure_heading), 1e-4);
}

TEST(Parkring, CrossSection) {
  const Road& r = parkring().roads.front();
  const LaneSection& sec = r.sections.front();
  for (int side : {1, -1}) {
    EXPECT_EQ(sec.find_lane(side)->type, "driving");
    EXPECT_GE(r.lane_width(0, side, 10), 3.25);
    EXPECT_LE(r.lane_width(0, side, 10), 3.5);
    EXPECT_EQ(sec.find_lane(side)->road_marks.front().type, "solid");
    EXPECT_EQ(sec.find_lane(4 * side)->type, "sidewalk");
    EXPECT_EQ(r.lane_width(0, 4 * side, 10), 2.0);
  }
  EXPECT_EQ(sec.find_lane(0)->road_marks.front().type, "broken");
}

TEST(Parkring, RouteWaypointsAreEvenAndOnTheLaneCentre) {
  const Network& net = parkring();
  std::vector<Pose2> reference;
  for (const Road& r : net.roads) {
    for (double s = 0; s < r.length; s += 0.1) reference.push_back(r.reference(s));
  }
  reference.push_back(reference.front());
  for (int lane : {-1, 1}) {
    SCOPED_TRACE("lane " + std::to_string(lane));
    const double ds = 2.0;
    const Route route = sample_route(net, "1", lane, ds);
    ASSERT_TRUE(route.closed);
    EXPECT_EQ(route.legs.size(), 4u);
    EXPECT_LT(route.closure_gap, 0.01);  // the end of the route is its start
    EXPECT_LT(std::abs(route.closure_heading), 1e-4);
    const auto& pts = route.points;
    ASSERT_GT(pts.size(), 400u);
    double turn = 0;
    for (size_t i = 0; i < pts.size(); ++i) {
      const Pose2& a = pts[i];
      const Pose2& b = pts[(i + 1) % pts.size()];  // includes the gap back to the start
      EXPECT_NEAR(std::hypot(b.x - a.x, b.y - a.y), ds, 0.01 * ds) << "point " << i;
      const double d = distance_to(reference, a.x, a.y);
      EXPECT_GE(d, 1.6) << "point " << i;
      EXPECT_LE(d, 1.8) << "point " << i;
      // Heading points at the next waypoint (within the chord angle of the tightest curve).
      const double chord = std::atan2(b.y - a.y, b.x - a.x);
      EXPECT_LT(std::abs(std::remainder(chord - a.heading, 2 * std::numbers::pi)), 0.06);
      turn += std::remainder(b.heading - a.heading, 2 * std::numbers::pi);
    }
    // Right-hand traffic: lane -1 runs counter-clockwise (with s), lane 1 clockwise.
    EXPECT_NEAR(turn, lane < 0 ? 2 * std::numbers::pi : -2 * std::numbers::pi, 1e-6);
  }
}

TEST(Parkring, LaneCentreOfOneRoad) {
  const Network& net = parkring();
  const Road& r = net.road("2");
  const std::vector<Pose2> pts = sample_lane_centre(net, "2", -1, 5.0);
  ASSERT_GE(pts.size(), 2u);
  const Pose2 start = r.lane_point(0, -1, 0.5), end = r.lane_point(r.length, -1, 0.5);
  EXPECT_NEAR(pts.front().x, start.x, 1e-9);
  EXPECT_NEAR(pts.back().y, end.y, 1e-9);
  for (size_t i = 0; i + 2 < pts.size(); ++i) {
    EXPECT_NEAR(std::hypot(pts[i + 1].x - pts[i].x, pts[i + 1].y - pts[i].y), 5.0, 0.05);
  }
  EXPECT_THROW(sample_lane_centre(net, "2", -7, 5.0), std::runtime_error);
  EXPECT_THROW(sample_lane_centre(net, "nope", -1, 5.0), std::runtime_error);
}

double area(const Mesh& m) {
  double sum = 0;
  for (const auto& t : m.triangles) {
    const auto &p = m.positions[t[0]], &q = m.positions[t[1]], &r = m.positions[t[2]];
    const double ux = q[0] - p[0], uy = q[1] - p[1], uz = q[2] - p[2];
    const double vx = r[0] - p[0], vy = r[1] - p[1], vz = r[2] - p[2];
    sum += 0.5 * std::hypot(uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx);
  }
  return sum;
}

void expect_valid(const RoadMesh& mesh) {
  for (const auto& [kind, m] : mesh.parts) {
    SCOPED_TRACE(surface_kind_name(kind));
    ASSERT_EQ(m.normals.size(), m.positions.size());
    for (size_t i = 0; i < m.positions.size(); ++i) {
      for (int k = 0; k < 3; ++k) ASSERT_TRUE(std::isfinite(m.positions[i][k]));
      const auto& n = m.normals[i];
      ASSERT_NEAR(std::hypot(n[0], n[1], n[2]), 1.0, 1e-9);
    }
    for (const auto& t : m.triangles) {
      for (uint32_t v : t) ASSERT_LT(v, m.positions.size());
    }
  }
}

TEST(RoadMesh, ParkringSurfaces) {
  const Network& net = parkring();
  const RoadMesh mesh = build_road_mesh(net);
  expect_valid(mesh);
  std::set<std::string> kinds;
  for (const auto& [kind, m] : mesh.parts) kinds.insert(surface_kind_name(kind));
  EXPECT_EQ(kinds, (std::set<std::string>{"asphalt", "curb", "grass", "mark_white", "sidewalk"}));
  // Asphalt faces up at z 0, sidewalks at the curb height, marks 1 cm above the asphalt.
  for (const auto& n : mesh.parts.at(SurfaceKind::kAsphalt).normals) EXPECT_GT(n[2], 0.999);
  for (const auto& p : mesh.parts.at(SurfaceKind::kSidewalk).positions) EXPECT_EQ(p[2], 0.12);
  for (const auto& p : mesh.parts.at(SurfaceKind::kMarkWhite).positions) EXPECT_EQ(p[2], 0.01);
  for (const auto& n : mesh.parts.at(SurfaceKind::kCurb).normals) EXPECT_LT(std::abs(n[2]), 1e-9);
  // Areas: the lanes' widths times the lengths of their centres (length at offset t around a
  // loop turning 2 pi: L - 2 pi t); marks: two 0.12 m edge lines and 3 m / 6 m centre dashes.
  const double L = net.total_length(), two_pi = 2 * std::numbers::pi;
  EXPECT_NEAR(area(mesh.parts.at(SurfaceKind::kSidewalk)), 2.0 * 2 * L, 1.0);
  EXPECT_NEAR(area(mesh.parts.at(SurfaceKind::kAsphalt)), (3.4 + 0.5) * 2 * L, 1.0);
  double dashes = 0;
  for (const Road& r : net.roads) {
    const double periods = std::floor(r.length / 9);
    dashes += 3 * periods + std::min(3.0, r.length - 9 * periods);
  }
  const double edges = (L - two_pi * 3.4) + (L + two_pi * 3.4);
  EXPECT_NEAR(area(mesh.parts.at(SurfaceKind::kMarkWhite)), 0.12 * (edges + dashes), 0.2);
  // Curb faces: sidewalk and verge stand 0.12 m high, one step up at each shoulder and one
  // step down at each outer edge.
  EXPECT_NEAR(
      area(mesh.parts.at(SurfaceKind::kCurb)),
      0.12 * ((L - two_pi * 3.9) + (L + two_pi * 3.9) + (L - two_pi * 6.9) + (L + two_pi * 6.9)),
      0.5);
}

TEST(RoadMesh, LanesFileKindsAndFiles) {
  const Network net = load(kData + "/lanes.xodr");
  const RoadMesh mesh = build_road_mesh(net);
  expect_valid(mesh);
  for (SurfaceKind k : {SurfaceKind::kAsphalt, SurfaceKind::kSidewalk, SurfaceKind::kGrass,
                        SurfaceKind::kCurb, SurfaceKind::kMarkWhite, SurfaceKind::kMarkYellow}) {
    EXPECT_TRUE(mesh.parts.count(k)) << surface_kind_name(k);
  }
  // Curbs of the straight road face the asphalt (+y, at y -3 .. -2, lane offset 0.5 .. 1.5)
  // or, at the outer edge of the sidewalk / verge (y -6 .. -4), the outside (-y).
  const Mesh& curb = mesh.parts.at(SurfaceKind::kCurb);
  for (size_t i = 0; i < curb.positions.size(); ++i) {
    const double y = curb.positions[i][1];
    ASSERT_TRUE(y < -3.99 || y > -3.01) << y;
    EXPECT_NEAR(curb.normals[i][1], y > -3.5 ? 1.0 : -1.0, 0.002) << "y " << y;  // widening
    EXPECT_EQ(curb.normals[i][2], 0.0);
  }
  EXPECT_NEAR(area(curb), 2 * 0.12 * 100, 0.01);
  // Yellow: the solid 0.15 m edge line of lane 1 over the first section (40 m).
  EXPECT_NEAR(area(mesh.parts.at(SurfaceKind::kMarkYellow)), 0.15 * 40, 0.05);

  const auto dir = std::filesystem::temp_directory_path() / "convoy_opendrive_test";
  std::filesystem::create_directories(dir);
  write_obj(mesh, dir / "road.obj", "road.mtl");
  write_mtl(mesh, dir / "road.mtl");
  write_road_sdf(dir / "road.sdf", "road.obj", network_bounds(net));
  std::ifstream obj(dir / "road.obj");
  std::string line;
  size_t v = 0, vn = 0, f = 0, o = 0;
  while (std::getline(obj, line)) {
    v += line.rfind("v ", 0) == 0;
    vn += line.rfind("vn ", 0) == 0;
    f += line.rfind("f ", 0) == 0;
    o += line.rfind("o ", 0) == 0;
  }
  EXPECT_EQ(v, vn);
  EXPECT_EQ(f, mesh.triangle_count());
  EXPECT_EQ(o, mesh.parts.size());
  std::ifstream sdf(dir / "road.sdf");
  const std::string text((std::istreambuf_iterator<char>(sdf)), {});
  EXPECT_NE(text.find("<model name=\"road\">"), std::string::npos);
  EXPECT_NE(text.find("<plane>"), std::string::npos);
  EXPECT_NE(text.find("<cast_shadows>false</cast_shadows>"), std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST(Bounds, CoverTheOuterBorders) {
  const Bounds b = network_bounds(load(kData + "/lanes.xodr"));
  // Straight road: x 0..100; lowest border t = 0.5 - 3.5 - 3 at s 40, highest 1.5 + 4.69 at
  // s 100. Curved road (R 50 about (0, 50), 1.2 rad, borders at +-3): highest at its end.
  EXPECT_NEAR(b.min[0], 0, 1e-9);
  EXPECT_NEAR(b.max[0], 100, 1e-9);
  EXPECT_NEAR(b.min[1], -6, 1e-9);
  EXPECT_NEAR(b.max[1], 50 - 47 * std::cos(1.2), 1e-9);
  EXPECT_EQ(b.min[2], 0);
  EXPECT_EQ(b.max[2], 0);
}

}  // namespace
}  // namespace convoy::opendrive
