// Renderer tests: geometry against the pinhole model, depth, lighting, ground-truth boxes,
// determinism and a golden image. They need an OpenGL ES 3 context; where EGL cannot start
// they fail with its message rather than skip.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <limits>
#include <memory>
#include <numbers>
#include <string>

#include "render/image_io.h"
#include "render/renderer.h"
#include "shared_renderer.h"

namespace convoy::render {
namespace {

#define GET_RENDERER(r)            \
  Renderer* r = shared_renderer(); \
  ASSERT_NE(r, nullptr)

Material plain(float r, float g, float b) {
  Material m;
  m.diffuse = {r, g, b, 1};
  m.ambient = {r, g, b, 1};
  m.specular = {0, 0, 0, 1};
  return m;
}

struct Rect {
  int x_min = std::numeric_limits<int>::max(), y_min = std::numeric_limits<int>::max();
  int x_max = -1, y_max = -1;
  int count = 0;
};

// Bounding rectangle of the pixels for which `pick(r, g, b)` holds.
template <typename Pick>
Rect find_pixels(const Frame& f, Pick pick) {
  Rect r;
  for (int y = 0; y < f.height; ++y) {
    for (int x = 0; x < f.width; ++x) {
      const uint8_t* p = &f.rgb[3 * (static_cast<size_t>(y) * f.width + x)];
      if (!pick(p[0], p[1], p[2])) continue;
      r.x_min = std::min(r.x_min, x);
      r.x_max = std::max(r.x_max, x);
      r.y_min = std::min(r.y_min, y);
      r.y_max = std::max(r.y_max, y);
      ++r.count;
    }
  }
  return r;
}

// Pixels (column, row) of the point (X forward, Y left, Z up) in the camera frame.
std::array<double, 2> project(const CameraSpec& s, double x, double y, double z) {
  const double f = (s.width / 2.0) / std::tan(s.hfov / 2);
  return {s.width / 2.0 - f * y / x, s.height / 2.0 - f * z / x};
}

// The pixel rectangle a box's silhouette covers: pixels whose centre lies inside the hull of
// the projected corners' bounding rectangle (camera at the origin looking along +X).
Rect predicted_box(const CameraSpec& s, double cx, double cy, double cz, double half) {
  double u0 = 1e9, u1 = -1e9, v0 = 1e9, v1 = -1e9;
  for (int i = 0; i < 8; ++i) {
    const auto p = project(s, cx + (i & 1 ? half : -half), cy + (i & 2 ? half : -half),
                           cz + (i & 4 ? half : -half));
    u0 = std::min(u0, p[0]), u1 = std::max(u1, p[0]);
    v0 = std::min(v0, p[1]), v1 = std::max(v1, p[1]);
  }
  Rect r;
  r.x_min = static_cast<int>(std::ceil(u0 - 0.5));
  r.x_max = static_cast<int>(std::floor(u1 - 0.5));
  r.y_min = static_cast<int>(std::ceil(v0 - 0.5));
  r.y_max = static_cast<int>(std::floor(v1 - 0.5));
  return r;
}

void expect_near_rect(const Rect& a, int x_min, int y_min, int x_max, int y_max,
                      const std::string& what) {
  EXPECT_NEAR(a.x_min, x_min, 1) << what;
  EXPECT_NEAR(a.y_min, y_min, 1) << what;
  EXPECT_NEAR(a.x_max, x_max, 1) << what;
  EXPECT_NEAR(a.y_max, y_max, 1) << what;
}

TEST(RenderTest, BoxLandsWherePinholePredicts) {
  GET_RENDERER(renderer);
  const CameraSpec spec{320, 240, 1.2, 0.1, 100};
  const double cx = 5, cy = 1, cz = 0.5;  // left of and above the optical axis
  Scene scene;
  scene.set_background({0, 0, 0.3f, 1});
  scene.add_light(Light{});
  scene.add_instance(scene.add_mesh(make_box(1, 1, 1)), plain(1, 0, 0), make_pose(cx, cy, cz), 7,
                     3);
  Frame f;
  renderer->render(scene, identity_pose(), spec, &f, true, true);
  ASSERT_EQ(f.width, 320);
  ASSERT_EQ(f.rgb.size(), 320u * 240 * 3);

  const Rect want = predicted_box(spec, cx, cy, cz, 0.5);
  EXPECT_LT(want.x_max, spec.width / 2);   // +Y is the image's left
  EXPECT_LT(want.y_max, spec.height / 2);  // +Z is up
  const Rect seen = find_pixels(f, [](int r, int, int) { return r > 40; });
  expect_near_rect(seen, want.x_min, want.y_min, want.x_max, want.y_max, "from colour");
  ASSERT_EQ(f.boxes.size(), 1u);
  const BoundingBox& b = f.boxes[0];
  EXPECT_EQ(b.model_id, 7u);
  EXPECT_EQ(b.class_id, 3u);
  expect_near_rect(Rect{b.x_min, b.y_min, b.x_max, b.y_max}, want.x_min, want.y_min, want.x_max,
                   want.y_max, "ground-truth box");
  EXPECT_EQ(static_cast<int>(b.pixel_count), seen.count);

  // A camera turned to look along +Y (yaw 90 degrees) sees a box on +Y centred.
  Scene turned;
  turned.add_light(Light{});
  turned.add_instance(turned.add_mesh(make_box(1, 1, 1)), plain(1, 0, 0), make_pose(0, 5, 0), 1);
  renderer->render(turned, make_pose(0, 0, 0, 0, 0, std::numbers::pi / 2), spec, &f, false, true);
  ASSERT_EQ(f.boxes.size(), 1u);
  EXPECT_NEAR((f.boxes[0].x_min + f.boxes[0].x_max) / 2.0, spec.width / 2.0 - 0.5, 1.0);
  EXPECT_NEAR((f.boxes[0].y_min + f.boxes[0].y_max) / 2.0, spec.height / 2.0 - 0.5, 1.0);
}

TEST(RenderTest, DepthIsDistanceAlongOpticalAxis) {
  GET_RENDERER(renderer);
  const CameraSpec spec{160, 120, 1.0, 0.1, 50};
  Scene scene;
  scene.add_light(Light{});
  scene.add_instance(scene.add_mesh(make_box(1, 2, 2)), Material{}, make_pose(5, 0, 0));
  // A camera 1 m behind the origin and 0.3 m up: the face at x = 4.5 is 5.5 m ahead.
  Frame f;
  renderer->render(scene, make_pose(-1, 0, 0.3), spec, &f, true, false);
  ASSERT_EQ(f.depth.size(), 160u * 120);
  EXPECT_NEAR(f.depth[60 * 160 + 80], 5.5, 0.01);
  EXPECT_NEAR(f.depth[50 * 160 + 70], 5.5, 0.01);  // off axis: still along the axis
  EXPECT_TRUE(std::isinf(f.depth[0]));             // nothing there
  EXPECT_TRUE(f.boxes.empty());
}

TEST(RenderTest, SphereIsBrighterOnTheLitSide) {
  GET_RENDERER(renderer);
  const CameraSpec spec{200, 200, 0.8, 0.1, 100};
  Scene scene;
  scene.set_ambient({0.1f, 0.1f, 0.1f, 1});
  scene.set_background({0, 0, 0, 1});
  Light sun;
  sun.direction = {0, -1, 0};  // shining from +Y (the image's left) towards -Y
  scene.add_light(sun);
  scene.add_instance(scene.add_mesh(make_sphere(1)), plain(0.8f, 0.8f, 0.8f), make_pose(6, 0, 0));
  Frame f;
  renderer->render(scene, identity_pose(), spec, &f);
  double left = 0, right = 0;
  for (int y = 0; y < f.height; ++y) {
    for (int x = 0; x < f.width; ++x) {
      (x < f.width / 2 ? left : right) += f.rgb[3 * (y * f.width + x)];
    }
  }
  EXPECT_GT(left, 3 * right);
}

// Sun shadows (Scene::set_shadows): a box floating 1 m above the ground, the sun at 45 degrees
// from behind the camera, shades the ground 1-2 m beyond it; off, the ground is lit alike.
// A sun from the -x side, a grey ground 1.5 m below the camera and a red box 6 m ahead;
// returns the box's instance.
int sun_ground_and_box(Scene& scene) {
  scene.set_ambient({0.2f, 0.2f, 0.2f, 1});
  Light sun;
  sun.direction = {1, 0, -1};
  scene.add_light(sun);
  scene.add_instance(scene.add_mesh(make_plane(80, 80)), plain(0.8f, 0.8f, 0.8f),
                     make_pose(0, 0, -1.5));
  return scene.add_instance(scene.add_mesh(make_box(1, 1, 1)), plain(0.8f, 0.2f, 0.2f),
                            make_pose(6, 0, 0));
}

TEST(RenderTest, TheSunCastsShadowsWhereAsked) {
  GET_RENDERER(renderer);
  const CameraSpec spec{320, 240, 1.2, 0.1, 100};
  Scene scene;
  sun_ground_and_box(scene);
  auto grey = [&](const Frame& f, double x, double y, double z) {
    const auto uv = project(spec, x, y, z);
    const uint8_t* p = &f.rgb[3 * (static_cast<int>(uv[1]) * f.width + static_cast<int>(uv[0]))];
    return (p[0] + p[1] + p[2]) / 3.0;
  };
  Frame off, on;
  renderer->render(scene, identity_pose(), spec, &off);
  Shadows shadows;
  shadows.enabled = true;
  scene.set_shadows(shadows);
  renderer->render(scene, identity_pose(), spec, &on);
  // In the shadow (x 6.5..8.5, y -0.5..0.5 on the ground) and beside it.
  EXPECT_LT(grey(on, 7.5, 0, -1.5), 0.5 * grey(on, 7.5, 2, -1.5));
  EXPECT_NEAR(grey(off, 7.5, 0, -1.5), grey(off, 7.5, 2, -1.5), 6);
  // Lit ground and the lit box keep their colour; only the shadow changed.
  EXPECT_NEAR(grey(on, 7.5, 2, -1.5), grey(off, 7.5, 2, -1.5), 2);
  EXPECT_NEAR(grey(on, 4, 0, -1.5), grey(off, 4, 0, -1.5), 2);
  // No sun above the horizon, no shadows.
  scene.clear_lights();
  Light evening;
  evening.direction = {1, 0, -0.01f};
  scene.add_light(evening);
  Frame dusk_on, dusk_off;
  renderer->render(scene, identity_pose(), spec, &dusk_on);
  scene.set_shadows(Shadows{});
  renderer->render(scene, identity_pose(), spec, &dusk_off);
  EXPECT_EQ(dusk_on.rgb, dusk_off.rgb);
}

TEST(RenderTest, AnInstanceThatCastsNoShadowLeavesNone) {
  GET_RENDERER(renderer);
  const CameraSpec spec{320, 240, 1.2, 0.1, 100};
  Scene scene;
  const int box = sun_ground_and_box(scene);
  Shadows shadows;
  shadows.enabled = true;
  scene.set_shadows(shadows);
  Frame with, without;
  renderer->render(scene, identity_pose(), spec, &with);
  scene.set_casts_shadows(box, false);  // SDF <cast_shadows>false</cast_shadows>
  renderer->render(scene, identity_pose(), spec, &without);
  const auto uv = project(spec, 7.5, 0, -1.5);  // in the box's shadow
  const size_t at = 3 * (static_cast<size_t>(uv[1]) * with.width + static_cast<size_t>(uv[0]));
  EXPECT_LT(with.rgb[at], 0.5 * without.rgb[at]);
  scene.set_shadows(Shadows{});
  Frame off;
  renderer->render(scene, identity_pose(), spec, &off);
  EXPECT_NEAR(without.rgb[at], off.rgb[at], 2);  // lit as without shadows at all
}

TEST(RenderTest, ACasterOutOfViewShadowsWhatIsInView) {
  // A tower off to the left, outside the view, with the sun behind it: its shadow falls
  // across the ground in front of the camera, and must be there although the tower is not.
  GET_RENDERER(renderer);
  const CameraSpec spec{320, 240, 1.2, 0.1, 100};
  Scene scene;
  scene.set_ambient({0.2f, 0.2f, 0.2f, 1});
  Light sun;
  sun.direction = {0, -2, -1};  // 27 degrees up: a shadow twice as long as the tower is high
  scene.add_light(sun);
  scene.add_instance(scene.add_mesh(make_plane(80, 80)), plain(0.8f, 0.8f, 0.8f),
                     make_pose(0, 0, -1.5));
  scene.add_instance(scene.add_mesh(make_box(2, 2, 10)), plain(0.8f, 0.2f, 0.2f),
                     make_pose(8, 20, 3.5));
  const auto tower = project(spec, 8, 19, 3.5);
  ASSERT_TRUE(tower[0] < 0 || tower[0] >= spec.width || tower[1] < 0 || tower[1] >= spec.height);
  Shadows shadows;
  shadows.enabled = true;
  scene.set_shadows(shadows);
  Frame on;
  renderer->render(scene, identity_pose(), spec, &on);
  auto grey = [&](double x, double y) {
    const auto uv = project(spec, x, y, -1.5);
    const uint8_t* p = &on.rgb[3 * (static_cast<int>(uv[1]) * on.width + static_cast<int>(uv[0]))];
    return (p[0] + p[1] + p[2]) / 3.0;
  };
  EXPECT_LT(grey(8, 0), 0.5 * grey(4, 0));  // in the tower's shadow, and lit ground nearer
}

TEST(RenderTest, PointAndSpotLightsFadeWithDistanceAndCone) {
  GET_RENDERER(renderer);
  const CameraSpec spec{200, 150, 1.2, 0.1, 100};
  Scene scene;
  scene.set_ambient({0, 0, 0, 1});
  // A white floor 2 m below the camera.
  scene.add_instance(scene.add_mesh(make_plane(60, 60)), plain(1, 1, 1), make_pose(0, 0, -2));
  Frame f;
  auto red_at = [&](double x) {  // the floor's red on the optical axis' vertical plane
    const auto p = project(spec, x, 0, -2);
    return int(f.rgb[3 * (int(p[1]) * spec.width + int(p[0]))]);
  };

  Light spot;
  spot.type = Light::kSpot;
  spot.position = {8, 0, 1};
  spot.direction = {0, 0, -1};
  spot.spot_inner_angle = 0.3f;
  spot.spot_outer_angle = 0.5f;  // a disc of radius 3 tan(0.25) = 0.77 m on the floor
  spot.range = 20;
  spot.attenuation_linear = 0;
  scene.add_light(spot);
  renderer->render(scene, identity_pose(), spec, &f);
  EXPECT_GT(red_at(8), 200);
  EXPECT_EQ(red_at(6.5), 0);
  EXPECT_EQ(red_at(10), 0);

  scene.clear_lights();
  Light bulb;
  bulb.type = Light::kPoint;
  bulb.position = {6, 0, -1};
  bulb.attenuation_linear = 0.5f;
  bulb.range = 30;
  scene.add_light(bulb);
  renderer->render(scene, identity_pose(), spec, &f);
  EXPECT_GT(red_at(6), 150);  // 1 m away, straight above: 1 / (1 + 0.5)
  EXPECT_GT(red_at(6), 4 * red_at(14));
  EXPECT_GT(red_at(14), 0);
  bulb.range = 5;  // beyond its range a light gives nothing
  scene.clear_lights();
  scene.add_light(bulb);
  renderer->render(scene, identity_pose(), spec, &f);
  EXPECT_EQ(red_at(14), 0);
}

TEST(RenderTest, BackgroundWhereNothingIs) {
  GET_RENDERER(renderer);
  Scene scene;
  scene.set_background({0.2f, 0.4f, 0.6f, 1});
  scene.add_instance(scene.add_mesh(make_box(1, 1, 1)), Material{}, make_pose(-5, 0, 0));  // behind
  Frame f;
  renderer->render(scene, identity_pose(), CameraSpec{64, 48, 1.0, 0.1, 10}, &f, true, true);
  for (size_t i = 0; i < f.rgb.size(); i += 3) {
    ASSERT_EQ(f.rgb[i], 51);
    ASSERT_EQ(f.rgb[i + 1], 102);
    ASSERT_EQ(f.rgb[i + 2], 153);
  }
  EXPECT_TRUE(std::all_of(f.depth.begin(), f.depth.end(), [](float d) { return std::isinf(d); }));
  EXPECT_TRUE(f.boxes.empty());
}

TEST(RenderTest, TheSkyGoesFromTheHorizonToTheZenithBehindTheScene) {
  GET_RENDERER(renderer);
  const CameraSpec spec{160, 120, 1.2, 0.1, 100};
  Scene scene;
  scene.set_background({0.55f, 0.7f, 0.9f, 1});
  const Sky sky = Sky::from_background(scene.background());
  scene.set_sky(sky);
  // The ground, 1.5 m below the camera, and a box in front: neither may change.
  scene.add_instance(scene.add_mesh(make_plane(400, 400)), plain(0.3f, 0.3f, 0.3f),
                     make_pose(0, 0, -1.5));
  scene.add_instance(scene.add_mesh(make_box(1, 1, 1)), plain(0.8f, 0.2f, 0.2f), make_pose(6, 0, 0),
                     1, 1);
  // Looking up 0.4 rad: the top rows see higher elevations than the rows near the horizon.
  const Pose up = make_pose(0, 0, 0, 0, -0.4, 0);
  Frame with, without;
  renderer->render(scene, up, spec, &with, true, true);
  Scene plain_sky;
  plain_sky = std::move(scene);
  plain_sky.set_sky(Sky{});
  renderer->render(plain_sky, up, spec, &without, true, true);
  auto blue = [&](const Frame& f, int row) { return f.rgb[3 * (row * f.width + 2) + 2]; };
  auto red = [&](const Frame& f, int row) { return f.rgb[3 * (row * f.width + 2)]; };
  // Without a gradient the background everywhere; with it, the zenith deeper than the horizon.
  EXPECT_EQ(blue(without, 0), 230);
  EXPECT_EQ(blue(without, 105), 230);
  EXPECT_LT(red(with, 0), red(with, 105));  // row 105: 2 degrees above the horizon
  EXPECT_GT(red(with, 105), 150);           // paler near the horizon than the background (140)
  EXPECT_NEAR(red(with, 0), 255 * (0.55 + (sky.zenith[0] - 0.55) * 0.75), 30);
  // The sky draws only where nothing is: depth, ids, boxes and the models' pixels are the same.
  EXPECT_EQ(with.depth, without.depth);
  ASSERT_EQ(with.boxes.size(), 1u);
  ASSERT_EQ(without.boxes.size(), 1u);
  EXPECT_EQ(with.boxes[0].pixel_count, without.boxes[0].pixel_count);
  size_t differ = 0;
  for (size_t p = 0; p < with.depth.size(); ++p) {
    const bool sky_pixel = std::isinf(with.depth[p]);
    const bool same = std::equal(&with.rgb[3 * p], &with.rgb[3 * p] + 3, &without.rgb[3 * p]);
    if (!sky_pixel) {
      EXPECT_TRUE(same) << "pixel " << p;
    }
    differ += sky_pixel && !same;
  }
  EXPECT_GT(differ, with.depth.size() / 4);
}

TEST(RenderTest, BoxesCountVisiblePixelsOnly) {
  GET_RENDERER(renderer);
  const CameraSpec spec{320, 240, 1.0, 0.1, 100};
  Scene scene;
  scene.set_background({0, 0, 0, 1});
  scene.set_ambient({1, 1, 1, 1});
  const int box = scene.add_mesh(make_box(1, 1, 1));
  scene.add_instance(box, plain(1, 0, 0), make_pose(6, 0, 0), 1, 10);  // red, far
  // Green, nearer, covering the far box's right half (-Y is the image's right).
  const int near =
      scene.add_instance(box, plain(0, 1, 0), with_scale(make_pose(4, -0.6, 0), 1, 1, 2), 2, 20);
  const int hidden = scene.add_instance(box, plain(0, 0, 1), make_pose(6, 2, 0), 3, 30);
  scene.set_visible(hidden, false);
  scene.add_instance(box, plain(1, 1, 1), make_pose(30, 0, 0), 0, 0);  // unlabelled, behind both
  // A second part of model 2, apart from the first: one merged box.
  scene.add_instance(box, plain(0, 1, 0), make_pose(4, -0.6, 1.6), 2, 21);

  Frame f;
  renderer->render(scene, identity_pose(), spec, &f, false, true);
  ASSERT_EQ(f.boxes.size(), 2u);
  const BoundingBox far_box = f.boxes[0];
  const BoundingBox near_box = f.boxes[1];
  EXPECT_EQ(far_box.model_id, 1u);
  EXPECT_EQ(near_box.model_id, 2u);
  EXPECT_EQ(near_box.class_id, 20u);  // the first instance's

  const Rect red = find_pixels(f, [](int r, int g, int b) { return r > 128 && g < 128; });
  const Rect green = find_pixels(f, [](int r, int g, int b) { return g > 128 && r < 128; });
  EXPECT_EQ(far_box.x_min, red.x_min);
  EXPECT_EQ(far_box.x_max, red.x_max);
  EXPECT_EQ(far_box.y_min, red.y_min);
  EXPECT_EQ(far_box.y_max, red.y_max);
  EXPECT_EQ(static_cast<int>(far_box.pixel_count), red.count);
  EXPECT_EQ(static_cast<int>(near_box.pixel_count), green.count);
  EXPECT_EQ(near_box.y_min, green.y_min);

  // Without the occluder the far box is wider to the right and has more pixels.
  scene.set_visible(near, false);
  renderer->render(scene, identity_pose(), spec, &f, false, true);
  ASSERT_GE(f.boxes.size(), 1u);
  EXPECT_EQ(f.boxes[0].model_id, 1u);
  EXPECT_EQ(f.boxes[0].x_min, far_box.x_min);
  EXPECT_GT(f.boxes[0].x_max, far_box.x_max + 10);
  EXPECT_GT(f.boxes[0].pixel_count, far_box.pixel_count);
}

Scene golden_scene() {
  Scene scene;
  scene.set_background({0.55f, 0.7f, 0.9f, 1});
  scene.set_ambient({0.3f, 0.3f, 0.3f, 1});
  Light sun;
  sun.direction = {-0.4f, 0.3f, -0.85f};
  sun.diffuse = {0.9f, 0.9f, 0.85f, 1};
  scene.add_light(sun);
  Light lamp;
  lamp.type = Light::kPoint;
  lamp.position = {3, -1.5f, 1.5f};
  lamp.diffuse = {0.8f, 0.5f, 0.2f, 1};
  lamp.attenuation_linear = 0.3f;
  scene.add_light(lamp);
  uint8_t checker[8 * 8 * 4];
  for (int i = 0; i < 64; ++i) {
    const uint8_t v = ((i % 8) / 2 + (i / 16)) % 2 ? 230 : 40;
    checker[4 * i] = v, checker[4 * i + 1] = v, checker[4 * i + 2] = 255 - v / 2;
    checker[4 * i + 3] = 255;
  }
  Material floor = plain(0.5f, 0.6f, 0.5f);
  scene.add_instance(scene.add_mesh(make_plane(30, 30)), floor, identity_pose());
  Material crate = plain(1, 1, 1);
  crate.texture = scene.add_texture(checker, 8, 8);
  scene.add_instance(scene.add_mesh(make_box(1, 1, 1)), crate, make_pose(5, 1, 0.5, 0, 0, 0.4), 1);
  Material ball = plain(0.9f, 0.2f, 0.1f);
  ball.specular = {0.8f, 0.8f, 0.8f, 1};
  scene.add_instance(scene.add_mesh(make_sphere(0.6f)), ball, make_pose(4, -1, 0.6), 2);
  scene.add_instance(scene.add_mesh(make_cylinder(0.3f, 1.5f)), plain(0.2f, 0.3f, 0.9f),
                     make_pose(7, -0.2f, 0.75f, 0.3, 0, 0), 3);
  return scene;
}

TEST(RenderTest, RendersAreDeterministic) {
  GET_RENDERER(renderer);
  Scene scene = golden_scene();
  const CameraSpec spec{320, 240, 1.2, 0.1, 100};
  const Pose camera = make_pose(0, 0, 1.2, 0, 0.1, 0);
  Frame a, b, other;
  renderer->render(scene, camera, spec, &a, true, true);
  renderer->render(golden_scene(), camera, CameraSpec{100, 80, 1, 0.1, 10}, &other, true, true);
  renderer->render(scene, camera, spec, &b, true, true);
  EXPECT_EQ(a.rgb, b.rgb);
  ASSERT_EQ(a.depth.size(), b.depth.size());
  EXPECT_EQ(0, std::memcmp(a.depth.data(), b.depth.data(), a.depth.size() * sizeof(float)));
  ASSERT_EQ(a.boxes.size(), b.boxes.size());
  EXPECT_EQ(0, std::memcmp(a.boxes.data(), b.boxes.data(), a.boxes.size() * sizeof(BoundingBox)));
}

TEST(RenderTest, MatchesGoldenImage) {
  GET_RENDERER(renderer);
  const std::string path = std::string(CONVOY_RENDER_TEST_DIR) + "/golden_scene.ppm";
  Frame f;
  renderer->render(golden_scene(), make_pose(0, 0, 1.2, 0, 0.1, 0),
                   CameraSpec{160, 120, 1.2, 0.1, 100}, &f);
  const char* update = std::getenv("CONVOY_UPDATE_GOLDEN");
  if (update && std::string(update) == "1") {
    write_ppm(path, f.width, f.height, f.rgb.data());
    std::cout << "wrote " << path << "\n";
  }
  ASSERT_TRUE(std::filesystem::exists(path))
      << path << " is missing; run with CONVOY_UPDATE_GOLDEN=1 to write it";
  const Image golden = read_ppm(path);
  ASSERT_EQ(golden.width, f.width);
  ASSERT_EQ(golden.height, f.height);
  double sum[3] = {0, 0, 0};
  int max_diff = 0;
  for (size_t i = 0; i < f.rgb.size(); ++i) {
    const int d = std::abs(int(f.rgb[i]) - int(golden.data[i]));
    sum[i % 3] += d;
    max_diff = std::max(max_diff, d);
  }
  const double pixels = f.width * f.height;
  for (int c = 0; c < 3; ++c) EXPECT_LT(sum[c] / pixels, 1.0) << "channel " << c;
  EXPECT_LT(max_diff, 32);
}

TEST(RenderTest, TextureAppearsUpright) {
  GET_RENDERER(renderer);
  // 2x2 texture, rows top first: red green / blue white.
  const uint8_t texels[16] = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255};
  Scene scene;
  scene.set_ambient({1, 1, 1, 1});
  Material m = plain(0, 0, 0);
  m.ambient = {1, 1, 1, 1};
  m.texture = scene.add_texture(texels, 2, 2);
  // The plane faces the camera: its x to the image's right (-Y), its y up (+Z).
  const Pose facing = {0, -1, 0, 0, 0, 0, 1, 0, -1, 0, 0, 0, 2, 0, 0, 1};
  scene.add_instance(scene.add_mesh(make_plane(1, 1)), m, facing);
  const CameraSpec spec{200, 200, 1.0, 0.1, 10};
  Frame f;
  renderer->render(scene, identity_pose(), spec, &f);
  // Samples at the quadrants' centres; bilinear filtering blends in a little of the others.
  auto expect_colour = [&](double y, double z, std::array<int, 3> want, const char* where) {
    const auto p = project(spec, 2, y, z);
    const uint8_t* px = &f.rgb[3 * (int(p[1]) * spec.width + int(p[0]))];
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(px[c], want[c], 8) << where << " channel " << c;
  };
  expect_colour(0.25, 0.25, {255, 0, 0}, "top left");
  expect_colour(-0.25, 0.25, {0, 255, 0}, "top right");
  expect_colour(0.25, -0.25, {0, 0, 255}, "bottom left");
  expect_colour(-0.25, -0.25, {255, 255, 255}, "bottom right");
}

// Scene::set_material changes how an instance looks from the next frame (the world engine's
// traffic lights switch their lamps so), and a textured emissive colour glows through the
// texture: a lit picture, dark where the texture is dark.
TEST(RenderTest, AnInstancesMaterialChangesAndItsEmissiveCanBeTextured) {
  GET_RENDERER(renderer);
  // 2x2 texture, rows top first: white black / black white.
  const uint8_t texels[16] = {255, 255, 255, 255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255, 255};
  Scene scene;
  scene.set_ambient({0, 0, 0, 1});
  scene.set_background({0, 0, 0, 1});
  Material dark = plain(0.05f, 0.05f, 0.05f);
  dark.texture = scene.add_texture(texels, 2, 2);
  const Pose facing = {0, -1, 0, 0, 0, 0, 1, 0, -1, 0, 0, 0, 2, 0, 0, 1};
  const int lamp = scene.add_instance(scene.add_mesh(make_plane(1, 1)), dark, facing);
  const CameraSpec spec{200, 200, 1.0, 0.1, 10};
  auto red_at = [&](const Frame& f, double y, double z) {
    const auto p = project(spec, 2, y, z);
    return int(f.rgb[3 * (int(p[1]) * spec.width + int(p[0]))]);
  };
  Frame before, lit, pictured;
  renderer->render(scene, identity_pose(), spec, &before);
  EXPECT_LT(red_at(before, 0.25, 0.25), 20);  // no light: dark
  Material glowing = dark;
  glowing.emissive = {1, 0.1f, 0.05f, 1};
  scene.set_material(lamp, glowing);
  renderer->render(scene, identity_pose(), spec, &lit);
  EXPECT_EQ(red_at(lit, 0.25, 0.25), 255);  // emissive as is: over white and black texels
  EXPECT_EQ(red_at(lit, -0.25, 0.25), 255);
  glowing.textured_emissive = true;
  scene.set_material(lamp, glowing);
  renderer->render(scene, identity_pose(), spec, &pictured);
  EXPECT_GT(red_at(pictured, 0.25, 0.25), 240);  // the white texel glows
  EXPECT_LT(red_at(pictured, -0.25, 0.25), 20);  // the black one stays dark
  // Lit per vertex (far away, small on screen) the same.
  Scene far;
  far.set_ambient({0, 0, 0, 1});
  far.set_background({0, 0, 0, 1});
  far.add_light(Light{});
  Material m = glowing;
  m.texture = far.add_texture(texels, 2, 2);
  const Pose away = {0, -1, 0, 0, 0, 0, 1, 0, -1, 0, 0, 0, 40, 0, 0, 1};
  far.add_instance(far.add_mesh(make_sphere(4.0f, 16, 32)), m, away);
  Frame small;
  renderer->render(far, identity_pose(), CameraSpec{200, 200, 1.0, 0.1, 100}, &small);
  EXPECT_GT(renderer->last_stats().per_vertex_lit, 0);
  int bright = 0, dim = 0;
  for (size_t i = 0; i < small.rgb.size(); i += 3) {
    if (small.rgb[i] > 200) ++bright;
    if (small.rgb[i] > 0 && small.rgb[i] < 60) ++dim;
  }
  EXPECT_GT(bright, 20);
  EXPECT_GT(dim, 20);
}

TEST(RenderTest, PerVertexLightingLooksLikePerPixel) {
  GET_RENDERER(renderer);
  // Finely tessellated spheres far enough away that their triangles cover a pixel or two.
  Scene scene;
  scene.set_background({0, 0, 0, 1});
  Light sun;
  sun.direction = {0.3f, -0.6f, -0.7f};
  scene.add_light(sun);
  Light bulb;
  bulb.type = Light::kPoint;
  bulb.position = {6, 2, 2};
  bulb.specular = {0.5f, 0.5f, 0.5f, 1};
  scene.add_light(bulb);
  Material shiny = plain(0.2f, 0.5f, 0.9f);
  shiny.specular = {0.6f, 0.6f, 0.6f, 1};
  const int sphere = scene.add_mesh(make_sphere(0.5f, 24, 48));
  for (int i = 0; i < 5; ++i) scene.add_instance(sphere, shiny, make_pose(10, 2.0 - i, 0));
  const CameraSpec spec{320, 240, 1.0, 0.1, 100};
  Frame per_vertex, per_pixel;
  renderer->render(scene, identity_pose(), spec, &per_vertex);
  EXPECT_EQ(renderer->last_stats().per_vertex_lit, 5);
  renderer->set_per_vertex_lighting_below(0);
  renderer->render(scene, identity_pose(), spec, &per_pixel);
  renderer->set_per_vertex_lighting_below(Renderer::kPerVertexLightingBelow);
  EXPECT_EQ(renderer->last_stats().per_vertex_lit, 0);
  double sum = 0;
  int covered = 0;
  for (size_t i = 0; i < per_pixel.rgb.size(); ++i) {
    if (per_pixel.rgb[i] == 0 && per_vertex.rgb[i] == 0) continue;
    sum += std::abs(int(per_pixel.rgb[i]) - int(per_vertex.rgb[i]));
    ++covered;
  }
  ASSERT_GT(covered, 1000);
  EXPECT_LT(sum / covered, 2.0);  // mean difference over the spheres, out of 255
}

TEST(RenderTest, LargeScenesKeepIdsAndDepthExact) {
  GET_RENDERER(renderer);
  // 64 spheres of 2208 triangles each: several batches for the rasteriser. Lit by ambient
  // light only, each shows its own exact colour.
  Scene scene;
  scene.set_background({0, 0, 0, 1});
  scene.set_ambient({1, 1, 1, 1});
  const int sphere = scene.add_mesh(make_sphere(0.4f, 24, 48));
  for (int i = 0; i < 64; ++i) {
    Material m = plain(0, 0, 0);
    m.ambient = {(40 + 3 * i) / 255.0f, (200 - 2 * i) / 255.0f, (i % 2 ? 255 : 128) / 255.0f, 1};
    scene.add_instance(sphere, m, make_pose(8 + i % 3, (i % 8 - 3.5) * 0.9, (i / 8 - 3.5) * 0.9),
                       100 + i, i % 3);
  }
  const CameraSpec spec{400, 300, 1.2, 0.1, 100};
  Frame f, again;
  renderer->render(scene, identity_pose(), spec, &f, true, true);
  EXPECT_GT(renderer->last_stats().triangles_drawn, 100000u);
  ASSERT_EQ(f.boxes.size(), 64u);
  for (const BoundingBox& b : f.boxes) {
    const int i = static_cast<int>(b.model_id) - 100;
    const int r = 40 + 3 * i, g = 200 - 2 * i, bl = i % 2 ? 255 : 128;
    const Rect seen =
        find_pixels(f, [&](int pr, int pg, int pb) { return pr == r && pg == g && pb == bl; });
    EXPECT_EQ(seen.count, static_cast<int>(b.pixel_count)) << "model " << b.model_id;
    EXPECT_EQ(seen.x_min, b.x_min) << "model " << b.model_id;
    EXPECT_EQ(seen.y_max, b.y_max) << "model " << b.model_id;
  }
  // Sphere 36, centred at (8, 0.45, 0.45), is 8 - 0.4 m ahead along the axis at its centre's
  // pixel.
  const auto centre = project(spec, 8, 0.45, 0.45);
  EXPECT_NEAR(f.depth[int(centre[1]) * spec.width + int(centre[0])], 7.6, 0.02);
  renderer->render(scene, identity_pose(), spec, &again, true, true);
  EXPECT_EQ(f.rgb, again.rgb);
  EXPECT_EQ(0, std::memcmp(f.depth.data(), again.depth.data(), f.depth.size() * sizeof(float)));
}

TEST(RenderTest, RejectsBadInput) {
  GET_RENDERER(renderer);
  Scene scene;
  Frame f;
  EXPECT_THROW(renderer->render(scene, identity_pose(), CameraSpec{0, 10, 1, 0.1, 10}, &f),
               std::invalid_argument);
  EXPECT_THROW(renderer->render(scene, identity_pose(), CameraSpec{10, 10, 3.2, 0.1, 10}, &f),
               std::invalid_argument);
  EXPECT_THROW(renderer->render(scene, identity_pose(), CameraSpec{10, 10, 1, 1, 0.5}, &f),
               std::invalid_argument);
  EXPECT_THROW(scene.add_instance(5, Material{}, identity_pose()), std::out_of_range);
  EXPECT_FALSE(renderer->description().empty());
}

// Levels of detail: far spheres are drawn coarser, near ones at full detail, and the image
// stays within the tolerance of the full-detail one (silhouettes move by under a pixel).
TEST(RenderTest, LevelsOfDetailLookTheSameAsFullDetail) {
  GET_RENDERER(renderer);
  Scene scene;
  scene.set_background({0, 0, 0, 1});
  Light sun;
  sun.direction = {0.3f, -0.6f, -0.7f};
  scene.add_light(sun);
  const int sphere = scene.add_mesh_levels(sphere_levels(0.4f, 24, 48));
  ASSERT_EQ(scene.mesh_lods()[sphere].size(), 2u);
  for (int i = 0; i < 6; ++i)
    scene.add_instance(sphere, plain(0.8f, 0.3f, 0.2f), make_pose(2 + 6 * i, 0.5 * (i % 2), 0),
                       1 + i);
  const CameraSpec spec{736, 480, 1.047, 0.1, 100};
  Frame lod, full;
  renderer->render(scene, identity_pose(), spec, &lod, false, true);
  const RenderStats with_lod = renderer->last_stats();
  renderer->set_lod_pixel_error(0);
  renderer->render(scene, identity_pose(), spec, &full, false, true);
  const RenderStats without = renderer->last_stats();
  renderer->set_lod_pixel_error(Renderer::kLodPixelError);
  EXPECT_EQ(without.coarser_level, 0);
  EXPECT_EQ(without.triangles_drawn, 6 * make_sphere(0.4f, 24, 48).triangle_count());
  EXPECT_GE(with_lod.coarser_level, 3);                              // the far ones
  EXPECT_LT(with_lod.triangles_drawn, without.triangles_drawn / 2);  // 4 of 6 coarser
  // The nearest sphere (2 m away, 280 px across) keeps every triangle: it is drawn first.
  // Coverage: the pixels one image covers and the other does not lie on silhouettes only.
  int differ = 0, covered = 0;
  double colour = 0;
  for (size_t p = 0; p < lod.rgb.size() / 3; ++p) {
    const bool a = lod.rgb[3 * p] || lod.rgb[3 * p + 1] || lod.rgb[3 * p + 2];
    const bool b = full.rgb[3 * p] || full.rgb[3 * p + 1] || full.rgb[3 * p + 2];
    covered += a || b;
    differ += a != b;
    if (a && b)
      for (int c = 0; c < 3; ++c)
        colour += std::abs(int(lod.rgb[3 * p + c]) - int(full.rgb[3 * p + c]));
  }
  ASSERT_GT(covered, 40000);
  EXPECT_LT(differ, covered / 100);
  EXPECT_LT(colour / (3.0 * covered), 1.0);  // mean difference out of 255
  // Ground truth is unchanged to the pixel box.
  ASSERT_EQ(lod.boxes.size(), full.boxes.size());
  for (size_t i = 0; i < lod.boxes.size(); ++i) {
    EXPECT_NEAR(lod.boxes[i].x_min, full.boxes[i].x_min, 1);
    EXPECT_NEAR(lod.boxes[i].x_max, full.boxes[i].x_max, 1);
    EXPECT_NEAR(lod.boxes[i].y_min, full.boxes[i].y_min, 1);
    EXPECT_NEAR(lod.boxes[i].y_max, full.boxes[i].y_max, 1);
  }
}

}  // namespace
}  // namespace convoy::render
