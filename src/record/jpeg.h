// JPEG encoding into memory (libjpeg), for the camera channels of the live server and of the
// recording.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace convoy::record {

// Encodes `width` x `height` pixels of `channels` bytes each (1 grey, 3 RGB, 4 RGBA: alpha
// dropped), rows top to bottom, at `quality` (1-100). Throws std::invalid_argument when the
// sizes do not match, std::runtime_error when libjpeg fails.
std::string encode_jpeg(std::string_view pixels, uint32_t width, uint32_t height, uint32_t channels,
                        int quality);

}  // namespace convoy::record
