#include "radar/radar_occlusion.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>

namespace convoy::radar {

namespace {

// The model id of the first surface along the ray (0 for none or an unlabelled one, which
// also blocks: -1 is returned as 0 with hit), passing through `own_model`'s.
struct Hit {
  bool hit = false;
  uint32_t model = 0;
  double t = -1;
};

Hit first_hit(const lidar::LidarScene& scene, const Eigen::Vector3d& o, const Eigen::Vector3d& d,
              double tfar, uint32_t own_model) {
  auto* top = static_cast<RTCScene>(scene.handle());
  const auto& info = scene.instances();
  double start = 0;
  for (int pass = 0; pass < 8; ++pass) {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh;
    rh.ray.org_x = static_cast<float>(o.x()), rh.ray.org_y = static_cast<float>(o.y());
    rh.ray.org_z = static_cast<float>(o.z());
    rh.ray.dir_x = static_cast<float>(d.x()), rh.ray.dir_y = static_cast<float>(d.y());
    rh.ray.dir_z = static_cast<float>(d.z());
    rh.ray.tnear = static_cast<float>(start), rh.ray.tfar = static_cast<float>(tfar);
    rh.ray.time = 0, rh.ray.mask = ~0u, rh.ray.id = 0, rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(top, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return {};
    const uint32_t model = info[rh.hit.instID[0]].model_id;
    if (own_model == 0 || model != own_model) return {true, model, rh.ray.tfar};
    start = rh.ray.tfar + 1e-3;  // through the sensor's own body
  }
  return {};
}

}  // namespace

Visibility visibility(const lidar::LidarScene& scene, const Eigen::Vector3d& origin,
                      const SceneObject& object, uint32_t own_model) {
  const Eigen::Vector3d c = object.centre(), size = object.size();
  Eigen::Vector3d los = c - origin;
  const double dist = los.norm();
  Visibility v;
  if (dist <= 0) return v;
  los /= dist;
  Eigen::Vector3d side = los.cross(Eigen::Vector3d::UnitZ());
  if (side.norm() < 1e-6) side = Eigen::Vector3d::UnitX();
  side.normalize();
  const Eigen::Vector3d up = side.cross(los).normalized();
  const double width = 0.35 * (std::abs(side.x()) * size.x() + std::abs(side.y()) * size.y());
  const double height = 0.35 * size.z();
  const Eigen::Vector3d points[kVisibilityRays] = {c, c + width * side, c - width * side,
                                                   c + height * up, c - height * up};
  const double reach = size.norm();
  int seen = 0;
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector3d d = p - origin;
    const double n = d.norm();
    if (n <= 0) continue;
    const Hit h = first_hit(scene, origin, d / n, n + reach, own_model);
    if (!h.hit || h.model != object.id) continue;
    ++seen;
    v.range = v.range < 0 ? h.t : std::min(v.range, h.t);
  }
  v.fraction = static_cast<double>(seen) / kVisibilityRays;
  return v;
}

}  // namespace convoy::radar
