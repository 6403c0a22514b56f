#include "systems/camera_datapacks.h"

#include "camera_sensors.h"
#include "convoy/datapacks.pb.h"
#include "datapack/registry.h"

namespace convoy::world {

void CameraDatapacks::configure(const WorldContext& ctx, const nlohmann::json& config) {
  ctx_ = &ctx;
  shadows_.distance = config.value("ShadowDistance", 60.0);
  shadows_.map_size = config.value("ShadowMapSize", 1024);
  // As the world's <scene><shadows> says (SDF: on by default), unless the config says.
  shadows_.enabled = config.contains("Shadows") && config["Shadows"].is_boolean()
                         ? config["Shadows"].get<bool>()
                         : ctx.desc->shadows;
  ctx.cameras->set_shadows(shadows_);
  CameraSensors& cameras = *ctx.cameras;
  for (size_t c = 0; c < cameras.count(); ++c) {
    const auto& cam = cameras.camera(c);
    std::vector<std::string> bases{cam.scoped_name};
    if (!cam.plugin_name.empty()) bases.insert(bases.begin(), cam.plugin_name + "::" + cam.name);
    for (const auto& base : bases) {
      by_datapack_[base] = {c, cam.segmentation.empty() ? kImage : kLabels};
      by_datapack_[base + "::depth"] = {c, kDepth};
      by_datapack_[base + "::boxes"] = {c, kBoxes};
      by_datapack_[base + "::instances"] = {c, kInstances};
      provided_.push_back({base, datapack::type_name<data::Camera>()});
      provided_.push_back({base + "::depth", "json"});
      provided_.push_back({base + "::boxes", "json"});
      provided_.push_back({base + "::instances", "json"});
      if (cam.segmentation.empty()) continue;
      by_datapack_[base + "::colored"] = {c, kColored};
      provided_.push_back({base + "::colored", datapack::type_name<data::Camera>()});
    }
  }
  cameras.update(ctx.time_s());
}

void CameraDatapacks::get_datapack(const std::string& name, datapack::Builder& out) {
  auto it = by_datapack_.find(name);
  if (it == by_datapack_.end()) return;
  CameraSensors& cameras = *ctx_->cameras;
  auto [index, kind] = it->second;
  if (kind == kImage)
    cameras.image_datapack(index, out);
  else if (kind == kDepth)
    cameras.depth_datapack(index, out);
  else if (kind == kInstances)
    cameras.instances_datapack(index, out);
  else if (kind == kLabels || kind == kColored)
    cameras.segmentation_datapack(index, kind == kColored, out);
  else
    cameras.boxes_datapack(index, out);
  sent_frames_[name] = cameras.frames(index);
}

bool CameraDatapacks::unchanged(const std::string& name) {
  auto it = by_datapack_.find(name);
  if (it == by_datapack_.end()) return false;
  auto sent = sent_frames_.find(name);
  return sent != sent_frames_.end() && sent->second == ctx_->cameras->frames(it->second.first);
}

void CameraDatapacks::after_step() { ctx_->cameras->update(ctx_->time_s()); }

void CameraDatapacks::reset() {
  ctx_->cameras->set_shadows(shadows_);
  sent_frames_.clear();
  ctx_->cameras->update(ctx_->time_s());
}

}  // namespace convoy::world
