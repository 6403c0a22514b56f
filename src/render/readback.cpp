#include "render/readback.h"

#include <algorithm>
#include <bit>
#include <climits>
#include <cstring>
#include <map>

namespace convoy::render {

// Pixels come as RGBA bytes and are handled as 32-bit words.
static_assert(std::endian::native == std::endian::little, "RGBA bytes read as little-endian words");

void rgba_to_rgb(const uint8_t* src, uint8_t* dst, size_t pixels) {
  // Four pixels (16 bytes in, 12 out) at a time, as little-endian words.
  size_t i = 0;
  for (; i + 4 <= pixels; i += 4) {
    uint32_t p[4], q[3];
    std::memcpy(p, src + 4 * i, 16);
    q[0] = (p[0] & 0xffffff) | (p[1] << 24);
    q[1] = ((p[1] >> 8) & 0xffff) | (p[2] << 16);
    q[2] = ((p[2] >> 16) & 0xff) | (p[3] << 8);
    std::memcpy(dst + 3 * i, q, 12);
  }
  for (; i < pixels; ++i) std::memcpy(dst + 3 * i, src + 4 * i, 3);
}

void add_noise(uint8_t* __restrict bytes, const int16_t* __restrict noise, size_t count) {
  // Restricted locals: the compiler vectorises this (16-bit lanes); through pointers it had to
  // reload, it added byte by byte.
  for (size_t i = 0; i < count; ++i) {
    const int v = bytes[i] + noise[i];
    bytes[i] = static_cast<uint8_t>(v < 0 ? 0 : v > 255 ? 255 : v);
  }
}

void boxes_from_ids(const uint32_t* ids, int width, int height, const Scene& scene,
                    std::vector<BoundingBox>* boxes, const float* instance_distance) {
  struct Extent {
    int x_min = INT_MAX, y_min = INT_MAX, x_max = -1, y_max = -1;
    uint32_t count = 0;
  };
  const auto& instances = scene.instances();
  std::vector<Extent> extents(instances.size() + 1);  // by id
  for (int y = 0; y < height; ++y) {
    const uint32_t* row = ids + static_cast<size_t>(y) * width;
    // Runs of one id along the row cost one update.
    for (int x = 0; x < width;) {
      const uint32_t v = row[x];
      int end = x + 1;
      while (end < width && row[end] == v) ++end;
      if (v != 0 && v < extents.size()) {
        Extent& e = extents[v];
        e.x_min = std::min(e.x_min, x);
        e.x_max = std::max(e.x_max, end - 1);
        e.y_min = std::min(e.y_min, y);
        e.y_max = y;
        e.count += end - x;
      }
      x = end;
    }
  }
  std::map<uint32_t, BoundingBox> by_model;
  for (size_t i = 0; i < instances.size(); ++i) {
    const Extent& e = extents[i + 1];
    const uint32_t model = instances[i].model_id;
    if (model == 0 || e.count == 0) continue;
    auto [it, inserted] = by_model.try_emplace(
        model, BoundingBox{model, instances[i].class_id, e.x_min, e.y_min, e.x_max, e.y_max, 0});
    BoundingBox& b = it->second;
    if (instance_distance) b.distance = std::min(b.distance, instance_distance[i]);
    b.x_min = std::min(b.x_min, e.x_min);
    b.y_min = std::min(b.y_min, e.y_min);
    b.x_max = std::max(b.x_max, e.x_max);
    b.y_max = std::max(b.y_max, e.y_max);
    b.pixel_count += e.count;
  }
  boxes->clear();
  for (const auto& [model, box] : by_model) boxes->push_back(box);
}

}  // namespace convoy::render
