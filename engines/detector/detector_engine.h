// EngineType "detector" (registered in detector_engine.cpp): runs an object detector on the latest
// camera image.
//
// Config keys (schema.json):
//   Backend             "convoy" (default: Convoy's trained detector) | "ground_truth" |
//                       "yolo" | "hog"
//   ModelPath           ONNX model, required for yolo (YOLOv5 or YOLOv8 export); convoy's
//                       default is share/convoy/models/detector/convoy_detector.onnx
//   ClassNamesFile      one class name per line (default: the 80 COCO names)
//   InputSize           network input side for yolo (default 640; convoy: model.json's)
//   ConfidenceThreshold default 0.25
//   NmsThreshold        IoU threshold of the per-class NMS, default 0.45
//   YoloVersion         "auto" (default, from the output shape) | "v5" | "v8"
// Datapacks read (set_datapack): any name holding an image, "camera_img" (JSON:
//   c_imageHeight, c_imageWidth, current_image_frame as list or numpy array) or "camera"
//   (convoy.data.Camera); the most recent one is used. With ground_truth: "boxes", the
//   JSON of a camera's ::boxes datapack.
// Datapack written: "detections" (JSON) {frame, time_ns, width, height, inference_ms,
//   detections: [{class, class_id, confidence, x_min, y_min, x_max, y_max}]} sorted by
//   confidence; empty until the first image (or boxes) was processed.
// Each step runs the detector once if a new input arrived since the last step (an image
// identical to the last one detected is not new: the camera did not render since).
#pragma once

#include <chrono>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string_view>

#include "convoy/datapacks.pb.h"
#include "datapack/json.h"
#include "datapack/registry.h"
#include "detector.h"
#include "engine/engine.h"

namespace convoy::engines {

class DetectorEngine final : public Engine {
 public:
  std::vector<engine::DataPackId> initialize(const std::string& name, const nlohmann::json& config,
                                             int64_t timestep_ns) override {
    name_ = name;
    backend_ = detector::make_backend(config);
    backend_name_ = config.value("Backend", std::string("convoy"));
    std::vector<engine::DataPackId> ids;
    auto add = [&](const char* dp_name, std::string_view type) {
      engine::DataPackId id;
      id.set_name(dp_name);
      id.set_engine_name(name);
      id.set_type(std::string(type));
      ids.push_back(id);
    };
    add("detections", datapack::kJsonType);
    add("camera_img", datapack::kJsonType);
    add("camera", datapack::type_name<data::Camera>());
    add("boxes", datapack::kJsonType);  // used by the ground-truth passthrough only
    return ids;
  }

  int64_t step(int64_t duration_ns) override {
    time_ns_ += duration_ns;
    if (!pending_) return time_ns_;
    pending_ = false;
    auto t0 = std::chrono::steady_clock::now();
    if (backend_->input() == detector::BackendInput::kGroundTruth) {
      width_ = pending_boxes_.value("width", width_);
      height_ = pending_boxes_.value("height", height_);
    } else {
      width_ = pending_image_.cols;
      height_ = pending_image_.rows;
    }
    std::vector<detector::Detection> dets = backend_->detect(pending_image_, pending_boxes_);
    // The image may point into the request's shared memory, valid during this step only.
    pending_image_ = cv::Mat();
    auto t1 = std::chrono::steady_clock::now();
    ++frame_;
    result_ = {{"frame", frame_},
               {"time_ns", time_ns_},
               {"width", width_},
               {"height", height_},
               {"inference_ms", std::chrono::duration<double, std::milli>(t1 - t0).count()},
               {"backend", backend_name_},
               {"ground_truth", backend_->input() == detector::BackendInput::kGroundTruth},
               {"detections", detector::detections_json(dets)}};
    return time_ns_;
  }

  void set_datapack(const datapack::View& dp) override {
    if (dp.empty()) return;
    if (backend_->input() == detector::BackendInput::kGroundTruth) {
      if (dp.is_json()) {
        nlohmann::json j = datapack::read_json(dp);
        if (j.is_object() && j.contains("boxes")) {
          pending_boxes_ = std::move(j);
          pending_ = true;
          return;
        }
      }
      // Images are accepted but not needed; they only give the frame size, read once (a
      // camera keeps its size).
      if (width_ > 0) return;
      cv::Mat img = detector::image_from_datapack(dp);
      if (!img.empty()) {
        width_ = img.cols;
        height_ = img.rows;
      }
      return;
    }
    // Ground truth sent to an image backend (one config for every backend) is not needed.
    if (dp.id().name() == "boxes") return;
    // In place: the image is read from the request's shared memory during the next step.
    cv::Mat img = detector::image_from_datapack(dp);
    if (img.empty()) return;
    // A camera renders at its update_rate; between two frames a TF that does not check
    // isUpdated() (the report's camera_tf.py) sends the same image again, one per step. Its
    // detections are those already made: detect new images only.
    if (!img.isContinuous()) img = img.clone();
    const size_t hash = std::hash<std::string_view>{}(
        std::string_view(reinterpret_cast<const char*>(img.data), img.total() * img.elemSize()));
    if (!result_.is_null() && hash == last_image_hash_ && img.size() == last_image_size_) return;
    last_image_hash_ = hash;
    last_image_size_ = img.size();
    pending_image_ = std::move(img);
    pending_ = true;
  }

  void get_datapack(const engine::DataPackId& id, datapack::Builder& out) override {
    // Only "detections" has a value; other ids come back empty, as for every engine.
    if (id.name() != "detections" || result_.is_null()) return;
    datapack::write_json(out, result_);
  }

  void reset() override {
    time_ns_ = 0;
    frame_ = 0;
    pending_ = false;
    pending_image_ = cv::Mat();
    result_ = nullptr;
  }

 private:
  std::string name_;
  std::unique_ptr<detector::Backend> backend_;
  int64_t time_ns_ = 0;
  int64_t frame_ = 0;
  bool pending_ = false;
  cv::Mat pending_image_;
  size_t last_image_hash_ = 0;
  cv::Size last_image_size_;
  nlohmann::json pending_boxes_;
  int width_ = 0, height_ = 0;
  nlohmann::json result_;
  std::string backend_name_;
};

}  // namespace convoy::engines
