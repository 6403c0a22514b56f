// Image files for the renderer: PNG / JPEG textures in, binary PPM (test images) in and out.
//
// PNG needs libpng and JPEG libjpeg at build time (both found by CMake when installed);
// without one, loading that format throws saying so. Rows run top to bottom.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace convoy::render {

struct Image {
  int width = 0, height = 0, channels = 0;  // channels: 4 from load_image_rgba, 3 from read_ppm
  std::vector<uint8_t> data;                // height x width x channels, row 0 = top
};

// Loads a PNG or JPEG file (told apart by its signature) as 8-bit RGBA. Throws
// std::runtime_error naming the file if it cannot be read or decoded.
Image load_image_rgba(const std::string& path);

// Binary PPM (P6, maxval 255) of a height x width x 3 image. Throw std::runtime_error naming
// the file on failure.
void write_ppm(const std::string& path, int width, int height, const uint8_t* rgb);
Image read_ppm(const std::string& path);

}  // namespace convoy::render
