// The renderer's weather (Scene::set_atmosphere): Koschmieder fog, rain and snow over the image
// (deterministic per seed and time), wet and snowy ground.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "render/precipitation.h"
#include "render/renderer.h"
#include "shared_renderer.h"

namespace convoy::render {
namespace {

Material plain(float r, float g, float b) {
  Material m;
  m.diffuse = {r, g, b, 1};
  m.ambient = {r, g, b, 1};
  m.specular = {0, 0, 0, 1};
  return m;
}

double luminance(const Frame& f, int x, int y) {
  const uint8_t* p = &f.rgb[3 * (static_cast<size_t>(y) * f.width + x)];
  return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
}

// A black object at distance d in fog of visibility V keeps the contrast exp(-3.912 d / V)
// against the fog behind it (the background is the fog's colour, as the world engine sets it).
TEST(WeatherRenderTest, FogContrastFollowsKoschmieder) {
  Renderer* r = shared_renderer();
  ASSERT_NE(r, nullptr);
  for (auto [d, v] :
       {std::pair{20.0, 100.0}, {50.0, 100.0}, {30.0, 300.0}, {80.0, 200.0}, {10.0, 500.0}}) {
    Scene scene;
    Material black = plain(0, 0, 0);
    scene.add_instance(scene.add_mesh(make_box(1, 8, 8)), black, make_pose(d + 0.5, 0, 0));
    scene.add_light(Light{});
    Atmosphere a;
    a.visibility = static_cast<float>(v);
    a.fog_color = {0.8f, 0.8f, 0.8f, 1};
    scene.set_atmosphere(a);
    scene.set_background(a.fog_color);
    CameraSpec spec{64, 48, 0.2, 0.1, 500};
    Frame f;
    r->render(scene, make_pose(0, 0, 0), spec, &f, true, false);
    const double bg = 0.8 * 255;
    const double obj = luminance(f, 32, 24);
    const double distance = f.depth[24 * 64 + 32];  // the centre pixel: along the axis
    EXPECT_NEAR(distance, d, 0.05);
    const double contrast = (bg - obj) / bg;
    EXPECT_NEAR(contrast, std::exp(-3.912 * d / v), 0.05) << "d " << d << " V " << v;
    // At the visibility distance itself: 2 %.
    if (d == 20.0) {
      EXPECT_NEAR(std::exp(-3.912 * v / v), 0.02, 0.001);
    }
  }
}

Scene street(const Atmosphere& a) {
  Scene scene;
  scene.add_instance(scene.add_mesh(make_plane(200, 200)), plain(0.3f, 0.3f, 0.3f),
                     make_pose(0, 0, -1.5));
  scene.add_instance(scene.add_mesh(make_box(4, 2, 1.5)), plain(0.7f, 0.1f, 0.1f),
                     make_pose(15, 1, -0.75));
  Light sun;
  sun.direction = {-0.3f, 0.4f, -0.85f};
  scene.add_light(sun);
  scene.set_background({0.55f, 0.7f, 0.95f, 1});
  scene.set_atmosphere(a);
  return scene;
}

Frame render_street(const Atmosphere& a) {
  Scene scene = street(a);
  Frame f;
  shared_renderer()->render(scene, make_pose(0, 0, 0), CameraSpec{320, 240, 1.2, 0.1, 300}, &f,
                            true, true);
  return f;
}

int differing_pixels(const Frame& a, const Frame& b) {
  int n = 0;
  for (size_t i = 0; i < a.rgb.size(); i += 3)
    n += a.rgb[i] != b.rgb[i] || a.rgb[i + 1] != b.rgb[i + 1] || a.rgb[i + 2] != b.rgb[i + 2];
  return n;
}

TEST(WeatherRenderTest, RainAndSnowDifferFromClearAndRepeatForTheSameSeed) {
  ASSERT_NE(shared_renderer(), nullptr);
  const Frame clear = render_street(Atmosphere{});
  for (bool snow : {false, true}) {
    Atmosphere a;
    a.precipitation = 0.8f;
    a.snow = snow;
    a.seed = 5;
    a.time = 1.25;
    const Frame one = render_street(a), again = render_street(a);
    EXPECT_EQ(one.rgb, again.rgb) << (snow ? "snow" : "rain");
    EXPECT_GT(differing_pixels(one, clear), 100) << (snow ? "snow" : "rain");
    a.time = 1.30;  // the next frame: a new pattern
    EXPECT_GT(differing_pixels(render_street(a), one), 50);
    a.time = 1.25;
    a.seed = 6;
    EXPECT_GT(differing_pixels(render_street(a), one), 50);
    // Depth and ground truth are the scene's, not the weather's.
    EXPECT_EQ(one.depth, clear.depth);
    ASSERT_EQ(one.boxes.size(), clear.boxes.size());
  }
}

// The particles: none without precipitation, more with more, each overlapping the image, the
// same for the same seed and others for another.
TEST(WeatherRenderTest, PrecipitationParticlesFollowAmountAndSeed) {
  for (bool snow : {false, true}) {
    PrecipitationParams p;
    p.width = 736;
    p.height = 480;
    p.snow = snow;
    p.slant = 0.15f;
    p.seed = 9;
    std::vector<PrecipitationVertex> v;
    make_precipitation(p, &v);
    EXPECT_TRUE(v.empty());
    size_t last = 0;
    for (float amount : {0.2f, 0.5f, 1.0f}) {
      p.amount = amount;
      make_precipitation(p, &v);
      ASSERT_EQ(v.size() % 6, 0u);
      EXPECT_GT(v.size(), last + 60) << amount;  // at least 10 more particles
      last = v.size();
      for (size_t i = 0; i < v.size(); i += 6) {
        float x_min = 1e9f, x_max = -1e9f, y_min = 1e9f, y_max = -1e9f;
        for (size_t k = i; k < i + 6; ++k) {
          x_min = std::min(x_min, v[k].x), x_max = std::max(x_max, v[k].x);
          y_min = std::min(y_min, v[k].y), y_max = std::max(y_max, v[k].y);
        }
        ASSERT_TRUE(x_max >= 0 && x_min <= p.width && y_max >= 0 && y_min <= p.height) << i;
      }
    }
    std::vector<PrecipitationVertex> again, other;
    make_precipitation(p, &again);
    p.seed = 10;
    make_precipitation(p, &other);
    ASSERT_EQ(again.size(), v.size());
    EXPECT_EQ(0, std::memcmp(again.data(), v.data(), v.size() * sizeof(v[0])));
    EXPECT_TRUE(other.size() != v.size() ||
                std::memcmp(other.data(), v.data(), v.size() * sizeof(v[0])) != 0);
  }
}

TEST(WeatherRenderTest, WetGroundDarkensAndSnowWhitens) {
  ASSERT_NE(shared_renderer(), nullptr);
  const Frame clear = render_street(Atmosphere{});
  Atmosphere wet;
  wet.wetness = 1;
  Atmosphere snowy;
  snowy.snow_cover = 1;
  const Frame w = render_street(wet), s = render_street(snowy);
  // The ground just below the image centre, near the camera (steep view: little reflection).
  const int x = 160, y = 230;
  EXPECT_LT(luminance(w, x, y), 0.8 * luminance(clear, x, y));
  EXPECT_GT(luminance(s, x, y), 1.5 * luminance(clear, x, y));
}

TEST(WeatherRenderTest, GroundTruthBoxesGiveTheirDistance) {
  ASSERT_NE(shared_renderer(), nullptr);
  Scene scene;
  scene.add_instance(scene.add_mesh(make_box(1, 1, 1)), plain(1, 0, 0), make_pose(12, 0, 0), 3, 1);
  scene.add_light(Light{});
  Frame f;
  shared_renderer()->render(scene, make_pose(0, 0, 0), CameraSpec{64, 48, 1.0, 0.1, 100}, &f, false,
                            true);
  ASSERT_EQ(f.boxes.size(), 1u);
  EXPECT_NEAR(f.boxes[0].distance, 12.0, 1e-3);
}

}  // namespace
}  // namespace convoy::render
