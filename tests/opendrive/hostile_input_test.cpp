// Files that would make sampling or meshing run for ever or take all memory end in an error
// (inputs found by fuzz/opendrive, reduced by hand).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

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

TEST(OpenDriveHostileInput, RunawayLaneWidthIsTooManyPoints) {
  // d = 3: the lane is 3 * 220^3 m wide at the end, its centre some 1e8 m long.
  const Network net = road("220", "<width sOffset='0' a='1' b='0' c='0' d='3'/>", "");
  try {
    sample_lane_centre(net, "r", -1, 1.0);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("hostile.xodr: road r lane -1"));
    EXPECT_THAT(e.what(), HasSubstr("too many points"));
  }
  EXPECT_NO_THROW(sample_lane_centre(road("220", kWidth, ""), "r", -1, 1.0));
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
