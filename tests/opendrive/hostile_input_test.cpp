// Files that would make sampling or meshing run for ever or take all memory end in an error
// (inputs found by fuzz/opendrive, reduced by hand).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "opendrive/parser.h"
#include "opendrive/road_mesh.h"
#include "opendrive/sampling.h"

namespace convoy::opendrive {
namespace {

using ::testing::HasSubstr;

// One straight road of `length` m with a right driving lane of the given width record and
// road mark.
Network road(const std::string& length, const std::string& width, const std::string& mark) {
  const std::string xml =
      "<OpenDRIVE><header revMajor='1' revMinor='6'/><road id='r' length='" + length +
      "' junction='-1'><planView><geometry s='0' x='0' y='0' hdg='0' length='" + length +
      "'><line/></geometry></planView><lanes><laneSection s='0'><center><lane id='0' "
      "type='none'/></center><right><lane id='-1' type='driving'>" +
      width + mark + "</lane></right></laneSection></lanes></road></OpenDRIVE>";
  return parse(xml, "hostile.xodr");
}

const std::string kWidth = "<width sOffset='0' a='3' b='0' c='0' d='0'/>";

TEST(OpenDriveHostileInput, RunawayLaneWidthIsRefusedWhenRead) {
  // d = 3: the lane would be 3 * 220^3 m wide at the end (its centre some 1e8 m long, and
  // sampling or meshing along its border would take minutes).
  try {
    road("220", "<width sOffset='0' a='1' b='0' c='0' d='3'/>", "");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("hostile.xodr"));
    EXPECT_THAT(e.what(), HasSubstr("road r"));
    EXPECT_THAT(e.what(), HasSubstr("lane -1 width reaches"));
    EXPECT_THAT(e.what(), HasSubstr("at most 1000 m"));
  }
  // The same with c = 8 (found by fuzz/opendrive on the Parkring: 2148 m, 17 s a sample).
  EXPECT_THROW(road("16.4", "<width sOffset='0' a='0.5' b='0' c='8' d='0'/>", ""),
               std::runtime_error);
  EXPECT_NO_THROW(sample_lane_centre(road("220", kWidth, ""), "r", -1, 1.0));
  // A spiral wound 100,000 times is evaluated from a table of its panels: each pose costs one
  // panel's integral, not the whole spiral's.
  const std::string xml =
      "<OpenDRIVE><header revMajor='1' revMinor='6'/><road id='s' length='1000' "
      "junction='-1'><planView><geometry s='0' x='0' y='0' hdg='0' length='1000'><spiral "
      "curvStart='0' curvEnd='1000'/></geometry></planView><lanes><laneSection "
      "s='0'><center><lane id='0' type='none'/></center><right><lane id='-1' "
      "type='driving'>" +
      kWidth + "</lane></right></laneSection></lanes></road></OpenDRIVE>";
  const Network spiral = parse(xml, "spiral.xodr");
  const Geometry& g = spiral.roads[0].plan_view[0];
  EXPECT_LE(std::get<Spiral>(g.shape).starts.size(), size_t{kMaxSpiralPanels} + 1);
  for (double ds : {0.0, 1e-3, 0.5, 999.0, 1000.0}) {
    const Pose2 p = g.at(ds);
    EXPECT_TRUE(std::isfinite(p.x) && std::isfinite(p.y)) << ds;
    EXPECT_NEAR(p.curvature, ds, 1e-9);
  }
}

TEST(OpenDriveHostileInput, RoadTooLongToSample) {
  const Network net = road("1e12", kWidth, "");
  EXPECT_THROW(road_stations(net.roads[0], 0, 1e12), std::runtime_error);
  EXPECT_THROW(build_road_mesh(net), std::runtime_error);
}

TEST(OpenDriveHostileInput, DashesOfNoLengthDoNotLoopForever) {
  const auto mark = [](const std::string& line) {
    return "<roadMark sOffset='0' type='broken'><type name='x'>" + line + "</type></roadMark>";
  };
  // A period of 2e-300 m never moved x forward; too many dashes is an error.
  EXPECT_THROW(build_road_mesh(road("100", kWidth, mark("<line length='1e-300' space='1e-300'/>"))),
               std::runtime_error);
  // A first dash far before the mark's start is skipped over, not walked to.
  const RoadMesh mesh =
      build_road_mesh(road("100", kWidth, mark("<line length='3' space='6' sOffset='-1e300'/>")));
  EXPECT_GT(mesh.parts.count(SurfaceKind::kMarkWhite), 0u);
}

}  // namespace
}  // namespace convoy::opendrive
