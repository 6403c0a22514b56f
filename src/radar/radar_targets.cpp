#include "radar/radar_targets.h"

#include <Eigen/LU>
#include <algorithm>

namespace convoy::radar {

namespace {

Eigen::Matrix4d matrix(const render::Pose& p) {
  return Eigen::Map<const Eigen::Matrix4d>(p.data());  // both column-major
}

}  // namespace

Eigen::Vector3d SceneObject::velocity_at(const Eigen::Vector3d& p) const {
  if (dt <= 0) return Eigen::Vector3d::Zero();
  const Eigen::Vector3d before = (motion * p.homogeneous()).head<3>();
  return (p - before) / dt;
}

void ObjectTracker::regroup(const render::Scene& scene) {
  const auto& inst = scene.instances();
  for (size_t i = instances_; i < inst.size(); ++i) {
    const uint32_t id = inst[i].model_id;
    if (id == 0) continue;
    if (by_id_.size() <= id) {
      by_id_.resize(id + 1);
      now_.resize(id + 1, Eigen::Matrix4d::Identity());
      prev_.resize(id + 1, Eigen::Matrix4d::Identity());
    }
    if (by_id_[id].empty()) now_[id] = prev_[id] = matrix(inst[i].world_from_object);
    by_id_[id].push_back(static_cast<int>(i));
  }
  instances_ = inst.size();
}

void ObjectTracker::track(const render::Scene& scene, double t) {
  if (scene.instances().size() != instances_) regroup(scene);
  const auto& inst = scene.instances();
  prev_.swap(now_);
  for (size_t id = 0; id < by_id_.size(); ++id)
    now_[id] = by_id_[id].empty() ? prev_[id] : matrix(inst[by_id_[id][0]].world_from_object);
  t_prev_ = t_now_;
  t_now_ = t;
  ++records_;
}

std::vector<SceneObject> ObjectTracker::objects(const render::Scene& scene) const {
  std::vector<SceneObject> out;
  const auto& inst = scene.instances();
  const auto& bounds = scene.mesh_bounds();
  const double dt = records_ >= 2 ? t_now_ - t_prev_ : 0;
  for (size_t id = 1; id < by_id_.size(); ++id) {
    SceneObject o;
    bool any = false;
    for (int i : by_id_[id]) {
      const auto& in = inst[i];
      if (!in.visible) continue;
      const auto& b = bounds[in.mesh];
      const Eigen::Matrix4d m = matrix(in.world_from_object);
      for (int c = 0; c < 8; ++c) {
        const Eigen::Vector3d local((c & 1) ? b.hi[0] : b.lo[0], (c & 2) ? b.hi[1] : b.lo[1],
                                    (c & 4) ? b.hi[2] : b.lo[2]);
        const Eigen::Vector3d w = (m * local.homogeneous()).head<3>();
        o.lo = any ? o.lo.cwiseMin(w) : w;
        o.hi = any ? o.hi.cwiseMax(w) : w;
        any = true;
      }
      o.class_id = in.class_id;
    }
    if (!any) continue;
    o.id = static_cast<uint32_t>(id);
    if (dt > 0) {
      o.dt = dt;
      o.motion = prev_[id] * now_[id].inverse();
    }
    out.push_back(o);
  }
  return out;
}

}  // namespace convoy::radar
