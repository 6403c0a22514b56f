#include "detector.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "datapack/camera.h"
#include "datapack/json.h"

namespace convoy::detector {

YoloVersion parse_yolo_version(const std::string& s) {
  if (s == "auto" || s.empty()) return YoloVersion::kAuto;
  if (s == "v5") return YoloVersion::kV5;
  if (s == "v8") return YoloVersion::kV8;
  throw std::runtime_error("YoloVersion '" + s + "': must be \"auto\", \"v5\" or \"v8\"");
}

const std::vector<std::string>& coco_class_names() {
  static const std::vector<std::string> names = {"person",        "bicycle",      "car",
                                                 "motorcycle",    "airplane",     "bus",
                                                 "train",         "truck",        "boat",
                                                 "traffic light", "fire hydrant", "stop sign",
                                                 "parking meter", "bench",        "bird",
                                                 "cat",           "dog",          "horse",
                                                 "sheep",         "cow",          "elephant",
                                                 "bear",          "zebra",        "giraffe",
                                                 "backpack",      "umbrella",     "handbag",
                                                 "tie",           "suitcase",     "frisbee",
                                                 "skis",          "snowboard",    "sports ball",
                                                 "kite",          "baseball bat", "baseball glove",
                                                 "skateboard",    "surfboard",    "tennis racket",
                                                 "bottle",        "wine glass",   "cup",
                                                 "fork",          "knife",        "spoon",
                                                 "bowl",          "banana",       "apple",
                                                 "sandwich",      "orange",       "broccoli",
                                                 "carrot",        "hot dog",      "pizza",
                                                 "donut",         "cake",         "chair",
                                                 "couch",         "potted plant", "bed",
                                                 "dining table",  "toilet",       "tv",
                                                 "laptop",        "mouse",        "remote",
                                                 "keyboard",      "cell phone",   "microwave",
                                                 "oven",          "toaster",      "sink",
                                                 "refrigerator",  "book",         "clock",
                                                 "vase",          "scissors",     "teddy bear",
                                                 "hair drier",    "toothbrush"};
  return names;
}

std::vector<std::string> read_class_names(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("ClassNamesFile '" + path + "': cannot open");
  std::vector<std::string> names;
  std::string line;
  while (std::getline(in, line)) {
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\t'))
      line.pop_back();
    names.push_back(line);
  }
  while (!names.empty() && names.back().empty()) names.pop_back();
  if (names.empty()) throw std::runtime_error("ClassNamesFile '" + path + "': no class names");
  return names;
}

Letterbox compute_letterbox(int width, int height, int size, int size_h) {
  Letterbox lb;
  lb.size = size;
  lb.size_h = size_h > 0 ? size_h : size;
  lb.scale = std::min(static_cast<double>(size) / width, static_cast<double>(lb.size_h) / height);
  int new_w = static_cast<int>(std::lround(width * lb.scale));
  int new_h = static_cast<int>(std::lround(height * lb.scale));
  lb.pad_x = (size - new_w) / 2;
  lb.pad_y = (lb.size_h - new_h) / 2;
  return lb;
}

cv::Mat letterbox_image(const cv::Mat& image, int size, Letterbox* lb, int size_h,
                        const std::optional<InputGain>& gain) {
  *lb = compute_letterbox(image.cols, image.rows, size, size_h);
  int new_w = static_cast<int>(std::lround(image.cols * lb->scale));
  int new_h = static_cast<int>(std::lround(image.rows * lb->scale));
  cv::Mat resized;
  if (new_w == image.cols && new_h == image.rows)
    resized = image;
  else
    cv::resize(image, resized, cv::Size(new_w, new_h), 0, 0, cv::INTER_LINEAR);
  if (gain) resized = brighten_image(resized, *gain);
  cv::Mat out;
  cv::copyMakeBorder(resized, out, lb->pad_y, lb->size_h - new_h - lb->pad_y, lb->pad_x,
                     size - new_w - lb->pad_x, cv::BORDER_CONSTANT, cv::Scalar::all(114));
  return out;
}

cv::Rect2f unletterbox(const cv::Rect2f& box, const Letterbox& lb, int width, int height) {
  auto fx = [&](double x) {
    return static_cast<float>(std::clamp((x - lb.pad_x) / lb.scale, 0.0, double(width)));
  };
  auto fy = [&](double y) {
    return static_cast<float>(std::clamp((y - lb.pad_y) / lb.scale, 0.0, double(height)));
  };
  float x0 = fx(box.x), y0 = fy(box.y), x1 = fx(box.x + box.width), y1 = fy(box.y + box.height);
  return {x0, y0, x1 - x0, y1 - y0};
}

std::vector<Detection> decode_yolo(const cv::Mat& output, YoloVersion version, float conf_threshold,
                                   int num_classes, YoloVersion* detected) {
  // Drop leading singleton dimensions down to 2.
  std::vector<int> dims(output.size.p, output.size.p + output.dims);
  while (dims.size() > 2 && dims.front() == 1) dims.erase(dims.begin());
  if (dims.size() != 2)
    throw std::runtime_error("YOLO output has an unexpected shape (dims " +
                             std::to_string(output.dims) + ")");
  if (output.depth() != CV_32F) throw std::runtime_error("YOLO output is not float32");
  cv::Mat m =
      cv::Mat(dims[0], dims[1], CV_32F, const_cast<void*>(static_cast<const void*>(output.ptr())));
  if (!output.isContinuous()) m = m.clone();
  const int rows = m.rows, cols = m.cols;
  if (version == YoloVersion::kAuto) {
    if (num_classes > 0 && cols == 5 + num_classes && rows != 4 + num_classes)
      version = YoloVersion::kV5;
    else if (num_classes > 0 && rows == 4 + num_classes && cols != 5 + num_classes)
      version = YoloVersion::kV8;
    else
      version = rows < cols ? YoloVersion::kV8 : YoloVersion::kV5;
  }
  if (detected) *detected = version;
  cv::Mat pred;  // [N, attrs]
  if (version == YoloVersion::kV8)
    cv::transpose(m, pred);
  else
    pred = m;
  const int first_cls = version == YoloVersion::kV5 ? 5 : 4;
  if (pred.cols <= first_cls)
    throw std::runtime_error("YOLO output has " + std::to_string(pred.cols) +
                             " values per box, too few for " +
                             (version == YoloVersion::kV5 ? "v5" : "v8"));
  std::vector<Detection> out;
  for (int i = 0; i < pred.rows; ++i) {
    const float* r = pred.ptr<float>(i);
    int best = 0;
    float best_score = r[first_cls];
    for (int c = first_cls + 1; c < pred.cols; ++c) {
      if (r[c] > best_score) {
        best_score = r[c];
        best = c - first_cls;
      }
    }
    float score = version == YoloVersion::kV5 ? r[4] * best_score : best_score;
    if (!(score > conf_threshold)) continue;
    Detection d;
    d.class_id = best;
    d.confidence = score;
    d.x_min = r[0] - r[2] / 2;
    d.y_min = r[1] - r[3] / 2;
    d.x_max = r[0] + r[2] / 2;
    d.y_max = r[1] + r[3] / 2;
    out.push_back(d);
  }
  return out;
}

void sort_by_confidence(std::vector<Detection>* dets) {
  std::stable_sort(dets->begin(), dets->end(), [](const Detection& a, const Detection& b) {
    return a.confidence > b.confidence;
  });
}

std::vector<Detection> nms_per_class(const std::vector<Detection>& candidates, float conf_threshold,
                                     float nms_threshold) {
  std::map<int, std::vector<size_t>> by_class;
  for (size_t i = 0; i < candidates.size(); ++i) by_class[candidates[i].class_id].push_back(i);
  std::vector<Detection> kept;
  for (const auto& [cls, idx] : by_class) {
    std::vector<cv::Rect2d> boxes;
    std::vector<float> scores;
    for (size_t i : idx) {
      const Detection& d = candidates[i];
      boxes.emplace_back(d.x_min, d.y_min, d.x_max - d.x_min, d.y_max - d.y_min);
      scores.push_back(d.confidence);
    }
    std::vector<int> keep;
    // NMSBoxes also drops scores <= the threshold (which must not be negative).
    cv::dnn::NMSBoxes(boxes, scores, std::max(conf_threshold, 0.0f), nms_threshold, keep);
    for (int k : keep) kept.push_back(candidates[idx[k]]);
  }
  sort_by_confidence(&kept);
  return kept;
}

void name_classes(std::vector<Detection>* dets, const std::vector<std::string>& names) {
  for (auto& d : *dets) {
    if (d.class_id >= 0 && static_cast<size_t>(d.class_id) < names.size())
      d.class_name = names[d.class_id];
    else
      d.class_name = "class_" + std::to_string(d.class_id);
  }
}

YoloDetector::YoloDetector(YoloOptions options) : options_(std::move(options)) {
  if (options_.model_path.empty()) throw std::runtime_error("Backend yolo needs ModelPath");
  if (!std::filesystem::exists(options_.model_path))
    throw std::runtime_error("ModelPath '" + options_.model_path + "': no such file");
  if (options_.input_size <= 0 || options_.input_size % 32 != 0)
    throw std::runtime_error("InputSize " + std::to_string(options_.input_size) +
                             ": must be a positive multiple of 32");
  if (options_.input_height < 0 || options_.input_height % 32 != 0)
    throw std::runtime_error("input height " + std::to_string(options_.input_height) +
                             ": must be a positive multiple of 32");
  try {
    net_ = cv::dnn::readNetFromONNX(options_.model_path);
  } catch (const cv::Exception& e) {
    throw std::runtime_error("ModelPath '" + options_.model_path +
                             "': cannot read ONNX model: " + e.what());
  }
  if (net_.empty())
    throw std::runtime_error("ModelPath '" + options_.model_path +
                             "': cannot read ONNX model: empty network");
  net_.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  net_.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
}

std::vector<Detection> YoloDetector::detect(const cv::Mat& image) {
  cv::Mat rgb = image;
  if (image.channels() == 1) cv::cvtColor(image, rgb, cv::COLOR_GRAY2RGB);
  Letterbox lb;
  cv::Mat input =
      letterbox_image(rgb, options_.input_size, &lb, options_.input_height, options_.gain);
  cv::Mat blob =
      cv::dnn::blobFromImage(input, 1.0 / 255.0, cv::Size(), cv::Scalar(), false, false, CV_32F);
  net_.setInput(blob);
  cv::Mat output;
  try {
    output = net_.forward();
  } catch (const cv::Exception& e) {
    throw std::runtime_error("ModelPath '" + options_.model_path +
                             "': inference failed: " + e.what());
  }
  auto candidates = decode_yolo(output, options_.version, options_.conf_threshold,
                                static_cast<int>(options_.class_names.size()));
  auto dets = nms_per_class(candidates, options_.conf_threshold, options_.nms_threshold);
  for (auto& d : dets) {
    cv::Rect2f r = unletterbox({d.x_min, d.y_min, d.x_max - d.x_min, d.y_max - d.y_min}, lb,
                               image.cols, image.rows);
    d.x_min = r.x;
    d.y_min = r.y;
    d.x_max = r.x + r.width;
    d.y_max = r.y + r.height;
  }
  name_classes(&dets, options_.class_names);
  return dets;
}

HogDetector::HogDetector() { hog_.setSVMDetector(cv::HOGDescriptor::getDefaultPeopleDetector()); }

std::vector<Detection> HogDetector::detect(const cv::Mat& image) {
  cv::Mat grey;
  if (image.channels() == 3)
    cv::cvtColor(image, grey, cv::COLOR_RGB2GRAY);
  else
    grey = image;
  std::vector<Detection> dets;
  if (grey.cols < hog_.winSize.width || grey.rows < hog_.winSize.height) return dets;
  std::vector<cv::Rect> found;
  std::vector<double> weights;
  hog_.detectMultiScale(grey, found, weights);
  for (size_t i = 0; i < found.size(); ++i) {
    cv::Rect r = found[i] & cv::Rect(0, 0, image.cols, image.rows);
    Detection d;
    d.class_id = 0;
    d.class_name = "person";
    d.confidence = i < weights.size() ? static_cast<float>(weights[i]) : 1.0f;
    d.x_min = static_cast<float>(r.x);
    d.y_min = static_cast<float>(r.y);
    d.x_max = static_cast<float>(r.x + r.width);
    d.y_max = static_cast<float>(r.y + r.height);
    dets.push_back(d);
  }
  sort_by_confidence(&dets);
  return dets;
}

std::vector<Detection> detections_from_boxes(const nlohmann::json& j,
                                             const std::vector<std::string>& names) {
  std::vector<Detection> dets;
  const nlohmann::json& boxes = j.is_object() ? j.value("boxes", nlohmann::json::array()) : j;
  if (!boxes.is_array()) throw std::runtime_error("datapack 'boxes': \"boxes\" is not a list");
  for (const auto& b : boxes) {
    Detection d;
    d.class_name = b.value("class", std::string());
    auto it = std::find(names.begin(), names.end(), d.class_name);
    d.class_id = it == names.end() ? -1 : static_cast<int>(it - names.begin());
    d.confidence = 1.0f;
    d.x_min = b.value("x_min", 0.0f);
    d.y_min = b.value("y_min", 0.0f);
    d.x_max = b.value("x_max", 0.0f);
    d.y_max = b.value("y_max", 0.0f);
    dets.push_back(d);
  }
  return dets;
}

namespace {

// An image of `bytes` bytes of pixels: wrapped in place (no copy) for 1 or 3 bytes a pixel,
// converted for 4. Empty for a zero size.
cv::Mat wrap_image(int height, int width, std::string_view bytes, const std::string& what) {
  if (height <= 0 || width <= 0 || bytes.empty()) return {};
  const size_t pixels = static_cast<size_t>(height) * width;
  if (bytes.size() % pixels != 0)
    throw std::runtime_error(what + ": " + std::to_string(bytes.size()) + " bytes for a " +
                             std::to_string(width) + "x" + std::to_string(height) + " image");
  const size_t depth = bytes.size() / pixels;
  auto* data = reinterpret_cast<uint8_t*>(const_cast<char*>(bytes.data()));
  if (depth == 1 || depth == 3) return cv::Mat(height, width, depth == 1 ? CV_8UC1 : CV_8UC3, data);
  if (depth == 4) {
    cv::Mat out;
    cv::cvtColor(cv::Mat(height, width, CV_8UC4, data), out, cv::COLOR_RGBA2RGB);
    return out;
  }
  throw std::runtime_error(what + ": unsupported image depth " + std::to_string(depth));
}

cv::Mat image_from_json(const datapack::View& dp) {
  const nlohmann::json j = datapack::read_json(dp);
  const std::string what = dp.describe();
  if (!j.is_object() || !j.contains("current_image_frame"))
    throw std::runtime_error(what + ": needs c_imageHeight, c_imageWidth, current_image_frame");
  int h = j.value("c_imageHeight", 0);
  int w = j.value("c_imageWidth", 0);
  const auto& frame = j["current_image_frame"];
  if (frame.is_array()) {
    std::string bytes;
    bytes.reserve(frame.size());
    for (const auto& v : frame) bytes.push_back(static_cast<char>(v.get<int>()));
    return wrap_image(h, w, bytes, what).clone();
  }
  if (!frame.is_binary())
    throw std::runtime_error(what + ": current_image_frame must be a list or a numpy array");
  const datapack::NdarrayRef array = datapack::read_ndarray(dp, frame);
  if (!datapack::is_uint8(array.header.dtype))
    throw std::runtime_error(what + ": current_image_frame dtype '" + array.header.dtype +
                             "' is not supported (needs uint8)");
  if (array.header.shape.size() >= 2 && (h <= 0 || w <= 0)) {
    h = static_cast<int>(array.header.shape[0]);
    w = static_cast<int>(array.header.shape[1]);
  }
  cv::Mat img = wrap_image(h, w, array.data, what);
  // Inline array bytes live in `j`, which goes now; a blob's stay.
  return frame.get_binary().subtype() == datapack::kNdarrayExtType ? img.clone() : img;
}

}  // namespace

cv::Mat image_from_datapack(const datapack::View& dp) {
  if (dp.is_proto()) {
    const datapack::CameraImage img = datapack::read_camera(dp);
    cv::Mat mat = wrap_image(static_cast<int>(img.height), static_cast<int>(img.width), img.pixels,
                             dp.describe());
    return img.owned.empty() ? mat : mat.clone();  // a small frame's pixels live in `img`
  }
  if (dp.is_json()) return image_from_json(dp);
  return {};
}

std::vector<Detection> GroundTruthPassthrough::detect(const cv::Mat&, const nlohmann::json& boxes) {
  std::vector<Detection> dets = detections_from_boxes(boxes, names_);
  sort_by_confidence(&dets);
  return dets;
}

namespace {
using BackendFactory = std::unique_ptr<Backend> (*)(const nlohmann::json& config,
                                                    std::vector<std::string> names);
const std::map<std::string, BackendFactory>& backends() {
  static const std::map<std::string, BackendFactory> table = {
      {"ground_truth",
       [](const nlohmann::json&, std::vector<std::string> names) -> std::unique_ptr<Backend> {
         return std::make_unique<GroundTruthPassthrough>(std::move(names));
       }},
      {"yolo",
       [](const nlohmann::json& config,
          std::vector<std::string> names) -> std::unique_ptr<Backend> {
         YoloOptions o;
         o.model_path = config.value("ModelPath", std::string());
         o.class_names = std::move(names);
         o.input_size = config.value("InputSize", 640);
         o.conf_threshold = config.value("ConfidenceThreshold", 0.25f);
         o.nms_threshold = config.value("NmsThreshold", 0.45f);
         o.version = parse_yolo_version(config.value("YoloVersion", std::string("auto")));
         return std::make_unique<YoloDetector>(std::move(o));
       }},
      {"hog",
       [](const nlohmann::json&, std::vector<std::string>) -> std::unique_ptr<Backend> {
         return std::make_unique<HogDetector>();
       }},
      // Convoy's own detector (models/detector, trained by tools/detector/train.py): YOLOv8
      // layout, its input size from model.json, its classes from classes.txt.
      {"convoy",
       [](const nlohmann::json& config,
          std::vector<std::string> names) -> std::unique_ptr<Backend> {
         YoloOptions o;
         o.model_path = config.value("ModelPath", std::string());
         const std::filesystem::path dir = std::filesystem::path(o.model_path).parent_path();
         std::ifstream in(dir / "model.json");
         if (!in) throw std::runtime_error("Backend convoy: no model.json next to " + o.model_path);
         nlohmann::json meta;
         try {
           meta = nlohmann::json::parse(in);
           o.input_size = meta.at("input_width").get<int>();
           o.input_height = meta.at("input_height").get<int>();
           if (o.input_size <= 0 || o.input_size % 32 || o.input_height <= 0 || o.input_height % 32)
             throw std::runtime_error(
                 "input_width and input_height must be positive multiples of 32");
           o.gain = input_gain_from_meta(meta);
         } catch (const std::exception& e) {
           throw std::runtime_error("Backend convoy: " + (dir / "model.json").string() + ": " +
                                    e.what());
         }
         o.class_names = std::move(names);
         o.conf_threshold = config.value("ConfidenceThreshold", 0.25f);
         o.nms_threshold = config.value("NmsThreshold", 0.45f);
         o.version = YoloVersion::kV8;
         return std::make_unique<YoloDetector>(std::move(o));
       }},
  };
  return table;
}
}  // namespace

std::vector<std::string> backend_names() {
  std::vector<std::string> out;
  for (const auto& [name, f] : backends()) out.push_back(name);
  return out;
}

std::string convoy_model_dir() {
  const char* share = std::getenv("CONVOY_SHARE_DIR");
  return (std::filesystem::path(share && *share ? share : CONVOY_DEFAULT_SHARE_DIR) / "models" /
          "detector")
      .string();
}

std::unique_ptr<Backend> make_backend(const nlohmann::json& in) {
  nlohmann::json config = in;
  const std::string name = config.value("Backend", std::string("convoy"));
  if (name == "convoy") {
    // Convoy's model and its class names, unless the config names others.
    if (!config.contains("ModelPath"))
      config["ModelPath"] = convoy_model_dir() + "/convoy_detector.onnx";
    if (!config.contains("ClassNamesFile")) {
      const std::string model = config["ModelPath"].get<std::string>();
      config["ClassNamesFile"] =
          (std::filesystem::path(model).parent_path() / "classes.txt").string();
    }
    if (!std::filesystem::exists(config["ModelPath"].get<std::string>()))
      throw std::runtime_error("Backend convoy: no model at " +
                               config["ModelPath"].get<std::string>() +
                               " (tools/detector/train.py makes one; docs/perception.md)");
  }
  auto it = backends().find(name);
  if (it == backends().end()) {
    std::string known;
    for (const auto& n : backend_names()) known += (known.empty() ? "\"" : ", \"") + n + "\"";
    throw std::runtime_error("Backend '" + name + "': must be one of " + known);
  }
  const std::string names_file = config.value("ClassNamesFile", std::string());
  return it->second(config, names_file.empty() ? coco_class_names() : read_class_names(names_file));
}

nlohmann::json detections_json(const std::vector<Detection>& dets) {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& d : dets) {
    list.push_back({{"class", d.class_name},
                    {"class_id", d.class_id},
                    {"confidence", d.confidence},
                    {"x_min", d.x_min},
                    {"y_min", d.y_min},
                    {"x_max", d.x_max},
                    {"y_max", d.y_max}});
  }
  return list;
}

}  // namespace convoy::detector
