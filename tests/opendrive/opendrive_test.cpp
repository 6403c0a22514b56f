// OpenDRIVE parsing, plan-view geometry, lanes and error messages against hand-computed values.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "opendrive/parser.h"

namespace convoy::opendrive {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

const std::string kData = CONVOY_OPENDRIVE_TEST_DATA;

const Network& geometry_net() {
  static const Network net = load(kData + "/geometry.xodr");
  return net;
}

const Network& lanes_net() {
  static const Network net = load(kData + "/lanes.xodr");
  return net;
}

void expect_pose(const Pose2& p, double x, double y, double heading, double tol = 1e-9) {
  EXPECT_NEAR(p.x, x, tol);
  EXPECT_NEAR(p.y, y, tol);
  EXPECT_NEAR(std::remainder(p.heading - heading, 2 * std::numbers::pi), 0.0, tol);
}

// Arc length of v = c u^2 from u = 0 to u.
double parabola_arc(double c, double u) {
  return 0.5 * u * std::sqrt(1 + 4 * c * c * u * u) + std::asinh(2 * c * u) / (4 * c);
}

// A global point expressed in the frame (x0, y0, hdg).
std::pair<double, double> to_local(const Pose2& p, double x0, double y0, double hdg) {
  const double dx = p.x - x0, dy = p.y - y0;
  return {std::cos(hdg) * dx + std::sin(hdg) * dy, -std::sin(hdg) * dx + std::cos(hdg) * dy};
}

TEST(OpenDriveGeometry, LineMatchesAnalytic) {
  const Road& r = geometry_net().road("line");
  for (double s : {0.0, 3.3, 10.0}) {
    const Pose2 p = r.reference(s);
    expect_pose(p, 1 + s * std::cos(0.5), 2 + s * std::sin(0.5), 0.5);
    EXPECT_EQ(p.curvature, 0.0);
  }
}

TEST(OpenDriveGeometry, ArcsMatchAnalytic) {
  const Road& left = geometry_net().road("arc");  // R = 20 to the left from heading 0.3
  const double cx = -20 * std::sin(0.3), cy = 20 * std::cos(0.3);
  for (double s : {0.0, 7.5, 30.0}) {
    const double h = 0.3 + s / 20;
    const Pose2 p = left.reference(s);
    expect_pose(p, cx + 20 * std::sin(h), cy - 20 * std::cos(h), h);
    EXPECT_NEAR(p.curvature, 0.05, 1e-15);
  }
  const Road& right = geometry_net().road("arc_right");  // R = 10 to the right
  const double rx = 5 + 10 * std::sin(-1.2), ry = 5 - 10 * std::cos(-1.2);
  for (double s : {0.0, 11.0, 20.0}) {
    const double h = -1.2 - 0.1 * s;
    expect_pose(right.reference(s), rx - 10 * std::sin(h), ry + 10 * std::cos(h), h);
  }
}

TEST(OpenDriveGeometry, SpiralFromZeroCurvatureIsTheFresnelIntegral) {
  // curvature pi/100 after 100 m: x = a C(1), y = a S(1) with a = 100 (Fresnel, pi/2 t^2).
  const Pose2 p = geometry_net().road("fresnel").reference(100);
  expect_pose(p, 77.98934003768228, 43.82591473903548, std::numbers::pi / 2, 1e-8);
  EXPECT_NEAR(p.curvature, std::numbers::pi / 100, 1e-15);
}

TEST(OpenDriveGeometry, SpiralMatchesHighPrecisionReference) {
  const Road& r = geometry_net().road("spiral");  // x 10, y -5, hdg 1, k -0.02 -> 0.03 over 100
  const double k0 = -0.02, k1 = 0.03, L = 100;
  auto theta = [&](long double t) { return 1.0L + k0 * t + (k1 - k0) * t * t / (2 * L); };
  for (double s : {12.5, 50.0, 100.0}) {
    // Composite Simpson, 200000 intervals, long double: error far below 1e-9 m.
    const int n = 200000;
    const long double h = s / n;
    long double x = 0, y = 0;
    for (int i = 0; i <= n; ++i) {
      const long double w = (i == 0 || i == n) ? 1 : (i % 2 ? 4 : 2);
      x += w * std::cos(theta(i * h));
      y += w * std::sin(theta(i * h));
    }
    const Pose2 p = r.reference(s);
    // Brief asks for 1 mm over 100 m; the Gauss-Legendre panels do far better.
    expect_pose(p, 10 + static_cast<double>(x * h / 3), -5 + static_cast<double>(y * h / 3),
                static_cast<double>(theta(s)), 1e-9);
    EXPECT_NEAR(p.curvature, k0 + (k1 - k0) * s / L, 1e-15);
  }
}

TEST(OpenDriveGeometry, Poly3IsParametrisedByArcLength) {
  const Road& r = geometry_net().road("poly3");  // v = 0.5 + 0.01 u^2 from (2, 1), hdg 0.25
  const double L = r.length;
  const Pose2 end = r.reference(L);
  expect_pose(end, 2 + 20 * std::cos(0.25) - 4.5 * std::sin(0.25),
              1 + 20 * std::sin(0.25) + 4.5 * std::cos(0.25), 0.25 + std::atan(0.4), 1e-9);
  EXPECT_NEAR(end.curvature, 0.02 / std::pow(1.16, 1.5), 1e-12);
  const auto [u0, v0] = to_local(r.reference(0), 2, 1, 0.25);
  EXPECT_NEAR(u0, 0, 1e-12);
  EXPECT_NEAR(v0, 0.5, 1e-12);
  for (double s : {4.0, 10.0, 17.0}) {
    const auto [u, v] = to_local(r.reference(s), 2, 1, 0.25);
    EXPECT_NEAR(v, 0.5 + 0.01 * u * u, 1e-9) << "s=" << s;
    EXPECT_NEAR(parabola_arc(0.01, u), s, 1e-9) << "s=" << s;
  }
}

TEST(OpenDriveGeometry, ParamPoly3ArcLengthRangeOnAStraightLine) {
  const Road& r = geometry_net().road("pp3_unit");  // u = 0.6 p, v = 0.8 p
  expect_pose(r.reference(5), 3, 4, std::atan2(0.8, 0.6));
  expect_pose(r.reference(10), 6, 8, std::atan2(0.8, 0.6));
}

TEST(OpenDriveGeometry, ParamPoly3NormalizedRange) {
  const Road& r = geometry_net().road("pp3_normalized");  // u = 20 p, v = 4 p^2: v = 0.01 u^2
  expect_pose(r.reference(r.length), 2 + 20 * std::cos(0.25) - 4 * std::sin(0.25),
              1 + 20 * std::sin(0.25) + 4 * std::cos(0.25), 0.25 + std::atan(0.4), 1e-9);
  for (double s : {5.0, 10.0, 15.0}) {
    const auto [u, v] = to_local(r.reference(s), 2, 1, 0.25);
    EXPECT_NEAR(v, 0.01 * u * u, 1e-9);
    EXPECT_NEAR(parabola_arc(0.01, u), s, 1e-9);
  }
}

TEST(OpenDriveGeometry, ParamPoly3ArcLengthRangeScalesToTheCurvesEnd) {
  // u = p, v = 0.01 p^2, p in [0, 20]: the curve is 20.5212 m long but @length is 20, so s is
  // scaled: s = 20 is the curve's end, and s covers the same fraction of its arc length.
  const Road& r = geometry_net().road("pp3_arclength");
  const double true_length = parabola_arc(0.01, 20);
  expect_pose(r.reference(20), 20, 4, std::atan(0.4), 1e-9);
  for (double s : {5.0, 10.0}) {
    const Pose2 p = r.reference(s);
    EXPECT_NEAR(p.y, 0.01 * p.x * p.x, 1e-9);
    EXPECT_NEAR(parabola_arc(0.01, p.x) / true_length, s / 20, 1e-9);
  }
}

TEST(OpenDriveGeometry, RoadPicksTheGeometryContainingS) {
  const Road& r = geometry_net().road("multi");  // line 10, quarter circle R 10, line 5
  const double q = 5 * std::numbers::pi;
  expect_pose(r.reference(5), 5, 0, 0);
  expect_pose(r.reference(10 + q / 2), 10 + 10 * std::sin(std::numbers::pi / 4),
              10 - 10 * std::cos(std::numbers::pi / 4), std::numbers::pi / 4);
  expect_pose(r.reference(10 + q + 2), 20, 12, std::numbers::pi / 2);
  expect_pose(r.reference(1e9), 20, 15, std::numbers::pi / 2);  // clamped to the end
}

TEST(OpenDriveLanes, WidthRecordsWithSOffsetsAndSections) {
  const Road& r = lanes_net().road("straight");
  ASSERT_EQ(r.sections.size(), 2u);
  EXPECT_EQ(r.sections[0].s_end, 40);
  EXPECT_EQ(r.section_index(39.9), 0u);
  EXPECT_EQ(r.section_index(40), 1u);
  EXPECT_DOUBLE_EQ(r.lane_width(0, 1, 5), 3);
  EXPECT_DOUBLE_EQ(r.lane_width(0, 1, 15), 3 + 0.1 * 5 - 0.002 * 25);
  EXPECT_DOUBLE_EQ(r.lane_width(0, -2, 10), 2);  // records given out of order in the file
  EXPECT_DOUBLE_EQ(r.lane_width(0, -2, 30), 2 + 0.05 * 10);
  EXPECT_NEAR(r.lane_width(1, 1, 60), 3.25 + 0.001 * 400 - 0.00001 * 8000, 1e-12);
  EXPECT_DOUBLE_EQ(r.lane_width(1, -1, 60), 3.5);
  EXPECT_EQ(r.lane_width(0, 0, 5), 0);
  EXPECT_THROW(r.lane_width(0, 3, 5), std::runtime_error);
}

TEST(OpenDriveLanes, LaneOffset) {
  const Road& r = lanes_net().road("straight");
  double slope = -1;
  EXPECT_DOUBLE_EQ(r.lane_offset(10, &slope), 0.5);
  EXPECT_EQ(slope, 0);
  EXPECT_DOUBLE_EQ(r.lane_offset(60, &slope), 0.7);
  EXPECT_DOUBLE_EQ(slope, 0.02);
}

TEST(OpenDriveLanes, LanePointOnLeftAndRightLanes) {
  const Road& r = lanes_net().road("straight");
  // s 15: offset 0.5, lane 1 width 3.45 (slope 0.08), lane -1 3.5, lane -2 2.
  expect_pose(r.lane_point(15, 1, 0.5), 15, 0.5 + 3.45 / 2, std::atan(0.04), 1e-12);
  expect_pose(r.lane_point(15, 1, 0), 15, 0.5, 0, 1e-12);
  expect_pose(r.lane_point(15, -1, 0), 15, 0.5, 0, 1e-12);
  expect_pose(r.lane_point(15, -1, 0.5), 15, 0.5 - 1.75, 0, 1e-12);
  expect_pose(r.lane_point(15, -2, 1), 15, 0.5 - 3.5 - 2, 0, 1e-12);
  expect_pose(r.lane_point(30, -2, 1), 15 + 15, -3 - 2.5, std::atan(-0.05), 1e-12);
  expect_pose(r.lane_point(60, 0, 0.5), 60, 0.7, std::atan(0.02), 1e-12);
  // Section 2 at s 60: offset 0.7 (slope 0.02), lane 1 width 3.57 (slope 0.028).
  expect_pose(r.lane_point(60, 1, 1), 60, 0.7 + 3.57, std::atan(0.048), 1e-12);
  try {
    r.lane_point(60, -3, 0.5);
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), AllOf(HasSubstr("road straight"), HasSubstr("lane -3")));
  }
}

TEST(OpenDriveLanes, LanePointOnACurve) {
  const Road& r = lanes_net().road("curved");  // arc R 50 to the left, centre (0, 50)
  for (double s : {0.0, 20.0, 60.0}) {
    const double phi = s / 50;
    const Pose2 left = r.lane_point(s, 1, 0.5);  // radius 48.5
    expect_pose(left, 48.5 * std::sin(phi), 50 - 48.5 * std::cos(phi), phi, 1e-9);
    EXPECT_NEAR(left.curvature, 1 / 48.5, 1e-12);
    const Pose2 right = r.lane_point(s, -1, 0.5);  // radius 51.5
    expect_pose(right, 51.5 * std::sin(phi), 50 - 51.5 * std::cos(phi), phi, 1e-9);
    EXPECT_NEAR(right.curvature, 1 / 51.5, 1e-12);
  }
}

TEST(OpenDriveParse, RoadMarksAndLinks) {
  const Road& r = lanes_net().road("straight");
  const Lane* centre = r.sections[0].find_lane(0);
  ASSERT_NE(centre, nullptr);
  ASSERT_EQ(centre->road_marks.size(), 2u);
  EXPECT_EQ(centre->road_marks[1].type, "solid solid");
  EXPECT_EQ(centre->road_marks[1].start, 20);
  const Lane* left = r.sections[0].find_lane(1);
  EXPECT_EQ(left->road_marks[0].color, "yellow");
  EXPECT_EQ(left->road_marks[0].width, 0.15);
  const RoadMark& custom = r.sections[1].find_lane(1)->road_marks[0];
  EXPECT_EQ(custom.start, 40);
  ASSERT_EQ(custom.lines.size(), 1u);
  EXPECT_EQ(custom.lines[0].length, 2);
  EXPECT_EQ(custom.lines[0].space, 2);
  EXPECT_EQ(r.sections[0].find_lane(-1)->road_marks[0].width, 0.12);  // default, standard
  EXPECT_TRUE(r.predecessor.empty());
}

std::string error_of(const std::string& xml, const std::string& name = "inline.xodr") {
  try {
    parse(xml, name);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(OpenDriveErrors, MalformedXmlNamesFileAndLine) {
  try {
    load(kData + "/malformed.xodr");
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), AllOf(HasSubstr("malformed.xodr:"), HasSubstr("malformed XML")));
  }
}

TEST(OpenDriveErrors, UnknownGeometryNamesFileRoadAndGeometry) {
  try {
    load(kData + "/unknown_geometry.xodr");
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("unknown_geometry.xodr:7: road 7 geometry 1: unknown "
                                    "geometry type 'foo'"));
  }
}

TEST(OpenDriveErrors, MissingFileAndBadValues) {
  EXPECT_THAT(error_of("<OpenDRIVE/>"), HasSubstr("inline.xodr:1: no <road> elements"));
  EXPECT_THAT(error_of("<root/>"), HasSubstr("root element is 'root'"));
  const std::string lanes =
      "<lanes><laneSection s='0'><center><lane id='0'/></center></laneSection></lanes>";
  EXPECT_THAT(error_of("<OpenDRIVE><road id='4' length='x'/></OpenDRIVE>"),
              HasSubstr("inline.xodr:1: road 4: attribute 'length' is not a number: 'x'"));
  EXPECT_THAT(error_of("<OpenDRIVE>\n<road id='4' length='1'><planView><geometry s='0' x='0' "
                       "y='0' length='1'><line/></geometry></planView>" +
                       lanes + "</road></OpenDRIVE>"),
              HasSubstr("inline.xodr:2: road 4 geometry 0: missing attribute 'hdg'"));
  EXPECT_THAT(error_of("<OpenDRIVE><road id='4' length='1'><link><successor elementType='road' "
                       "elementId='9'/></link><planView><geometry s='0' x='0' y='0' hdg='0' "
                       "length='1'><line/></geometry></planView>" +
                       lanes + "</road></OpenDRIVE>"),
              HasSubstr("road 4 successor: links to unknown road '9'"));
  EXPECT_THAT(error_of("<OpenDRIVE><road id='4' length='1'><planView><geometry s='0' x='0' "
                       "y='0' hdg='0' length='1'><line/></geometry></planView><lanes><laneSection "
                       "s='0'><center><lane id='0'/></center><right><lane id='1'/></right>"
                       "</laneSection></lanes></road></OpenDRIVE>"),
              HasSubstr("road 4 laneSection 0 lane 1: lane id does not belong in <right>"));
  try {
    load(kData + "/does_not_exist.xodr");
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("does_not_exist.xodr: cannot open file"));
  }
}

}  // namespace
}  // namespace convoy::opendrive
