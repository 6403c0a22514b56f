// What the fuzz targets do with a decoded datapack: read it as its receivers would, and check
// that whatever a decoder accepted is consistent.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string_view>

#include "datapack/camera.h"
#include "datapack/json.h"
#include "fuzz_input.h"

namespace convoy::fuzz {

// Reads every byte of `bytes` (so that ASan sees a view that points outside its buffer).
inline uint8_t touch(std::string_view bytes) {
  uint8_t sum = 0;
  for (char c : bytes) sum ^= static_cast<uint8_t>(c);
  return sum;
}

// Every numpy array inside `value`: read_ndarray either throws std::runtime_error or returns
// bytes that hold exactly shape x dtype, in range.
inline void check_ndarrays(const datapack::View& view, const nlohmann::json& value, int depth = 0) {
  if (depth > 64) return;
  if (value.is_binary()) {
    try {
      auto ref = datapack::read_ndarray(view, value);
      uint64_t total = datapack::dtype_size(ref.header.dtype);
      for (uint64_t d : ref.header.shape) {
        if (__builtin_mul_overflow(total, d, &total)) fail("read_ndarray: shape x dtype overflows");
      }
      if (total != ref.data.size()) fail("read_ndarray: size does not match shape x dtype");
      touch(ref.data);
    } catch (const std::runtime_error&) {
    }
    return;
  }
  if (value.is_structured()) {
    for (const auto& item : value) check_ndarrays(view, item, depth + 1);
  }
}

// A received datapack as the coordinator, the engines and the detector read it.
inline void read_datapack(const datapack::View& view) {
  if (view.is_json()) {
    try {
      check_ndarrays(view, datapack::read_json(view));
    } catch (const std::runtime_error&) {
    }
  }
  try {
    auto img = datapack::read_camera(view);
    uint64_t expected = img.height;
    if (__builtin_mul_overflow(expected, uint64_t{img.width}, &expected) ||
        __builtin_mul_overflow(expected, uint64_t{img.depth}, &expected))
      fail("read_camera: height x width x depth overflows");
    if (expected != img.pixels.size()) fail("read_camera: pixels do not match the size");
    touch(img.pixels);
  } catch (const std::runtime_error&) {
  }
  for (int i = 0; i <= view.message().blobs_size(); ++i) {
    try {
      touch(view.blob(static_cast<uint32_t>(i)));
    } catch (const std::runtime_error&) {
    }
  }
}

}  // namespace convoy::fuzz
