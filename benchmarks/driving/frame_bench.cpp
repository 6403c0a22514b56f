// Rendering plus detection run standalone, in one process, without the co-simulation: the
// reference for the framework's share of each camera frame's time (benchmarks/driving_bench.py).
//
// Each frame does the work the engines do for one camera frame of the autonomous-driving
// experiment: the physics steps of one camera period (the car parked, as in the detection
// config), rendering the camera (with the ground-truth pass when the backend needs it), and
// detection. Prints the median over runs of frames per second and milliseconds per frame.
//
//   frame_bench WORLD.sdf [--backend ground_truth|hog|yolo] [--model M.onnx] [--frames 300]
//               [--runs 5] [--shadows 0|1]
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "camera_sensors.h"
#include "datapack/json.h"
#include "detector.h"
#include "physics_world.h"
#include "render/image_io.h"
#include "world_description.h"

using namespace convoy;

namespace {

// CPU time of the whole process (all llvmpipe threads), seconds: steadier than the wall clock
// on a machine with other work running.
double cpu_seconds() {
  rusage u;
  getrusage(RUSAGE_SELF, &u);
  return u.ru_utime.tv_sec + u.ru_stime.tv_sec + 1e-6 * (u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr,
                 "usage: frame_bench WORLD.sdf [--backend B] [--model M.onnx] [--frames N] "
                 "[--runs R] [--shadows 0|1] [--save LAST_FRAME.ppm]\n");
    return 2;
  }
  std::string world_file = argv[1], backend = "ground_truth", model, save;
  int frames = 300, runs = 5;
  bool shadows = false;
  for (int i = 2; i + 1 < argc; i += 2) {
    std::string k = argv[i], v = argv[i + 1];
    if (k == "--backend")
      backend = v;
    else if (k == "--model")
      model = v;
    else if (k == "--frames")
      frames = std::stoi(v);
    else if (k == "--runs")
      runs = std::stoi(v);
    else if (k == "--shadows")
      shadows = v == "1";
    else if (k == "--save")
      save = v;
  }
  try {
    world::WorldDesc desc = world::load_world(world_file);
    world::PhysicsWorld physics(desc);
    world::CameraSensors cameras(desc, physics, 7);
    if (cameras.count() == 0) throw std::runtime_error(world_file + ": no camera");
    render::Shadows shadow_settings;
    shadow_settings.enabled = shadows;
    cameras.set_shadows(shadow_settings);
    const world::CameraDesc& cam = cameras.camera(0);
    const double period = cam.update_rate > 0 ? 1.0 / cam.update_rate : 1.0 / 30;
    const int substeps = std::max(1, static_cast<int>(std::lround(period / physics.step_size())));

    std::unique_ptr<detector::YoloDetector> yolo;
    std::unique_ptr<detector::HogDetector> hog;
    if (backend == "yolo") {
      detector::YoloOptions o;
      o.model_path = model;
      yolo = std::make_unique<detector::YoloDetector>(o);
    } else if (backend == "hog") {
      hog = std::make_unique<detector::HogDetector>();
    } else if (backend != "ground_truth") {
      throw std::runtime_error("--backend must be ground_truth, hog or yolo");
    }
    const auto& names = detector::coco_class_names();
    const bool truth = backend == "ground_truth";

    engine::DataPack image, boxes;
    datapack::InlineBlobWriter writer;
    double t = 0;
    size_t detections = 0;
    auto one_frame = [&] {
      for (int k = 0; k < substeps; ++k) physics.step();
      t += substeps * physics.step_size();
      cameras.update(t);
      std::vector<detector::Detection> dets;
      // The frame the co-simulated detector receives, converted from the read-back pixels
      // (with the camera's noise) as the world engine does for its reply.
      image.Clear();
      datapack::Builder image_out(&image, writer);
      cameras.image_datapack(0, image_out);
      if (truth) {
        boxes.Clear();
        datapack::Builder out(&boxes, writer);
        cameras.boxes_datapack(0, out);
        dets = detector::detections_from_boxes(
            datapack::read_json(datapack::View(boxes, datapack::inline_blob_reader())), names);
      } else {
        cv::Mat img =
            detector::image_from_datapack(datapack::View(image, datapack::inline_blob_reader()));
        dets = yolo ? yolo->detect(img) : hog->detect(img);
      }
      detections += dets.size();
    };
    for (int i = 0; i < 10; ++i) one_frame();  // warm-up: first renders, programs
    std::vector<double> ms, cpu_ms;
    for (int run = 0; run < runs; ++run) {
      auto t0 = std::chrono::steady_clock::now();
      const double c0 = cpu_seconds();
      for (int i = 0; i < frames; ++i) one_frame();
      double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      ms.push_back(1e3 * s / frames);
      cpu_ms.push_back(1e3 * (cpu_seconds() - c0) / frames);
    }
    if (!save.empty()) {  // the last frame, as the detector receives it
      cv::Mat rgb =
          detector::image_from_datapack(datapack::View(image, datapack::inline_blob_reader()));
      if (rgb.channels() != 3 || !rgb.isContinuous()) throw std::runtime_error("--save: not RGB");
      render::write_ppm(save, rgb.cols, rgb.rows, rgb.data);
    }
    std::sort(ms.begin(), ms.end());
    std::sort(cpu_ms.begin(), cpu_ms.end());
    const double med = ms[ms.size() / 2];
    std::printf(
        "standalone physics + render + detect (backend %s, %dx%d, %d physics steps a frame%s): "
        "%.2f ms/frame, %.1f frames/s (median of %d runs of %d frames; %.1f detections a "
        "frame; CPU %.2f ms/frame over all threads)\n",
        backend.c_str(), cam.width, cam.height, substeps, shadows ? ", shadows" : "", med,
        1e3 / med, runs, frames, static_cast<double>(detections) / ((runs * frames) + 10),
        cpu_ms[cpu_ms.size() / 2]);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "frame_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
