// Object detection for the detector engine: image decoding from datapacks, YOLO
// (ONNX through OpenCV DNN) decoding with letterboxing and per-class NMS, the HOG people
// detector, and the ground-truth passthrough. Pure functions here; the engine class lives in
// detector_engine.cpp.
#pragma once

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>
#include <opencv2/objdetect.hpp>
#include <string>
#include <vector>

#include "convoy/engine.pb.h"

namespace convoy::detector {

struct Detection {
  int class_id = -1;
  std::string class_name;
  float confidence = 0;
  float x_min = 0, y_min = 0, x_max = 0, y_max = 0;  // pixels of the original image
};

// Where the original image lies inside the square network input.
struct Letterbox {
  double scale = 1;  // network pixels per image pixel
  int pad_x = 0;     // left padding, network pixels
  int pad_y = 0;     // top padding
  int size = 640;    // network input side
};

enum class YoloVersion { kAuto, kV5, kV8 };
YoloVersion parse_yolo_version(const std::string& s);  // "auto" | "v5" | "v8"

// The 80 COCO class names, in YOLO order.
const std::vector<std::string>& coco_class_names();
// One name per line (blank lines at the end ignored); throws naming the file.
std::vector<std::string> read_class_names(const std::string& path);

// Letterbox transform for an image of `width` x `height` into a `size` square (keeps the
// aspect ratio, centres the image).
Letterbox compute_letterbox(int width, int height, int size);
// Resizes and pads `image` (pad value 114) per compute_letterbox.
cv::Mat letterbox_image(const cv::Mat& image, int size, Letterbox* lb);
// Maps a box in network coordinates back to the original image, clipped to it.
cv::Rect2f unletterbox(const cv::Rect2f& box, const Letterbox& lb, int width, int height);

// Decodes a raw YOLO output (leading singleton dimensions are ignored, the rest is
// [N, 5+C] for v5 or [4+C, N] for v8). `num_classes` (0: unknown) helps the auto detection.
// Returns candidates above `conf_threshold`, boxes in network coordinates.
std::vector<Detection> decode_yolo(const cv::Mat& output, YoloVersion version, float conf_threshold,
                                   int num_classes = 0, YoloVersion* detected = nullptr);
// Per-class non-maximum suppression (cv::dnn::NMSBoxes); result sorted by confidence desc.
std::vector<Detection> nms_per_class(const std::vector<Detection>& candidates, float conf_threshold,
                                     float nms_threshold);
void sort_by_confidence(std::vector<Detection>* dets);
// Fills class_name from `names` ("class_<k>" when out of range).
void name_classes(std::vector<Detection>* dets, const std::vector<std::string>& names);

struct YoloOptions {
  std::string model_path;
  std::vector<std::string> class_names = coco_class_names();
  int input_size = 640;
  float conf_threshold = 0.25f;
  float nms_threshold = 0.45f;
  YoloVersion version = YoloVersion::kAuto;
};

class YoloDetector {
 public:
  // Throws "ModelPath '<path>': cannot read ONNX model: ..." on failure.
  explicit YoloDetector(YoloOptions options);
  // `image`: RGB (CV_8UC3) or grey (CV_8UC1).
  std::vector<Detection> detect(const cv::Mat& image);
  const YoloOptions& options() const { return options_; }

 private:
  YoloOptions options_;
  cv::dnn::Net net_;
};

class HogDetector {
 public:
  HogDetector();
  std::vector<Detection> detect(const cv::Mat& image);

 private:
  cv::HOGDescriptor hog_;
};

// Ground-truth boxes datapack {"boxes": [{"class", "x_min", ...}]} -> detections with
// confidence 1; class_id is the index of the class in `names`, or -1.
std::vector<Detection> detections_from_boxes(const nlohmann::json& boxes,
                                             const std::vector<std::string>& names);

// The RGB (or grey) image of a camera datapack: a convoy.data.Camera protobuf, or a JSON
// datapack {c_imageHeight, c_imageWidth, current_image_frame}. Returns an empty Mat when
// the datapack holds no image (empty payload, zero size). Throws on malformed data.
cv::Mat image_from_datapack(const engine::DataPack& dp);

// The detections datapack body.
nlohmann::json detections_json(const std::vector<Detection>& dets);

}  // namespace convoy::detector
