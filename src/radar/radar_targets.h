// The objects a radar can see, from the scene the cameras render (render::Scene): each
// labelled model (a scene instance's model_id > 0) as one object, its box the world-axis
// bounding box of its visible instances, its velocity from how its instances moved.
//
//   ObjectTracker objects;
//   objects.track(scene, t);                 // every engine step (poses up to date)
//   for (const auto& o : objects.objects(scene)) ... o.velocity_at(point) ...
//
// Velocity: the first instance of a model (its anchor, posed even while hidden, so an
// animated walker's pose switches do not move it) gives the rigid motion between the last
// two track() calls, M_prev M_now^-1; a point p moved from M_prev M_now^-1 p to p over that
// time. An object seen once only stands still.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "render/scene.h"

namespace convoy::radar {

struct SceneObject {
  uint32_t id = 0, class_id = 0;
  Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi = Eigen::Vector3d::Zero();  // world box
  Eigen::Matrix4d motion = Eigen::Matrix4d::Identity();                        // M_prev M_now^-1
  double dt = 0;  // s between them (0: none)

  Eigen::Vector3d centre() const { return 0.5 * (lo + hi); }
  Eigen::Vector3d size() const { return hi - lo; }
  // World velocity of the object's point `p` (world frame).
  Eigen::Vector3d velocity_at(const Eigen::Vector3d& p) const;
};

class ObjectTracker {
 public:
  // Records the anchors' poses at time `t` (s); the previous record becomes the past one.
  void track(const render::Scene& scene, double t);
  // The labelled models with a visible instance, by id.
  std::vector<SceneObject> objects(const render::Scene& scene) const;
  void reset() { *this = ObjectTracker(); }
  bool tracked() const { return records_ > 0; }

 private:
  void regroup(const render::Scene& scene);

  size_t instances_ = 0;                     // scene instances grouped
  std::vector<std::vector<int>> by_id_;      // model id -> its instances (first: the anchor)
  std::vector<Eigen::Matrix4d> now_, prev_;  // by model id
  double t_now_ = 0, t_prev_ = 0;
  int records_ = 0;
};

}  // namespace convoy::radar
