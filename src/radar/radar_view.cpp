#include "radar/radar_view.h"

#include "radar/radar_occlusion.h"

namespace convoy::radar {

std::vector<Target> visible_targets(const RadarParams& p, const lidar::LidarScene& rays,
                                    const std::vector<SceneObject>& objects,
                                    const Eigen::Isometry3d& world_from_sensor,
                                    const Eigen::Vector3d& sensor_velocity, uint32_t own_model,
                                    const std::function<std::string(uint32_t)>& class_of) {
  const Eigen::Vector3d origin = world_from_sensor.translation();
  const Eigen::Matrix3d to_sensor = world_from_sensor.linear().transpose();
  std::vector<Target> out;
  for (const SceneObject& o : objects) {
    if (o.id == own_model) continue;
    Target t;
    t.centre = to_sensor * (o.centre() - origin);
    if (!in_view(p, t.centre)) continue;
    const Visibility vis = visibility(rays, origin, o, own_model);
    if (vis.fraction <= 0) continue;
    t.id = o.id;
    t.cls = class_of(o.id);
    t.size = o.size();
    t.velocity = to_sensor * (o.velocity_at(o.centre()) - sensor_velocity);
    t.range = vis.range;
    t.visible_fraction = vis.fraction;
    out.push_back(std::move(t));
  }
  return out;
}

}  // namespace convoy::radar
