// The protobuf datapack types every Convoy program knows. One line per type.
#include "convoy/datapacks.pb.h"
#include "convoy/nav_sensors.pb.h"
#include "convoy/point_cloud.pb.h"
#include "convoy/radar.pb.h"
#include "convoy/road_users.pb.h"
#include "datapack/nrp.h"
#include "datapack/registry.h"

namespace convoy::datapack {

void register_standard_types(Registry& r) {
  // The report's tables 3.1-3.3, under NRP-Core's Python class names.
  r.add<data::Camera>("GazeboCameraDataPack");
  r.add<data::Joint>("GazeboJointDataPack");
  r.add<data::Link>("GazeboLinkDataPack");
  // Road users (proto/convoy/road_users.proto, docs/road_users.md).
  r.add<data::RoadUser>("RoadUserDataPack");
  r.add<data::RoadUsers>("RoadUsersDataPack");
  r.add<data::PointCloud>("PointCloudDataPack");  // LiDAR (proto/convoy/point_cloud.proto)
  r.add<data::Imu>("ImuDataPack");                // proto/convoy/nav_sensors.proto
  r.add<data::NavSat>("NavSatDataPack");
  r.add<data::Radar>("RadarDataPack");  // proto/convoy/radar.proto
  r.add<data::Odometry>("OdometryDataPack");
  // NRP-Core's message set (datapack/nrp.h): Dump, EngineTest, Gazebo, NrpGenericProto,
  // Wrappers. Gazebo.Camera / Joint / Link travel as the three above, whose Python classes
  // keep the names GazeboCameraDataPack... (Registry::add: a named class wins).
  register_nrp_packages(r);
}

}  // namespace convoy::datapack
