#include "camera_desc.h"

#include <sdf/Camera.hh>
#include <stdexcept>

#include "sdf_eigen.h"
#include "sensor_sdf.h"

namespace convoy::world {

bool is_camera_sensor(const sdf::Sensor* sensor) {
  return sensor && (sensor->Type() == sdf::SensorType::CAMERA ||
                    sensor->Type() == sdf::SensorType::SEGMENTATION_CAMERA);
}

CameraDesc camera_desc(const sdf::Sensor* sensor, const std::string& model, const std::string& link,
                       const std::filesystem::path& file) {
  const sdf::Camera* cam = sensor->CameraSensor();
  CameraDesc cd;
  cd.name = sensor->Name();
  cd.scoped_name = model + "::" + link + "::" + sensor->Name();
  ignition::math::Pose3d sp;
  sensor->SemanticPose().Resolve(sp);
  cd.pose = to_eigen(sp);
  if (cam) {
    cd.width = static_cast<int>(cam->ImageWidth());
    cd.height = static_cast<int>(cam->ImageHeight());
    cd.format = cam->PixelFormatStr();
    cd.hfov = cam->HorizontalFov().Radian();
    cd.near_clip = cam->NearClip();
    cd.far_clip = cam->FarClip();
    const sdf::Noise& n = cam->ImageNoise();
    cd.noise = n.Type() == sdf::NoiseType::GAUSSIAN;
    cd.noise_mean = n.Mean();
    cd.noise_stddev = n.StdDev();
    if (sensor->Type() == sdf::SensorType::SEGMENTATION_CAMERA)
      cd.segmentation = cam->HasSegmentationType() ? cam->SegmentationType() : "semantic";
  }
  cd.update_rate = sensor->UpdateRate();
  cd.plugin_name = sensor_plugin_name(sensor);
  const std::string& seg = cd.segmentation;
  if (!seg.empty() && seg != "semantic" && seg != "panoptic")
    throw std::runtime_error(sensor_where(file, model, link, cd.name) + "<segmentation_type>: '" +
                             seg + "' is not semantic or panoptic");
  return cd;
}

}  // namespace convoy::world
