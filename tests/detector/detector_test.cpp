// Tests of the detector engine: letterboxing, YOLO decoding and NMS as pure functions, image
// decoding from datapacks, the engine's backends, and YOLOv5/YOLOv8 ONNX models with fixed
// outputs built by make_models.py (run here with Debian's python3 and python3-onnx).
#include "detector.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <opencv2/imgproc.hpp>

#include "convoy/datapacks.pb.h"
#include "datapack/blobs.h"
#include "detector_engine.h"

namespace convoy::detector {
namespace {

constexpr float kBoxTol = 1e-3f;
constexpr float kConfTol = 1e-5f;

// A scratch folder of this process (ctest may run the tests in parallel processes).
std::filesystem::path temp_dir() {
  auto dir = std::filesystem::path(testing::TempDir()) /
             ("convoy_detector_test_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  return dir;
}

void expect_det(const Detection& d, const std::string& cls, int id, float conf, float x0, float y0,
                float x1, float y1) {
  EXPECT_EQ(d.class_name, cls);
  EXPECT_EQ(d.class_id, id);
  EXPECT_NEAR(d.confidence, conf, kConfTol);
  EXPECT_NEAR(d.x_min, x0, kBoxTol);
  EXPECT_NEAR(d.y_min, y0, kBoxTol);
  EXPECT_NEAR(d.x_max, x1, kBoxTol);
  EXPECT_NEAR(d.y_max, y1, kBoxTol);
}

TEST(Letterbox, Geometry) {
  Letterbox a = compute_letterbox(640, 480, 640);
  EXPECT_DOUBLE_EQ(a.scale, 1.0);
  EXPECT_EQ(a.pad_x, 0);
  EXPECT_EQ(a.pad_y, 80);
  Letterbox b = compute_letterbox(1280, 720, 640);
  EXPECT_DOUBLE_EQ(b.scale, 0.5);
  EXPECT_EQ(b.pad_x, 0);
  EXPECT_EQ(b.pad_y, 140);
  Letterbox c = compute_letterbox(480, 640, 640);
  EXPECT_EQ(c.pad_x, 80);
  EXPECT_EQ(c.pad_y, 0);
  Letterbox d = compute_letterbox(320, 240, 640);
  EXPECT_DOUBLE_EQ(d.scale, 2.0);
  EXPECT_EQ(d.pad_y, 80);
  // A rectangular network input (Convoy's detector): 736 x 480 into 448 x 288.
  Letterbox e = compute_letterbox(736, 480, 448, 288);
  EXPECT_NEAR(e.scale, 0.6, 1e-9);
  EXPECT_EQ(e.pad_x, 3);
  EXPECT_EQ(e.pad_y, 0);
  cv::Mat img(480, 736, CV_8UC3, cv::Scalar(10, 20, 30));
  Letterbox f;
  cv::Mat out = letterbox_image(img, 448, &f, 288);
  EXPECT_EQ(out.cols, 448);
  EXPECT_EQ(out.rows, 288);
  cv::Rect2f back = unletterbox({3.0f, 0.0f, 60.0f, 30.0f}, f, 736, 480);
  EXPECT_NEAR(back.x, 0.0, 1e-3);
  EXPECT_NEAR(back.width, 100.0, 1e-3);
  EXPECT_NEAR(back.height, 50.0, 1e-3);
}

TEST(Letterbox, ImagePaddedWith114) {
  cv::Mat img(480, 640, CV_8UC3, cv::Scalar(10, 20, 30));
  Letterbox lb;
  cv::Mat out = letterbox_image(img, 640, &lb);
  ASSERT_EQ(out.rows, 640);
  ASSERT_EQ(out.cols, 640);
  EXPECT_EQ(out.at<cv::Vec3b>(0, 0), cv::Vec3b(114, 114, 114));
  EXPECT_EQ(out.at<cv::Vec3b>(79, 300), cv::Vec3b(114, 114, 114));
  EXPECT_EQ(out.at<cv::Vec3b>(80, 300), cv::Vec3b(10, 20, 30));
  EXPECT_EQ(out.at<cv::Vec3b>(559, 639), cv::Vec3b(10, 20, 30));
  EXPECT_EQ(out.at<cv::Vec3b>(560, 0), cv::Vec3b(114, 114, 114));
}

TEST(Letterbox, BoxesScaledBackAndClipped) {
  Letterbox lb = compute_letterbox(320, 240, 640);  // scale 2, pad_y 80
  cv::Rect2f r = unletterbox({100, 180, 50, 40}, lb, 320, 240);
  EXPECT_FLOAT_EQ(r.x, 50);
  EXPECT_FLOAT_EQ(r.y, 50);
  EXPECT_FLOAT_EQ(r.width, 25);
  EXPECT_FLOAT_EQ(r.height, 20);
  cv::Rect2f c = unletterbox({600, 40, 100, 600}, lb, 320, 240);
  EXPECT_FLOAT_EQ(c.x, 300);
  EXPECT_FLOAT_EQ(c.y, 0);
  EXPECT_FLOAT_EQ(c.x + c.width, 320);
  EXPECT_FLOAT_EQ(c.y + c.height, 240);
}

cv::Mat v5_output() {
  int sizes[] = {1, 10, 7};  // 2 classes
  cv::Mat m(3, sizes, CV_32F, cv::Scalar(0));
  float rows[3][7] = {{100, 100, 20, 10, 0.5f, 0.9f, 0.1f},
                      {300, 200, 40, 40, 0.9f, 0.2f, 0.6f},
                      {10, 10, 4, 4, 0.3f, 0.5f, 0.5f}};  // 0.15: below
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 7; ++c) m.ptr<float>(0, r)[c] = rows[r][c];
  return m;
}

TEST(DecodeYolo, V5) {
  YoloVersion seen;
  auto d = decode_yolo(v5_output(), YoloVersion::kAuto, 0.25f, 2, &seen);
  EXPECT_EQ(seen, YoloVersion::kV5);
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(d[0].class_id, 0);
  EXPECT_NEAR(d[0].confidence, 0.45f, kConfTol);
  EXPECT_FLOAT_EQ(d[0].x_min, 90);
  EXPECT_FLOAT_EQ(d[0].y_min, 95);
  EXPECT_FLOAT_EQ(d[0].x_max, 110);
  EXPECT_FLOAT_EQ(d[0].y_max, 105);
  EXPECT_EQ(d[1].class_id, 1);
  EXPECT_NEAR(d[1].confidence, 0.54f, kConfTol);
  // Unknown class count: decided by the shape (more rows than columns: v5).
  decode_yolo(v5_output(), YoloVersion::kAuto, 0.25f, 0, &seen);
  EXPECT_EQ(seen, YoloVersion::kV5);
}

TEST(DecodeYolo, V8Transposed) {
  int sizes[] = {1, 6, 12};  // 2 classes, 12 anchors
  cv::Mat m(3, sizes, CV_32F, cv::Scalar(0));
  auto set = [&](int attr, int anchor, float v) { m.ptr<float>(0, attr)[anchor] = v; };
  for (int a : {3, 7}) {
    set(0, a, 50.f + a);
    set(1, a, 60);
    set(2, a, 10);
    set(3, a, 20);
  }
  set(5, 3, 0.8f);
  set(4, 7, 0.3f);
  set(5, 7, 0.1f);
  YoloVersion seen;
  auto d = decode_yolo(m, YoloVersion::kAuto, 0.25f, 2, &seen);
  EXPECT_EQ(seen, YoloVersion::kV8);
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(d[0].class_id, 1);
  EXPECT_FLOAT_EQ(d[0].confidence, 0.8f);
  EXPECT_FLOAT_EQ(d[0].x_min, 48);
  EXPECT_FLOAT_EQ(d[0].y_min, 50);
  EXPECT_FLOAT_EQ(d[0].x_max, 58);
  EXPECT_FLOAT_EQ(d[0].y_max, 70);
  EXPECT_EQ(d[1].class_id, 0);
  EXPECT_FLOAT_EQ(d[1].confidence, 0.3f);
  decode_yolo(m, YoloVersion::kAuto, 0.25f, 0, &seen);
  EXPECT_EQ(seen, YoloVersion::kV8);
}

TEST(Nms, PerClass) {
  std::vector<Detection> c(4);
  c[0] = {0, "", 0.6f, 0, 0, 100, 100};
  c[1] = {0, "", 0.9f, 5, 5, 105, 105};      // same class, IoU ~0.82: wins over c[0]
  c[2] = {1, "", 0.7f, 0, 0, 100, 100};      // other class, same box: kept
  c[3] = {0, "", 0.5f, 200, 200, 250, 250};  // same class, disjoint: kept
  auto k = nms_per_class(c, 0.25f, 0.45f);
  ASSERT_EQ(k.size(), 3u);
  EXPECT_FLOAT_EQ(k[0].confidence, 0.9f);
  EXPECT_EQ(k[1].class_id, 1);
  EXPECT_FLOAT_EQ(k[2].confidence, 0.5f);
  // A looser IoU threshold keeps both overlapping boxes.
  EXPECT_EQ(nms_per_class(c, 0.25f, 0.9f).size(), 4u);
}

TEST(ClassNames, CocoAndFile) {
  ASSERT_EQ(coco_class_names().size(), 80u);
  EXPECT_EQ(coco_class_names()[0], "person");
  EXPECT_EQ(coco_class_names()[79], "toothbrush");
  auto p = temp_dir() / "names.txt";
  std::ofstream(p) << "a\r\nb\n\n";
  EXPECT_EQ(read_class_names(p.string()), (std::vector<std::string>{"a", "b"}));
  EXPECT_THROW(read_class_names("/nonexistent/names.txt"), std::runtime_error);
}

// --- images from datapacks -------------------------------------------------------------

cv::Mat test_image(int h, int w) {
  cv::Mat img(h, w, CV_8UC3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) img.at<cv::Vec3b>(y, x) = cv::Vec3b(x % 256, y % 256, 7);
  return img;
}

std::string bytes_of(const cv::Mat& m) {
  return std::string(reinterpret_cast<const char*>(m.data), m.total() * m.elemSize());
}

// A datapack as an engine receives it, with inline blobs.
datapack::View in(const engine::DataPack& dp) { return {dp, datapack::inline_blob_reader()}; }

bool same(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0;
}

engine::DataPack camera_proto(const cv::Mat& img, bool as_blob) {
  engine::DataPack dp;
  dp.mutable_id()->set_name("camera");
  data::Camera cam;
  cam.set_image_height(img.rows);
  cam.set_image_width(img.cols);
  cam.set_image_depth(img.channels());
  if (as_blob) {
    datapack::InlineBlobWriter w;
    cam.set_image_blob(w.add(&dp, bytes_of(img)) + 1);
  } else {
    cam.set_image_data(bytes_of(img));
  }
  dp.mutable_proto()->set_type_name("convoy.data.Camera");
  cam.SerializeToString(dp.mutable_proto()->mutable_data());
  return dp;
}

std::vector<uint8_t> ndarray_header(const cv::Mat& img) {
  std::vector<uint8_t> h{3, '|', 'u', '1', 3};
  for (uint64_t d : {uint64_t(img.rows), uint64_t(img.cols), uint64_t(img.channels())})
    for (int k = 0; k < 8; ++k) h.push_back(static_cast<uint8_t>(d >> (8 * k)));
  return h;
}

// camera_img as the report's TF sends it; frame: 0 list, 1 ext 1, 2 ext 2 (blob).
engine::DataPack camera_json(const cv::Mat& img, int frame_kind) {
  engine::DataPack dp;
  dp.mutable_id()->set_name("camera_img");
  dp.mutable_id()->set_type("json");
  nlohmann::json j = {{"c_imageHeight", img.rows}, {"c_imageWidth", img.cols}};
  std::string raw = bytes_of(img);
  if (frame_kind == 0) {
    j["current_image_frame"] = std::vector<int>(raw.begin(), raw.end());
    for (size_t i = 0; i < raw.size(); ++i)
      j["current_image_frame"][i] = static_cast<int>(static_cast<uint8_t>(raw[i]));
  } else if (frame_kind == 1) {
    auto b = ndarray_header(img);
    b.insert(b.end(), raw.begin(), raw.end());
    j["current_image_frame"] = nlohmann::json::binary(b, 1);
  } else {
    datapack::InlineBlobWriter w;
    uint32_t index = w.add(&dp, raw);
    auto b = ndarray_header(img);
    for (int k = 3; k >= 0; --k) b.push_back(static_cast<uint8_t>(index >> (8 * k)));
    j["current_image_frame"] = nlohmann::json::binary(b, 2);
  }
  auto m = nlohmann::json::to_msgpack(j);
  dp.set_json_msgpack(std::string(m.begin(), m.end()));
  return dp;
}

TEST(ImageFromDatapack, CameraProto) {
  cv::Mat img = test_image(30, 40);
  EXPECT_TRUE(same(image_from_datapack(in(camera_proto(img, false))), img));
  EXPECT_TRUE(same(image_from_datapack(in(camera_proto(img, true))), img));
  cv::Mat grey(5, 6, CV_8UC1, cv::Scalar(9));
  EXPECT_TRUE(same(image_from_datapack(in(camera_proto(grey, false))), grey));
  EXPECT_TRUE(image_from_datapack(in(engine::DataPack())).empty());
}

TEST(ImageFromDatapack, JsonListAndNumpy) {
  cv::Mat img = test_image(12, 16);
  for (int kind : {0, 1, 2}) {
    SCOPED_TRACE(kind);
    EXPECT_TRUE(same(image_from_datapack(in(camera_json(img, kind))), img));
  }
}

TEST(ImageFromDatapack, BadSize) {
  cv::Mat img = test_image(12, 16);
  engine::DataPack dp = camera_json(img, 1);
  nlohmann::json j = nlohmann::json::from_msgpack(dp.json_msgpack());
  j["c_imageWidth"] = 17;
  auto m = nlohmann::json::to_msgpack(j);
  dp.set_json_msgpack(std::string(m.begin(), m.end()));
  EXPECT_THROW(image_from_datapack(in(dp)), std::runtime_error);
}

// --- the ONNX models of make_models.py ---------------------------------------------------

class OnnxModels : public testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = (temp_dir() / "models").string();
    std::string cmd = std::string(DETECTOR_PYTHON) + " " + DETECTOR_MAKE_MODELS + " " + dir_;
    ok_ = std::system(cmd.c_str()) == 0;
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    std::filesystem::remove_all(temp_dir(), ec);
  }
  void SetUp() override {
    ASSERT_TRUE(ok_) << "make_models.py failed (needs " << DETECTOR_PYTHON << " with python3-onnx)";
  }
  static std::string file(const std::string& name) { return dir_ + "/" + name; }
  static YoloOptions v5_options() {
    YoloOptions o;
    o.model_path = file("yolov5_test.onnx");
    o.class_names = read_class_names(file("classes3.txt"));
    return o;
  }
  static inline std::string dir_;
  static inline bool ok_ = false;
};

TEST_F(OnnxModels, YoloV5Letterboxed640x480) {
  YoloDetector det(v5_options());
  auto d = det.detect(test_image(480, 640));
  ASSERT_EQ(d.size(), 3u);  // duplicate car suppressed, dog 0.2 below threshold
  expect_det(d[0], "dog", 2, 0.95f, 550, 430, 640, 480);
  expect_det(d[1], "car", 0, 0.72f, 75, 100, 125, 140);
  expect_det(d[2], "person", 1, 0.63f, 75, 100, 125, 140);
}

TEST_F(OnnxModels, YoloV5ScaledBack320x240) {
  YoloOptions o = v5_options();
  o.version = YoloVersion::kV5;
  YoloDetector det(o);
  auto d = det.detect(test_image(240, 320));
  ASSERT_EQ(d.size(), 3u);
  expect_det(d[0], "dog", 2, 0.95f, 275, 215, 320, 240);
  expect_det(d[1], "car", 0, 0.72f, 37.5f, 50, 62.5f, 70);
  expect_det(d[2], "person", 1, 0.63f, 37.5f, 50, 62.5f, 70);
}

TEST_F(OnnxModels, YoloV8Coco) {
  for (YoloVersion v : {YoloVersion::kAuto, YoloVersion::kV8}) {
    YoloOptions o;
    o.model_path = file("yolov8_test.onnx");
    o.version = v;
    YoloDetector det(o);
    auto d = det.detect(test_image(480, 640));
    ASSERT_EQ(d.size(), 2u);
    expect_det(d[0], "person", 0, 0.9f, 220, 190, 420, 290);
    expect_det(d[1], "car", 2, 0.5f, 80, 0, 120, 40);
  }
}

TEST_F(OnnxModels, YoloThresholds) {
  YoloOptions o = v5_options();
  o.conf_threshold = 0.1f;  // the dog at 0.2 now passes
  o.nms_threshold = 0.9f;   // and the duplicate car stays
  YoloDetector det(o);
  auto d = det.detect(test_image(480, 640));
  ASSERT_EQ(d.size(), 5u);
  EXPECT_NEAR(d[2].confidence, 0.64f, kConfTol);  // the duplicate car
  EXPECT_NEAR(d[4].confidence, 0.2f, kConfTol);
}

TEST_F(OnnxModels, Errors) {
  YoloOptions o;
  try {
    YoloDetector det(o);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "Backend yolo needs ModelPath");
  }
  auto bad = temp_dir() / "not_a_model.onnx";
  std::ofstream(bad) << "garbage";
  o.model_path = bad.string();
  try {
    YoloDetector det(o);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(
        std::string(e.what()).find("ModelPath '" + bad.string() + "': cannot read ONNX model"),
        std::string::npos)
        << e.what();
  }
}

// --- the engine -------------------------------------------------------------------------

nlohmann::json detections_of(engines::DetectorEngine& e) {
  engine::DataPackId id;
  id.set_name("detections");
  engine::DataPack dp;
  *dp.mutable_id() = id;
  datapack::InlineBlobWriter blobs;
  datapack::Builder out(&dp, blobs);
  e.get_datapack(id, out);
  if (dp.payload_case() != engine::DataPack::kJsonMsgpack) return nullptr;
  EXPECT_EQ(dp.id().type(), "json");
  return nlohmann::json::from_msgpack(dp.json_msgpack());
}

TEST_F(OnnxModels, EngineYoloRunsOncePerNewImage) {
  engines::DetectorEngine e;
  auto ids = e.initialize("det",
                          {{"Backend", "yolo"},
                           {"ModelPath", file("yolov5_test.onnx")},
                           {"ClassNamesFile", file("classes3.txt")}},
                          10'000'000);
  ASSERT_FALSE(ids.empty());
  EXPECT_EQ(ids[0].name(), "detections");
  EXPECT_TRUE(detections_of(e).is_null());  // nothing yet
  e.step(10'000'000);
  EXPECT_TRUE(detections_of(e).is_null());
  const engine::DataPack input1 = camera_json(test_image(480, 640), 2);

  e.set_datapack(in(input1));
  e.step(10'000'000);
  nlohmann::json j = detections_of(e);
  ASSERT_TRUE(j.is_object());
  EXPECT_EQ(j["frame"], 1);
  EXPECT_EQ(j["time_ns"], 20'000'000);
  EXPECT_EQ(j["width"], 640);
  EXPECT_EQ(j["height"], 480);
  EXPECT_TRUE(j.contains("inference_ms"));
  ASSERT_EQ(j["detections"].size(), 3u);
  EXPECT_EQ(j["detections"][0]["class"], "dog");
  EXPECT_EQ(j["detections"][0]["class_id"], 2);
  EXPECT_NEAR(j["detections"][1]["confidence"].get<double>(), 0.72, 1e-5);
  EXPECT_NEAR(j["detections"][1]["y_min"].get<double>(), 100, 1e-3);
  e.step(10'000'000);  // no new image: same detections
  EXPECT_EQ(detections_of(e)["frame"], 1);
  EXPECT_EQ(detections_of(e)["time_ns"], 20'000'000);
  const engine::DataPack input2 = camera_json(test_image(480, 640), 2);  // the same image again

  e.set_datapack(in(input2));
  e.step(10'000'000);
  EXPECT_EQ(detections_of(e)["frame"], 1);  // not detected again
  cv::Mat changed = test_image(480, 640);
  changed.at<cv::Vec3b>(479, 639)[0] ^= 1;  // one pixel differs: a new image
  const engine::DataPack input3 = camera_json(changed, 2);

  e.set_datapack(in(input3));
  e.step(10'000'000);
  EXPECT_EQ(detections_of(e)["frame"], 2);
  const engine::DataPack input4 = camera_proto(test_image(240, 320), true);

  e.set_datapack(in(input4));
  e.step(10'000'000);
  j = detections_of(e);
  EXPECT_EQ(j["frame"], 3);
  EXPECT_EQ(j["width"], 320);
  EXPECT_NEAR(j["detections"][1]["x_min"].get<double>(), 37.5, 1e-3);
}

TEST(Engine, GroundTruthPassthrough) {
  engines::DetectorEngine e;
  e.initialize("det", {{"Backend", "ground_truth"}}, 1000);
  nlohmann::json boxes = {{"width", 320},
                          {"height", 240},
                          {"boxes",
                           {{{"model", "car_1"},
                             {"class", "car"},
                             {"instance", 1},
                             {"x_min", 10},
                             {"y_min", 20},
                             {"x_max", 30},
                             {"y_max", 40},
                             {"pixels", 300}},
                            {{"model", "ped"},
                             {"class", "pedestrian"},
                             {"instance", 2},
                             {"x_min", 1},
                             {"y_min", 2},
                             {"x_max", 3},
                             {"y_max", 4},
                             {"pixels", 4}}}}};
  engine::DataPack dp;
  dp.mutable_id()->set_name("boxes");
  auto m = nlohmann::json::to_msgpack(boxes);
  dp.set_json_msgpack(std::string(m.begin(), m.end()));
  e.set_datapack(in(dp));
  e.step(1000);
  nlohmann::json j = detections_of(e);
  ASSERT_TRUE(j.is_object());
  EXPECT_EQ(j["width"], 320);
  EXPECT_EQ(j["height"], 240);
  ASSERT_EQ(j["detections"].size(), 2u);
  EXPECT_EQ(j["detections"][0]["class"], "car");
  EXPECT_EQ(j["detections"][0]["class_id"], 2);
  EXPECT_EQ(j["detections"][0]["confidence"], 1.0);
  EXPECT_EQ(j["detections"][0]["x_max"], 30);
  EXPECT_EQ(j["detections"][1]["class_id"], -1);
}

TEST(Engine, AnUnknownDatapackComesBackEmpty) {
  engines::DetectorEngine e;
  e.initialize("det", nlohmann::json::object(), 1000);
  for (const char* name : {"no_such_datapack", "camera", "detections"}) {
    engine::DataPackId id;
    id.set_name(name);
    engine::DataPack dp;
    *dp.mutable_id() = id;
    datapack::InlineBlobWriter blobs;
    datapack::Builder out(&dp, blobs);
    EXPECT_NO_THROW(e.get_datapack(id, out)) << name;
    EXPECT_EQ(dp.payload_case(), engine::DataPack::PAYLOAD_NOT_SET) << name;
  }
}

TEST(Engine, BackendsComeFromOneTable) {
  EXPECT_EQ(detector::backend_names(),
            (std::vector<std::string>{"convoy", "ground_truth", "hog", "yolo"}));
  // The default: Convoy's own model (share/convoy/models/detector), from the image.
  EXPECT_EQ(detector::make_backend(nlohmann::json::object())->input(),
            detector::BackendInput::kImage);
  auto truth = detector::make_backend({{"Backend", "ground_truth"}});
  EXPECT_EQ(truth->input(), detector::BackendInput::kGroundTruth);
  try {
    detector::make_backend({{"Backend", "convoy"}, {"ModelPath", "/nonexistent/model.onnx"}});
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no model at /nonexistent/model.onnx"), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(detector::make_backend({{"Backend", "hog"}})->input(), detector::BackendInput::kImage);
  try {
    detector::make_backend({{"Backend", "ssd"}});
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(),
                 "Backend 'ssd': must be one of \"convoy\", \"ground_truth\", \"hog\", \"yolo\"");
  }
}

TEST(Engine, ConfigErrors) {
  engines::DetectorEngine a;
  try {
    a.initialize("det", {{"Backend", "yolo"}}, 1000);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "Backend yolo needs ModelPath");
  }
  engines::DetectorEngine b;
  EXPECT_THROW(b.initialize("det", {{"Backend", "ssd"}}, 1000), std::runtime_error);
  engines::DetectorEngine c;
  EXPECT_THROW(c.initialize("det", {{"Backend", "yolo"}, {"ModelPath", "/nonexistent.onnx"}}, 1000),
               std::runtime_error);
}

TEST(Engine, HogOnSyntheticImage) {
  engines::DetectorEngine e;
  e.initialize("det", {{"Backend", "hog"}}, 1000);
  cv::Mat img(240, 320, CV_8UC3, cv::Scalar(200, 200, 200));
  // A dark upright figure: HOG may or may not fire; the engine must run and report.
  cv::rectangle(img, cv::Rect(140, 60, 40, 120), cv::Scalar(20, 20, 20), cv::FILLED);
  cv::circle(img, cv::Point(160, 45), 15, cv::Scalar(20, 20, 20), cv::FILLED);
  const engine::DataPack input5 = camera_json(img, 1);

  e.set_datapack(in(input5));
  e.step(1000);
  nlohmann::json j = detections_of(e);
  ASSERT_TRUE(j.is_object());
  EXPECT_EQ(j["frame"], 1);
  for (const auto& d : j["detections"]) EXPECT_EQ(d["class"], "person");
}

}  // namespace
}  // namespace convoy::detector
