// Camera datapacks: the world's <sensor type="camera">s (camera_sensors.h renders them),
// and the cameras' sun shadows.
//
// Config keys: Shadows (default: the world's <scene><shadows>), ShadowDistance (m, 60),
// ShadowMapSize (texels a side, 1024).
// Datapacks (each camera under NRP's plugin name and NRP-Core 1.4's scoped name):
//   <camera plugin>::<sensor>, <model>::<link>::<sensor>  GazeboCameraDataPack, read
//   ...::depth      JSON {"width", "height", "depth": float32 ndarray (metres)}
//   ...::boxes      JSON {"width", "height", "boxes": [...]}: ground truth of visible models
//   ...::instances  JSON {"width", "height", "ids": uint32 ndarray, "instances": {...}}
// A <sensor type="segmentation_camera">'s first datapack is its label map instead of the
// image (GazeboCameraDataPack, CameraSensors::segmentation_datapack), and it has one more:
//   ...::colored    GazeboCameraDataPack: the label map in colours
// A camera datapack is unchanged() until the camera renders again. After every engine step
// (after_step) the cameras that are due render.
#pragma once

#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "render/scene.h"
#include "world_system.h"

namespace convoy::world {

class CameraDatapacks final : public WorldSystem {
 public:
  const char* name() const override { return "cameras"; }
  void configure(const WorldContext& ctx, const nlohmann::json& config) override;
  std::vector<ProvidedDataPack> provides() const override { return provided_; }
  void get_datapack(const std::string& name, datapack::Builder& out) override;
  bool unchanged(const std::string& name) override;
  void after_step() override;
  void reset() override;

 private:
  enum Output { kImage, kDepth, kBoxes, kInstances, kLabels, kColored };
  const WorldContext* ctx_ = nullptr;
  render::Shadows shadows_;
  std::unordered_map<std::string, std::pair<size_t, Output>> by_datapack_;
  std::vector<ProvidedDataPack> provided_;
  std::unordered_map<std::string, uint64_t> sent_frames_;  // datapack -> the frame sent
};

}  // namespace convoy::world
