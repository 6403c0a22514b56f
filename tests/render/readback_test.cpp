// Read-back helpers (render/readback.h): RGBA to RGB, and a camera's noise added with clamping.
#include "render/readback.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

namespace convoy::render {
namespace {

TEST(Readback, RgbaToRgbDropsAlphaForAnyCount) {
  std::mt19937 rng(3);
  for (size_t pixels : {0, 1, 3, 4, 5, 17, 1000}) {
    std::vector<uint8_t> rgba(4 * pixels), rgb(3 * pixels + 1, 0xAB);
    for (auto& b : rgba) b = static_cast<uint8_t>(rng());
    rgba_to_rgb(rgba.data(), rgb.data(), pixels);
    for (size_t p = 0; p < pixels; ++p)
      for (int c = 0; c < 3; ++c) ASSERT_EQ(rgb[3 * p + c], rgba[4 * p + c]) << p << " " << c;
    EXPECT_EQ(rgb[3 * pixels], 0xAB) << "wrote past the end";
  }
}

TEST(Readback, AddNoiseClampsAtBothEnds) {
  std::vector<uint8_t> bytes{0, 0, 255, 255, 100, 100, 7, 250};
  const std::vector<int16_t> noise{-5, 3, 9, -300, 155, 156, -7, 1000};
  add_noise(bytes.data(), noise.data(), bytes.size());
  EXPECT_EQ(bytes, (std::vector<uint8_t>{0, 3, 255, 0, 255, 255, 0, 255}));
}

TEST(Readback, AddNoiseMatchesTheScalarSumOnAFrame) {
  std::mt19937 rng(11);
  std::normal_distribution<double> normal(0.0, 20.0);
  const size_t n = 736 * 480 * 3 + 5;  // not a multiple of any vector width
  std::vector<uint8_t> bytes(n), expected(n);
  std::vector<int16_t> noise(n);
  for (size_t i = 0; i < n; ++i) {
    bytes[i] = static_cast<uint8_t>(rng());
    noise[i] = static_cast<int16_t>(normal(rng));
    const int v = bytes[i] + noise[i];
    expected[i] = static_cast<uint8_t>(v < 0 ? 0 : v > 255 ? 255 : v);
  }
  add_noise(bytes.data(), noise.data(), n);
  EXPECT_EQ(bytes, expected);
}

}  // namespace
}  // namespace convoy::render
