// Camera frames (convoy.data.Camera, NRP-Core's GazeboCameraDataPack): row-major pixels of
// image_depth bytes each. A frame of kLargeBlobBytes or more travels as a blob (image_blob is
// the blob's index + 1; 0 means the pixels are inline in image_data).
//
// The writer fills the pixels in place, in the outgoing arena; the reader sees them in place.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <string_view>
#include <vector>

#include "datapack/datapack.h"

namespace convoy::datapack {

struct CameraImage {
  uint32_t height = 0, width = 0, depth = 0;  // depth: bytes per pixel
  std::string_view pixels;                    // in place (see View for how long)
  bool in_shm = false;
  std::vector<uint8_t> owned;  // the pixels of a small frame, which come inline
};

// Writes a camera datapack of `height` x `width` x `depth` bytes; `fill` writes the pixels into
// the span it is given (in the outgoing arena for large frames: no copy of its own).
void write_camera(Builder& out, uint32_t height, uint32_t width, uint32_t depth,
                  const std::function<void(std::span<uint8_t>)>& fill);
// The same with pixels that already exist (copies them once).
void write_camera(Builder& out, uint32_t height, uint32_t width, uint32_t depth,
                  std::string_view pixels);

// Throws std::runtime_error naming the datapack unless it holds a camera frame whose size
// matches its dimensions. An empty datapack gives an empty image.
CameraImage read_camera(const View& in);

}  // namespace convoy::datapack
