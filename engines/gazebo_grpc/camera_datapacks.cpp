// CameraSensors: the datapacks of a camera (image, depth, instances, ground-truth boxes).
#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "camera_sensors.h"
#include "datapack/camera.h"
#include "datapack/json.h"

namespace convoy::world {

void CameraSensors::image_datapack(size_t i, datapack::Builder& out) {
  Camera& cam = cameras_[i];
  cam.want_image = true;
  if (!cam.rendered) first_render(cam);
  datapack::write_camera(out, static_cast<uint32_t>(cam.frame.height),
                         static_cast<uint32_t>(cam.frame.width),
                         static_cast<uint32_t>(cam.depth_channels),
                         [&](std::span<uint8_t> dst) { convert(cam, dst); });
}

void CameraSensors::depth_datapack(size_t i, datapack::Builder& out) {
  Camera& cam = cameras_[i];
  cam.want_depth = true;
  if (!cam.rendered)
    first_render(cam);
  else if (!cam.has_depth)
    render(cam);  // (noise redrawn: a new sample of the same view)
  const uint64_t shape[2] = {static_cast<uint64_t>(cam.frame.height),
                             static_cast<uint64_t>(cam.frame.width)};
  const std::string_view bytes(reinterpret_cast<const char*>(cam.frame.depth.data()),
                               cam.frame.depth.size() * sizeof(float));
  datapack::write_json(out, {{"width", cam.frame.width},
                             {"height", cam.frame.height},
                             {"depth", datapack::ndarray_json(out, "<f4", shape, bytes)}});
}

namespace {
double visible_fraction(const render::BoundingBox& b) {
  const double full =
      static_cast<double>(b.full_x_max - b.full_x_min) * (b.full_y_max - b.full_y_min);
  const double seen = static_cast<double>(b.x_max - b.x_min + 1) * (b.y_max - b.y_min + 1);
  if (!(full > 0)) return 1.0;
  return std::clamp(seen / full, 0.0, 1.0);
}
}  // namespace

void CameraSensors::ensure_ids(Camera& cam) {
  cam.want_ids = true;
  if (!cam.rendered)
    first_render(cam);
  else if (!cam.has_ids)
    render(cam);
}

void CameraSensors::instances_datapack(size_t i, datapack::Builder& out) {
  Camera& cam = cameras_[i];
  ensure_ids(cam);
  const size_t pixels = static_cast<size_t>(cam.frame.width) * cam.frame.height;
  ids_.resize(pixels);
  for (size_t p = 0; p < pixels && p < cam.frame.model_ids.size(); ++p) {
    const uint32_t id = cam.frame.model_ids[p];
    ids_[p] = id == cam.own_model ? 0 : id;
  }
  nlohmann::json instances = nlohmann::json::object();
  for (const auto& b : cam.frame.boxes) {
    if (b.model_id == cam.own_model) continue;
    instances[std::to_string(b.model_id)] = {{"model", model_names_[b.model_id - 1]},
                                             {"class", model_classes_[b.model_id - 1]}};
  }
  const uint64_t shape[2] = {static_cast<uint64_t>(cam.frame.height),
                             static_cast<uint64_t>(cam.frame.width)};
  const std::string_view bytes(reinterpret_cast<const char*>(ids_.data()),
                               ids_.size() * sizeof(uint32_t));
  datapack::write_json(out, {{"width", cam.frame.width},
                             {"height", cam.frame.height},
                             {"ids", datapack::ndarray_json(out, "<u4", shape, bytes)},
                             {"instances", instances}});
}

double CameraSensors::visibility(double distance) const {
  if (!has_weather_ || !std::isfinite(weather_.visibility_m) || !std::isfinite(distance))
    return 1.0;
  return std::exp(-3.912 * distance / weather_.visibility_m);
}

void CameraSensors::boxes_datapack(size_t i, datapack::Builder& out) {
  Camera& cam = cameras_[i];
  cam.want_boxes = true;
  if (!cam.rendered)
    first_render(cam);
  else if (!cam.has_boxes)
    render(cam);
  nlohmann::json boxes = nlohmann::json::array();
  for (const auto& b : cam.frame.boxes) {
    if (b.model_id == cam.own_model) continue;  // the camera's own vehicle
    boxes.push_back({{"model", model_names_[b.model_id - 1]},
                     {"class", model_classes_[b.model_id - 1]},
                     {"instance", b.model_id},
                     {"x_min", b.x_min},
                     {"y_min", b.y_min},
                     {"x_max", b.x_max},
                     {"y_max", b.y_max},
                     {"pixels", b.pixel_count},
                     {"distance", std::isfinite(b.distance) ? b.distance : -1.0f},
                     {"visibility", visibility(b.distance)},
                     {"visible_fraction", visible_fraction(b)},
                     {"full_box", {b.full_x_min, b.full_y_min, b.full_x_max, b.full_y_max}}});
  }
  datapack::write_json(
      out, {{"width", cam.frame.width}, {"height", cam.frame.height}, {"boxes", boxes}});
}

}  // namespace convoy::world
