#include "lidar/lidar_model.h"

#include <cmath>
#include <sdf/Lidar.hh>
#include <sdf/Noise.hh>
#include <sstream>
#include <stdexcept>

namespace convoy::lidar {

namespace {

[[noreturn]] void bad(const std::string& field, const std::string& rule, double value) {
  std::ostringstream s;
  s << field << ": " << rule << ", got " << value;
  throw std::invalid_argument(s.str());
}

void check_axis(const ScanAxis& a, const std::string& name) {
  const std::string at = "<lidar><scan><" + name + ">";
  if (a.samples < 1) bad(at + "<samples>", "must be at least 1", a.samples);
  if (!(a.resolution > 0)) bad(at + "<resolution>", "must be > 0", a.resolution);
  if (!std::isfinite(a.min_angle)) bad(at + "<min_angle>", "must be finite", a.min_angle);
  if (!std::isfinite(a.max_angle)) bad(at + "<max_angle>", "must be finite", a.max_angle);
  if (a.min_angle > a.max_angle) {
    std::ostringstream s;
    s << at << "<min_angle>: must not exceed <max_angle> (" << a.max_angle << "), got "
      << a.min_angle;
    throw std::invalid_argument(s.str());
  }
}

}  // namespace

void LidarModel::validate() const {
  check_axis(horizontal, "horizontal");
  check_axis(vertical, "vertical");
  if (vertical.min_angle < -M_PI / 2 || vertical.max_angle > M_PI / 2)
    bad("<lidar><scan><vertical>", "angles must lie within [-pi/2, pi/2]",
        vertical.min_angle < -M_PI / 2 ? vertical.min_angle : vertical.max_angle);
  if (!(range_min >= 0)) bad("<lidar><range><min>", "must be >= 0", range_min);
  if (!(range_max > range_min) || !std::isfinite(range_max)) {
    std::ostringstream s;
    s << "<lidar><range><max>: must be finite and greater than <min> (" << range_min << "), got "
      << range_max;
    throw std::invalid_argument(s.str());
  }
  if (!(range_resolution >= 0)) bad("<lidar><range><resolution>", "must be >= 0", range_resolution);
  if (!std::isfinite(noise_mean)) bad("<lidar><noise><mean>", "must be finite", noise_mean);
  if (!(noise_stddev >= 0) || !std::isfinite(noise_stddev))
    bad("<lidar><noise><stddev>", "must be >= 0", noise_stddev);
  if (!(update_rate >= 0) || !std::isfinite(update_rate))
    bad("<update_rate>", "must be >= 0", update_rate);
}

bool is_lidar_type(const std::string& type) {
  return type == "lidar" || type == "gpu_lidar" || type == "ray" || type == "gpu_ray";
}

LidarModel parse_lidar(const sdf::ElementPtr& sensor) {
  if (!sensor || sensor->GetName() != "sensor")
    throw std::invalid_argument("parse_lidar: not a <sensor> element");
  const std::string type =
      sensor->HasAttribute("type") ? sensor->GetAttribute("type")->GetAsString() : "";
  if (!is_lidar_type(type))
    throw std::invalid_argument("<sensor type=\"" + type +
                                "\">: not a LiDAR (lidar, gpu_lidar, ray or gpu_ray)");
  const char* child = sensor->HasElement("lidar") ? "lidar" : "ray";
  if (!sensor->HasElement(child))
    throw std::invalid_argument("<sensor type=\"" + type + "\">: missing <lidar> (or <ray>)");
  sdf::Lidar dom;
  sdf::Errors errors = dom.Load(sensor->GetElement(child));
  if (!errors.empty())
    throw std::invalid_argument(std::string("<") + child + ">: " + errors.front().Message());
  LidarModel m;
  m.horizontal = {static_cast<int>(dom.HorizontalScanSamples()), dom.HorizontalScanResolution(),
                  dom.HorizontalScanMinAngle().Radian(), dom.HorizontalScanMaxAngle().Radian()};
  m.vertical = {static_cast<int>(dom.VerticalScanSamples()), dom.VerticalScanResolution(),
                dom.VerticalScanMinAngle().Radian(), dom.VerticalScanMaxAngle().Radian()};
  m.range_min = dom.RangeMin();
  m.range_max = dom.RangeMax();
  m.range_resolution = dom.RangeResolution();
  const sdf::Noise& noise = dom.LidarNoise();
  m.gaussian_noise = noise.Type() == sdf::NoiseType::GAUSSIAN ||
                     noise.Type() == sdf::NoiseType::GAUSSIAN_QUANTIZED;
  m.noise_mean = m.gaussian_noise ? noise.Mean() : 0;
  m.noise_stddev = m.gaussian_noise ? noise.StdDev() : 0;
  if (sensor->HasElement("update_rate")) m.update_rate = sensor->Get<double>("update_rate");
  m.validate();
  return m;
}

}  // namespace convoy::lidar
