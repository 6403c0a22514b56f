#include "render/frustum.h"

#include <gtest/gtest.h>

#include "render/renderer.h"

namespace convoy::render {
namespace {

// 90 degrees across, square: the side planes are x = +-(-z), y = +-(-z).
CameraSpec square90() { return CameraSpec{100, 100, 1.5707963267948966, 0.1, 50}; }

TEST(ViewFrustum, SpheresInsideOutsideAndOnEachPlane) {
  const ViewFrustum f(square90());
  EXPECT_FALSE(f.misses_sphere({0, 0, -10}, 1));     // straight ahead
  EXPECT_TRUE(f.misses_sphere({0, 0, 10}, 1));       // behind
  EXPECT_TRUE(f.misses_sphere({0, 0, -60}, 1));      // beyond the far plane
  EXPECT_FALSE(f.misses_sphere({0, 0, -50.5}, 1));   // touching it
  EXPECT_TRUE(f.misses_sphere({20, 0, -10}, 1));     // right of the right plane
  EXPECT_FALSE(f.misses_sphere({10.5, 0, -10}, 1));  // straddling it
  EXPECT_TRUE(f.misses_sphere({0, -20, -10}, 1));    // below
  EXPECT_TRUE(f.misses_sphere({-20, 0, -10}, 1));    // left
  EXPECT_TRUE(f.misses_sphere({0, 20, -10}, 1));     // above
}

TEST(ViewFrustum, ACapsuleIsInViewWhenItsSweepCrossesTheView) {
  const ViewFrustum f(square90());
  // A caster off to the right whose shadow falls across the view: kept.
  EXPECT_FALSE(f.misses_capsule({30, 0, -20}, {-30, 0, -20}, 1));
  // The same caster with its shadow falling further right: skipped.
  EXPECT_TRUE(f.misses_capsule({30, 0, -20}, {60, 0, -20}, 1));
  // Behind the camera, shadow falling further back: skipped; falling forward into view: kept.
  EXPECT_TRUE(f.misses_capsule({0, 0, 5}, {0, 0, 40}, 1));
  EXPECT_FALSE(f.misses_capsule({0, 0, 5}, {0, -5, -20}, 1));
}

TEST(ViewFrustum, ANearerFarPlane) {
  const ViewFrustum f(square90(), 20);
  EXPECT_TRUE(f.misses_sphere({0, 0, -30}, 1));
  EXPECT_FALSE(f.misses_sphere({0, 0, -15}, 1));
  EXPECT_DOUBLE_EQ(f.tan_x(), f.tan_y());
}

}  // namespace
}  // namespace convoy::render
