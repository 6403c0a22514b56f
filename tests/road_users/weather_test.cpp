// Driving in the weather: IDM's v0, T, a and b on a wet or icy road and in fog, and the
// desired speed from them, the speed limit and the visibility.
#include "road_users/weather.h"

#include <gtest/gtest.h>

#include <cmath>

namespace convoy::road_users {
namespace {

const Idm kBase{.v0 = 20, .T = 1.5, .s0 = 2, .a = 1.5, .b = 2, .delta = 4};

TEST(AdaptToWeather, DryAndClearChangesNothing) {
  for (double mu : {0.8, 1.0}) {  // grippier than dry counts as dry
    const Driving d = adapt_to_weather(kBase, {mu, INFINITY});
    EXPECT_EQ(d.idm.v0, 20);
    EXPECT_EQ(d.idm.T, 1.5);
    EXPECT_EQ(d.idm.a, 1.5);
    EXPECT_EQ(d.idm.b, 2);
    EXPECT_EQ(d.idm.s0, 2);
    EXPECT_EQ(d.speed_factor, 1);
    EXPECT_EQ(d.visibility_speed, INFINITY);
  }
}

TEST(AdaptToWeather, WetRoad) {
  // mu 0.5: loss 0.375; speed x 0.85, T x 1.1875; grip 0.5 x 0.5 x 9.81 = 2.4525 caps neither.
  const Driving d = adapt_to_weather(kBase, {0.5, INFINITY});
  EXPECT_NEAR(d.speed_factor, 0.85, 1e-12);
  EXPECT_NEAR(d.idm.v0, 17, 1e-12);
  EXPECT_NEAR(d.idm.T, 1.78125, 1e-12);
  EXPECT_EQ(d.idm.a, 1.5);
  EXPECT_EQ(d.idm.b, 2);
  EXPECT_EQ(d.idm.s0, 2);
  EXPECT_EQ(d.idm.delta, 4);
}

TEST(AdaptToWeather, IcyRoad) {
  // mu 0.1: loss 0.875; speed x 0.65, T x 1.4375; a and b at most 0.05 x 9.81 = 0.4905.
  const Driving d = adapt_to_weather(kBase, {0.1, INFINITY});
  EXPECT_NEAR(d.idm.v0, 13, 1e-12);
  EXPECT_NEAR(d.idm.T, 2.15625, 1e-12);
  EXPECT_NEAR(d.idm.a, 0.4905, 1e-12);
  EXPECT_NEAR(d.idm.b, 0.4905, 1e-12);
  // Almost no grip: never under 0.3 m/s^2.
  EXPECT_EQ(adapt_to_weather(kBase, {0.02, INFINITY}).idm.b, 0.3);
}

TEST(AdaptToWeather, FogLengthensTheHeadwayAndCapsTheSpeed) {
  // 60 m: T x 1.3 (the full 30 % below 100 m); stopping within 60 m at grip 3.924 m/s^2 after
  // 1.5 s: v = 3.924 (-1.5 + sqrt(2.25 + 120 / 3.924)) = 16.5979 m/s.
  const Driving fog = adapt_to_weather(kBase, {0.8, 60});
  EXPECT_NEAR(fog.idm.T, 1.95, 1e-12);
  EXPECT_NEAR(fog.visibility_speed, 16.5978830276, 1e-9);
  EXPECT_EQ(fog.idm.v0, 20);
  // 550 m: T x 1.15; the cap is 60.08 m/s.
  const Driving mist = adapt_to_weather(kBase, {0.8, 550});
  EXPECT_NEAR(mist.idm.T, 1.725, 1e-12);
  EXPECT_NEAR(mist.visibility_speed, 60.0764514099, 1e-9);
  // 1000 m and more: no fog.
  EXPECT_EQ(adapt_to_weather(kBase, {0.8, 1000}).visibility_speed, INFINITY);
}

TEST(DesiredSpeed, V0OrTheLimitTimesItsFactorsCappedByTheVisibility) {
  const Driving ice = adapt_to_weather(kBase, {0.1, INFINITY});
  EXPECT_NEAR(desired_speed(ice, 1.0, std::nullopt), 13, 1e-12);  // no limit known: v0
  EXPECT_NEAR(desired_speed(ice, 0.0, 50 / 3.6), 13, 1e-12);      // limits not followed
  EXPECT_NEAR(desired_speed(ice, 1.0, INFINITY), 13, 1e-12);      // no limit there
  // 50 km/h x 0.65.
  EXPECT_NEAR(desired_speed(ice, 1.0, 50 / 3.6), 9.0277777778, 1e-9);
  EXPECT_NEAR(desired_speed(ice, 1.2, 50 / 3.6), 1.2 * 9.0277777778, 1e-9);
  // Fog of 60 m caps a 30 m/s limit, and v0.
  const Driving fog = adapt_to_weather(kBase, {0.8, 60});
  EXPECT_NEAR(desired_speed(fog, 1.0, 30), 16.5978830276, 1e-9);
  EXPECT_NEAR(desired_speed(fog, 1.0, std::nullopt), 16.5978830276, 1e-9);
  EXPECT_EQ(desired_speed(Driving{kBase}, 1.0, 10), 10);
}

}  // namespace
}  // namespace convoy::road_users
