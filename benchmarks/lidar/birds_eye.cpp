#include "birds_eye.h"

#include <png.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <stdexcept>

namespace convoy::lidar_bench {

namespace {

std::array<uint8_t, 3> class_colour(const std::string& cls) {
  static const std::map<std::string, std::array<uint8_t, 3>> colours = {
      {"car", {245, 90, 50}},        {"truck", {200, 40, 160}},        {"bus", {250, 200, 30}},
      {"pedestrian", {255, 30, 30}}, {"cyclist", {255, 120, 200}},     {"building", {60, 110, 250}},
      {"tree", {40, 200, 60}},       {"shrub", {110, 230, 90}},        {"pole", {230, 230, 120}},
      {"sign", {250, 250, 250}},     {"traffic_light", {250, 150, 0}}, {"barrier", {160, 120, 80}},
      {"other", {180, 100, 250}}};
  auto it = colours.find(cls);
  return it == colours.end() ? std::array<uint8_t, 3>{180, 100, 250} : it->second;
}

}  // namespace

void write_birds_eye(const std::string& path, const lidar::PointCloud& cloud,
                     const std::vector<std::string>& class_of, int size, double metres_per_pixel) {
  std::vector<uint8_t> rgb(static_cast<size_t>(size) * size * 3, 0);
  auto plot = [&](int px, int py, const std::array<uint8_t, 3>& c, int dot) {
    for (int dy = 0; dy < dot; ++dy)
      for (int dx = 0; dx < dot; ++dx) {
        const int x = px + dx, y = py + dy;
        if (x < 0 || y < 0 || x >= size || y >= size) continue;
        std::copy(c.begin(), c.end(), &rgb[3 * (static_cast<size_t>(y) * size + x)]);
      }
  };
  // the ground first, labelled objects over it
  for (int pass = 0; pass < 2; ++pass)
    for (const lidar::Point& p : cloud.points) {
      const bool labelled = p.label != 0 && p.label < class_of.size() && !class_of[p.label].empty();
      const bool spurious = p.flags & lidar::Point::kSpurious;
      if ((pass == 1) != (labelled || spurious)) continue;
      const int px = static_cast<int>(std::floor(size / 2.0 - p.y / metres_per_pixel));
      const int py = static_cast<int>(std::floor(size / 2.0 - p.x / metres_per_pixel));
      std::array<uint8_t, 3> c;
      if (spurious) {
        c = {0, 230, 230};
      } else if (labelled) {
        c = class_colour(class_of[p.label]);
      } else {
        // intensity includes cos(incidence): far ground is dim; 0.25 and above is white
        const auto v =
            static_cast<uint8_t>(45 + 210 * std::sqrt(std::clamp(p.intensity / 0.25f, 0.0f, 1.0f)));
        c = {v, v, v};
      }
      plot(px, py, c, labelled ? 3 : 2);
    }
  // the sensor's vehicle: a white outline of 4.5 x 1.8 m
  const int hx = static_cast<int>(0.9 / metres_per_pixel),
            hy = static_cast<int>(2.25 / metres_per_pixel);
  for (int y = -hy; y <= hy; ++y)
    for (int x = -hx; x <= hx; ++x)
      if (std::abs(y) == hy || std::abs(x) == hx)
        plot(size / 2 + x, size / 2 + y, {255, 255, 255}, 1);
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = size;
  png.height = size;
  png.format = PNG_FORMAT_RGB;
  if (!png_image_write_to_file(&png, path.c_str(), 0, rgb.data(), size * 3, nullptr))
    throw std::runtime_error(path + ": cannot write the PNG: " + png.message);
}

}  // namespace convoy::lidar_bench
