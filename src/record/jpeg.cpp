#include "record/jpeg.h"

#include <jpeglib.h>

#include <csetjmp>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <vector>

namespace convoy::record {

namespace {

struct ErrorManager {
  jpeg_error_mgr base;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

void on_error(j_common_ptr info) {
  auto* err = reinterpret_cast<ErrorManager*>(info->err);
  (*info->err->format_message)(info, err->message);
  std::longjmp(err->jump, 1);
}

}  // namespace

std::string encode_jpeg(std::string_view pixels, uint32_t width, uint32_t height, uint32_t channels,
                        int quality) {
  if (channels != 1 && channels != 3 && channels != 4)
    throw std::invalid_argument("JPEG: " + std::to_string(channels) +
                                " bytes per pixel (1, 3 or 4 expected)");
  if (width == 0 || height == 0 || pixels.size() != size_t{width} * height * channels)
    throw std::invalid_argument("JPEG: " + std::to_string(pixels.size()) + " bytes for " +
                                std::to_string(width) + "x" + std::to_string(height) + "x" +
                                std::to_string(channels));
  jpeg_compress_struct info{};
  ErrorManager err{};
  info.err = jpeg_std_error(&err.base);
  err.base.error_exit = on_error;
  unsigned char* out = nullptr;
  unsigned long out_size = 0;
  std::vector<uint8_t> row(size_t{width} * 3);
  if (setjmp(err.jump)) {
    jpeg_destroy_compress(&info);
    std::free(out);
    throw std::runtime_error(std::string("JPEG: ") + err.message);
  }
  jpeg_create_compress(&info);
  jpeg_mem_dest(&info, &out, &out_size);
  info.image_width = width;
  info.image_height = height;
  info.input_components = channels == 1 ? 1 : 3;
  info.in_color_space = channels == 1 ? JCS_GRAYSCALE : JCS_RGB;
  jpeg_set_defaults(&info);
  jpeg_set_quality(&info, quality, TRUE);
  jpeg_start_compress(&info, TRUE);
  const auto* src = reinterpret_cast<const uint8_t*>(pixels.data());
  while (info.next_scanline < height) {
    const uint8_t* line = src + size_t{info.next_scanline} * width * channels;
    if (channels == 4) {
      for (uint32_t x = 0; x < width; ++x)
        for (int c = 0; c < 3; ++c) row[x * 3 + c] = line[x * 4 + c];
      line = row.data();
    }
    JSAMPROW rows[1] = {const_cast<JSAMPROW>(line)};
    jpeg_write_scanlines(&info, rows, 1);
  }
  jpeg_finish_compress(&info);
  std::string result(reinterpret_cast<const char*>(out), out_size);
  jpeg_destroy_compress(&info);
  std::free(out);
  return result;
}

}  // namespace convoy::record
