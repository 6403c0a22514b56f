#include "render/precipitation.h"

#include <algorithm>
#include <cmath>

namespace convoy::render {
namespace {

uint32_t hash(uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

void quad(std::vector<PrecipitationVertex>* out, const PrecipitationVertex (&c)[4]) {
  for (int i : {0, 1, 2, 0, 2, 3}) out->push_back(c[i]);
}

}  // namespace

void make_precipitation(const PrecipitationParams& p, std::vector<PrecipitationVertex>* out) {
  out->clear();
  const float amount = std::clamp(p.amount, 0.0f, 1.0f);
  if (amount <= 0 || p.width <= 0 || p.height <= 0) return;
  const float w = static_cast<float>(p.width), h = static_cast<float>(p.height);
  // q = (x - slant * y, y): the sheared space the cells tile.
  const float qx_min = std::min(0.0f, -p.slant * h), qx_max = std::max(w, w - p.slant * h);
  for (int layer = 0; layer < 3; ++layer) {
    const float fl = static_cast<float>(layer);
    const float cell_x = p.snow ? 14 + 14 * fl : 7 + 5 * fl;
    const float cell_y = p.snow ? 14 + 14 * fl : 80 + 60 * fl;
    const float chance = amount * (p.snow ? 0.45f - 0.1f * fl : 0.4f - 0.1f * fl);
    const uint32_t layer_key = hash(p.seed + static_cast<uint32_t>(layer) * 0x9e3779b9u);
    const int cx0 = static_cast<int>(std::floor(qx_min / cell_x));
    const int cx1 = static_cast<int>(std::floor(qx_max / cell_x));
    const int cy1 = static_cast<int>(std::floor(h / cell_y));
    for (int cy = 0; cy <= cy1; ++cy) {
      for (int cx = cx0; cx <= cx1; ++cx) {
        const uint32_t id =
            static_cast<uint32_t>(cx + 8192) * 16384u + static_cast<uint32_t>(cy + 8192);
        const uint32_t key = hash(id ^ layer_key);
        if (static_cast<float>(key & 0xffffu) / 65535.0f >= chance) continue;
        const float rx = static_cast<float>((key >> 16) & 0xffu) / 255.0f;
        const float ry = static_cast<float>(key >> 24) / 255.0f;
        if (p.snow) {
          const float radius = 0.7f + 0.9f * fl;
          const float qx = cx * cell_x + radius + rx * (cell_x - 2 * radius);
          const float y = cy * cell_y + radius + ry * (cell_y - 2 * radius);
          const float x = qx + p.slant * y;
          if (x + radius < 0 || x - radius > w || y - radius > h) continue;
          quad(out, {{x - radius, y - radius, -1, -1, 0.9f},
                     {x + radius, y - radius, 1, -1, 0.9f},
                     {x + radius, y + radius, 1, 1, 0.9f},
                     {x - radius, y + radius, -1, 1, 0.9f}});
        } else {
          const float len = cell_y * (0.3f + 0.15f * fl);
          const float qx = cx * cell_x + rx * cell_x;
          const float y0 = cy * cell_y + ry * (cell_y - len), y1 = y0 + len;
          const float x0 = qx + p.slant * y0, x1 = qx + p.slant * y1;
          const float width = 0.6f + 0.35f * fl, opacity = 0.16f + 0.08f * fl;
          if (std::max(x0, x1) + width < 0 || std::min(x0, x1) - width > w || y0 > h) continue;
          quad(out, {{x0 - width, y0, -1, 0, opacity},
                     {x0 + width, y0, 1, 0, opacity},
                     {x1 + width, y1, 1, 0, opacity},
                     {x1 - width, y1, -1, 0, opacity}});
        }
      }
    }
  }
}

}  // namespace convoy::render
