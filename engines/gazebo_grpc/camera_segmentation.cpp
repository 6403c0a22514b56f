// Segmentation cameras (camera_sensors.h, segmentation_datapack): the ground-truth instance
// image of a <sensor type="segmentation_camera"> as Gazebo's label and coloured maps.
#include <array>

#include "camera_sensors.h"
#include "datapack/camera.h"

namespace convoy::world {

namespace {

// Cityscapes' colours for the classes of known_classes(), in its order; black for none.
constexpr std::array<std::array<uint8_t, 3>, 14> kPalette = {{{0, 0, 0},
                                                              {0, 0, 142},
                                                              {0, 0, 70},
                                                              {0, 60, 100},
                                                              {220, 20, 60},
                                                              {119, 11, 32},
                                                              {70, 70, 70},
                                                              {107, 142, 35},
                                                              {152, 251, 152},
                                                              {153, 153, 153},
                                                              {250, 170, 30},
                                                              {220, 220, 0},
                                                              {190, 153, 153},
                                                              {81, 0, 81}}};

std::array<uint8_t, 3> instance_colour(uint32_t id) {  // a fixed colour per instance
  uint32_t h = id * 2654435761u;
  h ^= h >> 15;
  return {static_cast<uint8_t>(64 + (h & 0xbf)), static_cast<uint8_t>(64 + ((h >> 8) & 0xbf)),
          static_cast<uint8_t>(64 + ((h >> 16) & 0xbf))};
}

}  // namespace

void CameraSensors::segmentation_datapack(size_t i, bool colored, datapack::Builder& out) {
  Camera& cam = cameras_[i];
  ensure_ids(cam);
  const bool panoptic = cam.desc->segmentation == "panoptic";
  const auto w = static_cast<uint32_t>(cam.frame.width),
             h = static_cast<uint32_t>(cam.frame.height);
  std::vector<uint8_t> labels(model_classes_.size() + 1, 0);  // by model_id
  for (size_t m = 0; m < model_classes_.size(); ++m) labels[m + 1] = class_label(model_classes_[m]);
  datapack::write_camera(out, h, w, 3, [&](std::span<uint8_t> dst) {
    const size_t pixels = static_cast<size_t>(w) * h;
    for (size_t p = 0; p < pixels; ++p) {
      uint32_t id = p < cam.frame.model_ids.size() ? cam.frame.model_ids[p] : 0;
      if (id == cam.own_model || id >= labels.size()) id = 0;
      const uint8_t label = labels[id];
      uint8_t* px = dst.data() + 3 * p;
      if (colored) {
        const auto c = panoptic && label ? instance_colour(id) : kPalette[label];
        px[0] = c[0], px[1] = c[1], px[2] = c[2];
      } else if (panoptic) {  // Gazebo's panoptic label map: class, then the instance's 16 bits
        px[0] = label, px[1] = static_cast<uint8_t>(id >> 8), px[2] = static_cast<uint8_t>(id);
      } else {
        px[0] = px[1] = px[2] = label;
      }
    }
  });
}

}  // namespace convoy::world
