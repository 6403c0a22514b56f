// The world generator's polygon helpers and signal classification.
#include "worldgen/shapes.h"

#include <gtest/gtest.h>

#include <cmath>

#include "worldgen/signals.h"

namespace wg = convoy::worldgen;
namespace odr = convoy::opendrive;

TEST(ShapesTest, AConcavePolygonIsCoveredByItsTriangles) {
  // an L: 3 x 3 with a 2 x 2 corner cut away, area 5, clockwise to test the reversal
  std::vector<wg::Vec2> l = {{0, 0}, {0, 3}, {1, 3}, {1, 1}, {3, 1}, {3, 0}};
  const auto tris = wg::triangulate(l);
  ASSERT_EQ(tris.size(), 4u);
  double area = 0;
  for (const auto& t : tris) area += std::abs(wg::signed_area2({l[t[0]], l[t[1]], l[t[2]]}));
  EXPECT_NEAR(area / 2, 5.0, 1e-9);
}

TEST(ShapesTest, ABowTieIntersectsItselfAndASquareDoesNot) {
  EXPECT_TRUE(wg::self_intersects({{0, 0}, {1, 1}, {1, 0}, {0, 1}}));
  EXPECT_FALSE(wg::self_intersects({{0, 0}, {1, 0}, {1, 1}, {0, 1}}));
}

TEST(ShapesTest, PrismWallsFaceOutwardsAndTheRoofUp) {
  wg::Part walls, roof;
  wg::add_prism(walls, roof, {{0, 0, 0}, {4, 0, 0}, {4, 2, 0}, {0, 2, 0}}, {3, 3, 3, 3});
  ASSERT_EQ(walls.triangles.size(), 8u);
  ASSERT_EQ(roof.triangles.size(), 2u);
  for (const auto& n : roof.normals) EXPECT_NEAR(n[2], 1.0, 1e-9);
  // each wall's normal points away from the centre (2, 1)
  for (size_t i = 0; i < walls.positions.size(); ++i) {
    const auto& p = walls.positions[i];
    const auto& n = walls.normals[i];
    EXPECT_GT((p[0] - 2) * n[0] + (p[1] - 1) * n[1], 0) << i;
  }
}

odr::Signal signal(const char* country, const char* type, const char* subtype, double value,
                   const char* name = "") {
  odr::Signal s;
  s.country = country;
  s.type = type;
  s.subtype = subtype;
  s.value = value;
  s.name = name;
  return s;
}

TEST(SignalClassTest, KnowsTheCataloguesTheMapsUse) {
  EXPECT_EQ(wg::classify_signal(signal("OpenDRIVE", "1000001", "-1", NAN)).kind,
            wg::SignalKind::kTrafficLight);
  EXPECT_EQ(wg::classify_signal(signal("OpenDRIVE", "1000002", "-1", NAN)).kind,
            wg::SignalKind::kPedestrianLight);
  EXPECT_EQ(wg::classify_signal(signal("OpenDRIVE", "294", "-1", NAN)).kind,
            wg::SignalKind::kStopLine);
  EXPECT_EQ(
      wg::classify_signal(signal("OpenDRIVE", "1000003", "-1", 4, "SgRMCrosswalk-2Lanes")).kind,
      wg::SignalKind::kCrosswalk);
  const auto de = wg::classify_signal(signal("DE", "274", "", 70));
  EXPECT_EQ(de.sign_type, "speed_limit");
  EXPECT_EQ(de.value, 70);
  const auto se = wg::classify_signal(signal("se", "c", "31", 5));  // C31-5: 50 km/h
  EXPECT_EQ(se.sign_type, "speed_limit");
  EXPECT_EQ(se.value, 50);
  EXPECT_EQ(wg::classify_signal(signal("OpenDRIVE", "205", "-1", NAN)).sign_type, "yield");
  EXPECT_EQ(wg::classify_signal(signal("OpenDRIVE", "306", "-1", NAN)).sign_type, "priority");
  EXPECT_EQ(wg::classify_signal(signal("DE", "206", "", NAN)).sign_type, "stop");
  EXPECT_EQ(wg::classify_signal(signal("se", "c", "27", 1)).kind, wg::SignalKind::kUnknown);
  EXPECT_EQ(wg::classify_signal(signal("OpenDRIVE", "-1", "-1", NAN)).kind,
            wg::SignalKind::kUnknown);
  const auto arrow =
      wg::classify_signal(signal("OpenDRIVE", "-1", "-1", NAN, "SgRMArrowStraightRight.flt"));
  EXPECT_EQ(arrow.kind, wg::SignalKind::kArrow);
  EXPECT_EQ(arrow.sign_type, "straight_right");
  EXPECT_EQ(
      wg::classify_signal(signal("OpenDRIVE", "-1", "-1", NAN, "SgRMArrowLeft.flt")).sign_type,
      "left");
  EXPECT_EQ(wg::classify_signal(signal("DE", "297", "", NAN)).sign_type, "straight");
}
