#pragma once
// Rain streaks and snow flakes over a camera image, as small quads made on the CPU and drawn
// blended over the colour image (Renderer). Only the pixels the particles cover are shaded,
// which is what makes precipitation cheap on a software rasteriser.
//
// Three layers, nearer ones with longer, wider, brighter streaks (rain) or larger flakes
// (snow). Each layer cuts the image, sheared by `slant`, into cells of its own size; a cell
// holds one particle with a probability that grows with `amount`, placed within the cell. All
// of it is a hash of the cell, the layer and `seed`: the same seed gives the same particles, a
// new seed (one per frame) a new pattern.

#include <cstdint>
#include <vector>

namespace convoy::render {

struct PrecipitationVertex {
  float x, y;                         // image pixels, row 0 at the top
  float across_x, across_y, opacity;  // -1..1 across the streak or flake; its opacity
};

struct PrecipitationParams {
  int width = 0, height = 0;  // pixels
  float amount = 0;           // 0-1
  bool snow = false;
  float slant = 0;  // image x per image y
  uint32_t seed = 0;
};

// Replaces *out with two triangles (six vertices) per particle.
void make_precipitation(const PrecipitationParams& params, std::vector<PrecipitationVertex>* out);

}  // namespace convoy::render
