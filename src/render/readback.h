// Turning what glReadPixels returns into a Frame (internal to the renderer).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "render/renderer.h"
#include "render/scene.h"

namespace convoy::render {

// Copies `pixels` RGBA pixels to RGB, dropping alpha.
void rgba_to_rgb(const uint8_t* src, uint8_t* dst, size_t pixels);

// Adds noise[i] to bytes[i] for i < count, clamped to [0, 255] (a camera's sensor noise).
// The two ranges must not overlap.
void add_noise(uint8_t* bytes, const int16_t* noise, size_t count);

// The bounding boxes of `scene`'s labelled models in an id image: ids[y * width + x] is the
// index + 1 of the instance seen at that pixel, 0 where none is. One box per model_id != 0,
// by increasing model_id. `instance_distance` (by instance index, optional) gives each box's
// distance: the least of its visible instances'.
void boxes_from_ids(const uint32_t* ids, int width, int height, const Scene& scene,
                    std::vector<BoundingBox>* boxes, const float* instance_distance = nullptr);

}  // namespace convoy::render
