#include "datapack/camera.h"

#include <cstring>
#include <stdexcept>
#include <string>

#include "convoy/datapacks.pb.h"
#include "datapack/proto.h"
#include "datapack/registry.h"

namespace convoy::datapack {

void write_camera(Builder& out, uint32_t height, uint32_t width, uint32_t depth,
                  const std::function<void(std::span<uint8_t>)>& fill) {
  data::Camera c;
  c.set_image_height(height);
  c.set_image_width(width);
  c.set_image_depth(depth);
  const size_t size = static_cast<size_t>(height) * width * depth;
  if (size >= kLargeBlobBytes) {
    uint32_t index = 0;
    fill(out.reserve_blob(size, &index));
    c.set_image_blob(index + 1);
  } else {
    std::string* bytes = c.mutable_image_data();
    bytes->resize(size);
    fill({reinterpret_cast<uint8_t*>(bytes->data()), size});
  }
  write_proto(out, c);
}

void write_camera(Builder& out, uint32_t height, uint32_t width, uint32_t depth,
                  std::string_view pixels) {
  const size_t size = static_cast<size_t>(height) * width * depth;
  if (pixels.size() != size) {
    throw std::runtime_error(out.describe() + ": " + std::to_string(pixels.size()) +
                             " bytes for a " + std::to_string(width) + "x" +
                             std::to_string(height) + "x" + std::to_string(depth) + " image");
  }
  write_camera(out, height, width, depth, [&](std::span<uint8_t> dst) {
    if (size) std::memcpy(dst.data(), pixels.data(), size);
    count_copy(size);
  });
}

CameraImage read_camera(const View& in) {
  CameraImage img;
  if (in.empty()) return img;
  const auto c = read_proto<data::Camera>(in);
  img.height = c.image_height();
  img.width = c.image_width();
  img.depth = c.image_depth();
  if (c.image_blob() > 0) {
    if (c.image_blob() > static_cast<uint32_t>(in.message().blobs_size()))
      throw std::runtime_error(in.describe() + ": image_blob refers to a missing blob");
    img.pixels = in.blob(c.image_blob() - 1, &img.in_shm);
  } else {
    img.owned.assign(c.image_data().begin(), c.image_data().end());  // small: inline
    img.pixels = {reinterpret_cast<const char*>(img.owned.data()), img.owned.size()};
  }
  const size_t expected = static_cast<size_t>(img.height) * img.width * img.depth;
  if (img.pixels.size() != expected) {
    throw std::runtime_error(in.describe() + ": " + std::to_string(img.pixels.size()) +
                             " bytes of image, expected " + std::to_string(img.width) + "x" +
                             std::to_string(img.height) + "x" + std::to_string(img.depth) + " = " +
                             std::to_string(expected));
  }
  return img;
}

}  // namespace convoy::datapack
