#include "nav_desc.h"

#include <sdf/Imu.hh>
#include <sdf/NavSat.hh>
#include <sdf/Noise.hh>
#include <stdexcept>

#include "sdf_eigen.h"
#include "sensor_sdf.h"

namespace convoy::world {

namespace {

using nav_sensors::NoiseParams;

NoiseParams noise(const sdf::Noise& n, const std::string& field) {
  NoiseParams p;
  switch (n.Type()) {
    case sdf::NoiseType::NONE:
      p.type = NoiseParams::Type::none;
      break;
    case sdf::NoiseType::GAUSSIAN:
      p.type = NoiseParams::Type::gaussian;
      break;
    case sdf::NoiseType::GAUSSIAN_QUANTIZED:
      p.type = NoiseParams::Type::gaussian_quantized;
      break;
  }
  p.mean = n.Mean();
  p.stddev = n.StdDev();
  p.bias_mean = n.BiasMean();
  p.bias_stddev = n.BiasStdDev();
  p.dynamic_bias_stddev = n.DynamicBiasStdDev();
  p.dynamic_bias_correlation_time = n.DynamicBiasCorrelationTime();
  p.precision = n.Precision();
  try {
    nav_sensors::check(p);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(field + " noise: " + e.what());
  }
  return p;
}

void read_imu(const sdf::Sensor* sensor, NavSensorDesc& d) {
  d.kind = NavSensorDesc::kImu;
  const sdf::Imu* imu = sensor->ImuSensor();
  if (!imu) return;  // <sensor type="imu"> without <imu>: no noise
  const sdf::Noise* gyro[3] = {&imu->AngularVelocityXNoise(), &imu->AngularVelocityYNoise(),
                               &imu->AngularVelocityZNoise()};
  const sdf::Noise* accel[3] = {&imu->LinearAccelerationXNoise(), &imu->LinearAccelerationYNoise(),
                                &imu->LinearAccelerationZNoise()};
  const char* axis[3] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i) {
    d.imu.angular_velocity[i] = noise(*gyro[i], std::string("<angular_velocity><") + axis[i] + ">");
    d.imu.linear_acceleration[i] =
        noise(*accel[i], std::string("<linear_acceleration><") + axis[i] + ">");
  }
  d.imu.orientation = imu->OrientationEnabled();
}

void read_navsat(const sdf::Sensor* sensor, NavSensorDesc& d) {
  d.kind = NavSensorDesc::kNavSat;
  const sdf::NavSat* n = sensor->NavSatSensor();
  if (!n) return;
  d.navsat.position_horizontal =
      noise(n->HorizontalPositionNoise(), "<position_sensing><horizontal>");
  d.navsat.position_vertical = noise(n->VerticalPositionNoise(), "<position_sensing><vertical>");
  d.navsat.velocity_horizontal =
      noise(n->HorizontalVelocityNoise(), "<velocity_sensing><horizontal>");
  d.navsat.velocity_vertical = noise(n->VerticalVelocityNoise(), "<velocity_sensing><vertical>");
}

}  // namespace

bool is_nav_sensor(const sdf::Sensor* sensor) {
  if (!sensor) return false;
  const std::string t = sensor_type(sensor);
  return t == "imu" || t == "navsat" || t == "gps";
}

NavSensorDesc nav_desc(const sdf::Sensor* sensor, const std::string& model, const std::string& link,
                       const std::filesystem::path& file) {
  NavSensorDesc d;
  d.name = sensor->Name();
  d.model = model;
  d.link = link;
  d.scoped_name = model + "::" + link + "::" + sensor->Name();
  const std::string where = sensor_where(file, model, link, d.name);
  try {
    if (sensor_type(sensor) == "imu")
      read_imu(sensor, d);
    else
      read_navsat(sensor, d);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(where + e.what());
  }
  const double rate = sensor->UpdateRate();
  if (!(rate >= 0)) throw std::runtime_error(where + "<update_rate>: must not be negative");
  d.imu.update_rate = d.navsat.update_rate = rate;
  ignition::math::Pose3d pose;
  if (!sensor->SemanticPose().Resolve(pose).empty())
    throw std::runtime_error(where + "its pose cannot be resolved");
  d.pose = to_eigen(pose);
  d.plugin_name = sensor_plugin_name(sensor);
  return d;
}

nav_sensors::GeoOrigin geo_origin(const sdf::World* world, const std::filesystem::path& file) {
  nav_sensors::GeoOrigin o;
  const auto* sc = world ? world->SphericalCoordinates() : nullptr;
  if (!sc) return o;
  const std::string where =
      file.string() + ": world '" + world->Name() + "': spherical_coordinates: ";
  if (sc->Surface() != ignition::math::SphericalCoordinates::EARTH_WGS84)
    throw std::runtime_error(where + "surface_model: only EARTH_WGS84 is supported");
  o.latitude_deg = sc->LatitudeReference().Degree();
  o.longitude_deg = sc->LongitudeReference().Degree();
  o.elevation_m = sc->ElevationReference();
  o.heading_deg = sc->HeadingOffset().Degree();
  try {
    nav_sensors::check(o);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(where + e.what());
  }
  return o;
}

}  // namespace convoy::world
