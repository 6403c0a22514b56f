// EngineType "detector" (registered in detector_engine.cpp): runs an object detector on the latest
// camera image.
//
// Config keys (schema.json):
//   Backend             "ground_truth" (default) | "yolo" | "hog"
//   ModelPath           ONNX model, required for yolo (YOLOv5 or YOLOv8 export)
//   ClassNamesFile      one class name per line (default: the 80 COCO names)
//   InputSize           network input side (default 640)
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

#include "detector.h"
#include "engine/engine.h"

namespace convoy::engines {

class DetectorEngine final : public Engine {
 public:
  std::vector<engine::DataPackId> initialize(const std::string& name, const nlohmann::json& config,
                                             int64_t timestep_ns) override {
    name_ = name;
    backend_ = config.value("Backend", std::string("ground_truth"));
    std::string names_file = config.value("ClassNamesFile", std::string());
    names_ =
        names_file.empty() ? detector::coco_class_names() : detector::read_class_names(names_file);
    if (backend_ == "yolo") {
      detector::YoloOptions o;
      o.model_path = config.value("ModelPath", std::string());
      o.class_names = names_;
      o.input_size = config.value("InputSize", 640);
      o.conf_threshold = config.value("ConfidenceThreshold", 0.25f);
      o.nms_threshold = config.value("NmsThreshold", 0.45f);
      o.version = detector::parse_yolo_version(config.value("YoloVersion", std::string("auto")));
      yolo_ = std::make_unique<detector::YoloDetector>(std::move(o));
    } else if (backend_ == "hog") {
      hog_ = std::make_unique<detector::HogDetector>();
    } else if (backend_ != "ground_truth") {
      throw std::runtime_error("Backend '" + backend_ +
                               "': must be \"yolo\", \"hog\" or \"ground_truth\"");
    }
    std::vector<engine::DataPackId> ids;
    auto add = [&](const char* dp_name, const char* type) {
      engine::DataPackId id;
      id.set_name(dp_name);
      id.set_engine_name(name);
      id.set_type(type);
      ids.push_back(id);
    };
    add("detections", "json");
    add("camera_img", "json");
    add("camera", "convoy.data.Camera");
    add("boxes", "json");  // used by the ground_truth backend, ignored by the others
    return ids;
  }

  int64_t step(int64_t duration_ns) override {
    time_ns_ += duration_ns;
    if (!pending_) return time_ns_;
    pending_ = false;
    auto t0 = std::chrono::steady_clock::now();
    std::vector<detector::Detection> dets;
    if (backend_ == "ground_truth") {
      dets = detector::detections_from_boxes(pending_boxes_, names_);
      detector::sort_by_confidence(&dets);
      width_ = pending_boxes_.value("width", width_);
      height_ = pending_boxes_.value("height", height_);
    } else {
      width_ = pending_image_.cols;
      height_ = pending_image_.rows;
      dets = yolo_ ? yolo_->detect(pending_image_) : hog_->detect(pending_image_);
    }
    auto t1 = std::chrono::steady_clock::now();
    ++frame_;
    result_ = {{"frame", frame_},
               {"time_ns", time_ns_},
               {"width", width_},
               {"height", height_},
               {"inference_ms", std::chrono::duration<double, std::milli>(t1 - t0).count()},
               {"detections", detector::detections_json(dets)}};
    return time_ns_;
  }

  void set_datapack(const engine::DataPack& dp) override {
    if (dp.payload_case() == engine::DataPack::PAYLOAD_NOT_SET) return;
    if (backend_ == "ground_truth") {
      if (dp.payload_case() == engine::DataPack::kJsonMsgpack) {
        const std::string& raw = dp.json_msgpack();
        nlohmann::json j = nlohmann::json::from_msgpack(raw.begin(), raw.end());
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

  void get_datapack(const engine::DataPackId& id, engine::DataPack* out) override {
    if (id.name() != "detections") {
      throw std::runtime_error("engine '" + name_ + "' has no datapack '" + id.name() +
                               "' (it provides \"detections\")");
    }
    out->mutable_id()->set_type("json");
    if (result_.is_null()) return;
    std::vector<uint8_t> bytes = nlohmann::json::to_msgpack(result_);
    out->set_json_msgpack(std::string(bytes.begin(), bytes.end()));
  }

  void reset() override {
    time_ns_ = 0;
    frame_ = 0;
    pending_ = false;
    result_ = nullptr;
  }

 private:
  std::string name_;
  std::string backend_;
  std::vector<std::string> names_;
  std::unique_ptr<detector::YoloDetector> yolo_;
  std::unique_ptr<detector::HogDetector> hog_;
  int64_t time_ns_ = 0;
  int64_t frame_ = 0;
  bool pending_ = false;
  cv::Mat pending_image_;
  size_t last_image_hash_ = 0;
  cv::Size last_image_size_;
  nlohmann::json pending_boxes_;
  int width_ = 0, height_ = 0;
  nlohmann::json result_;
};

}  // namespace convoy::engines
