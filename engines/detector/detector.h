// Object detection for the detector engine: image decoding from datapacks, YOLO
// (ONNX through OpenCV DNN) decoding with letterboxing and per-class NMS, the HOG people
// detector, and the ground-truth passthrough. Pure functions here; the engine class lives in
// detector_engine.cpp.
#pragma once

#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>
#include <opencv2/objdetect.hpp>
#include <string>
#include <vector>

#include "datapack/datapack.h"
#include "input_gain.h"

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
  int size = 640;    // network input width
  int size_h = 640;  // network input height
};

enum class YoloVersion { kAuto, kV5, kV8 };
YoloVersion parse_yolo_version(const std::string& s);  // "auto" | "v5" | "v8"

// The 80 COCO class names, in YOLO order.
const std::vector<std::string>& coco_class_names();
// One name per line (blank lines at the end ignored); throws naming the file.
std::vector<std::string> read_class_names(const std::string& path);

// Letterbox transform for an image of `width` x `height` into a `size` square, or a
// `size` x `size_h` network input (keeps the aspect ratio, centres the image).
Letterbox compute_letterbox(int width, int height, int size, int size_h = 0);
// Resizes and pads `image` (pad value 114) per compute_letterbox; with `gain`, the resized
// image brightened (brighten_image) before the padding.
cv::Mat letterbox_image(const cv::Mat& image, int size, Letterbox* lb, int size_h = 0,
                        const std::optional<InputGain>& gain = std::nullopt);
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
  int input_size = 640;  // network input width
  int input_height = 0;  // its height; 0: input_size (square)
  float conf_threshold = 0.25f;
  float nms_threshold = 0.45f;
  YoloVersion version = YoloVersion::kAuto;
  std::optional<InputGain> gain;  // Convoy's models: model.json's "brighten"
};

// What a detector backend detects from.
enum class BackendInput { kImage, kGroundTruth };

// A detector backend: a camera image (or, for the ground-truth passthrough, the camera's
// ground-truth boxes) in, detections out.
class Backend {
 public:
  virtual ~Backend() = default;
  virtual BackendInput input() const { return BackendInput::kImage; }
  // `image` for kImage backends; `boxes` (the ::boxes datapack's JSON) for kGroundTruth.
  virtual std::vector<Detection> detect(const cv::Mat& image, const nlohmann::json& boxes) = 0;
};

// The backend named by the engine's config ("Backend", default "ground_truth"), built from
// the config's other keys. Throws naming the key on a bad value.
std::unique_ptr<Backend> make_backend(const nlohmann::json& config);
// The backend names make_backend knows.
std::vector<std::string> backend_names();

class YoloDetector final : public Backend {
 public:
  // Throws "ModelPath '<path>': cannot read ONNX model: ..." on failure.
  explicit YoloDetector(YoloOptions options);
  // `image`: RGB (CV_8UC3) or grey (CV_8UC1).
  std::vector<Detection> detect(const cv::Mat& image);
  std::vector<Detection> detect(const cv::Mat& image, const nlohmann::json&) override {
    return detect(image);
  }
  const YoloOptions& options() const { return options_; }

 private:
  YoloOptions options_;
  cv::dnn::Net net_;
};

class HogDetector final : public Backend {
 public:
  HogDetector();
  std::vector<Detection> detect(const cv::Mat& image);
  std::vector<Detection> detect(const cv::Mat& image, const nlohmann::json&) override {
    return detect(image);
  }

 private:
  cv::HOGDescriptor hog_;
};

// Ground-truth boxes datapack {"boxes": [{"class", "x_min", ...}]} -> detections with
// confidence 1; class_id is the index of the class in `names`, or -1.
std::vector<Detection> detections_from_boxes(const nlohmann::json& boxes,
                                             const std::vector<std::string>& names);

// Not a detector: passes the camera's ground-truth boxes through, labelled as ground truth.
class GroundTruthPassthrough final : public Backend {
 public:
  explicit GroundTruthPassthrough(std::vector<std::string> names) : names_(std::move(names)) {}
  BackendInput input() const override { return BackendInput::kGroundTruth; }
  std::vector<Detection> detect(const cv::Mat&, const nlohmann::json& boxes) override;

 private:
  std::vector<std::string> names_;
};

// The RGB (or grey) image of a camera datapack: a convoy.data.Camera protobuf, or a JSON
// datapack {c_imageHeight, c_imageWidth, current_image_frame}. Returns an empty Mat when
// the datapack holds no image (empty payload, zero size). Throws on malformed data.
// A frame in a blob is wrapped in place, without a copy: the Mat is valid as long as the
// datapack's blobs are (for an engine: until the end of the step that follows).
cv::Mat image_from_datapack(const datapack::View& dp);

// The detections datapack body.
nlohmann::json detections_json(const std::vector<Detection>& dets);

}  // namespace convoy::detector
