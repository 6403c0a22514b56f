// The renderer's scene as an Embree ray-tracing scene, for LiDAR sensors.
//
// Built from a render::Scene (src/render/scene.h): each mesh that an instance draws becomes
// one triangle geometry in a scene of its own (its finest level of detail: a LiDAR sees the
// true shape), committed once; each Scene instance becomes an Embree instance of it with the
// instance's pose, in a top-level scene. update() then follows the render::Scene a step at a
// time: it re-poses the instances whose pose changed, enables or disables the ones whose
// visibility changed (hidden instances return nothing), re-reads changed materials, adds
// instances added since, and recommits the top level only (a few hundred instances: well
// under a millisecond); the meshes are never rebuilt.
//
// Per instance it keeps what a return reports: the instance's model_id and class_id (the
// ground-truth labels the camera's ground truth has) and the surface's reflectivity
// (reflectivity.h). The Scene is read, never kept: pass the same one to update().
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "render/scene.h"

namespace convoy::lidar {

class LidarScene {
 public:
  struct InstanceInfo {
    uint32_t model_id = 0, class_id = 0;
    float reflectivity = 0;
    // World-from-object normal transform (the inverse transpose of the pose's linear part),
    // row-major: Embree reports an instance's hit normals in the object's frame.
    std::array<float, 9> normal_from_object{1, 0, 0, 0, 1, 0, 0, 0, 1};
  };

  explicit LidarScene(const render::Scene& scene);
  ~LidarScene();
  LidarScene(const LidarScene&) = delete;
  LidarScene& operator=(const LidarScene&) = delete;

  // Brings poses, visibility, materials and new instances up to date with `scene` (the Scene
  // this was built from; throws std::invalid_argument for another one) and recommits.
  // Returns how many instances changed.
  int update(const render::Scene& scene);

  const std::vector<InstanceInfo>& instances() const { return info_; }
  size_t mesh_count() const;      // meshes built (those some instance draws)
  size_t triangle_count() const;  // over the built meshes
  // Whether packets of 16 rays go to Embree's 16-wide kernels (else one ray at a time).
  bool packets16() const;

  // The Embree scene (an RTCScene) and device, for LidarSensor.
  void* handle() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::vector<InstanceInfo> info_;
};

}  // namespace convoy::lidar
