// The parsed SDF world: an immutable description of models, links, joints, plugins,
// sensors and lights, with every pose resolved to the world frame. Built once from
// libsdformat's DOM; the physics and the renderer are built from it.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "lidar/lidar_model.h"
#include "nav_sensors/geodetic.h"
#include "nav_sensors/imu_model.h"
#include "nav_sensors/navsat_model.h"
#include "radar/radar_model.h"
#include "wheel_odometry/odometry_model.h"

namespace convoy::world {

using Rgba = std::array<float, 4>;

struct Shape {
  enum Kind { kBox, kCylinder, kSphere, kPlane, kMesh, kHeightmap } kind = kBox;
  Eigen::Vector3d size = Eigen::Vector3d::Ones();     // box: x y z; cylinder: r r length;
                                                      // sphere: r r r; plane: x y 0
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // plane
  std::filesystem::path mesh;                         // mesh: absolute file path
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();    // mesh
  // heightmap (collisions only; height_map.h): `mesh` is its image, `size` the extent in x, y
  // and z, `position` the centre of its x-y extent and its lowest z
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
};

struct Material {
  Rgba ambient{0.6f, 0.6f, 0.6f, 1}, diffuse{0.7f, 0.7f, 0.7f, 1}, specular{0.1f, 0.1f, 0.1f, 1},
      emissive{0, 0, 0, 1};
  std::filesystem::path texture;  // albedo map, if any
  bool has_material = false;
};

struct CollisionDesc {
  std::string name;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // in the link frame
  Shape shape;
  double mu = 1.0;       // surface/friction/ode/mu
  int max_contacts = 0;  // <max_contacts> with any other shape (0: not set, no bound)
};

struct VisualDesc {
  std::string name;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // in the link frame
  Shape shape;
  Material material;
  bool cast_shadows = true;  // <cast_shadows>
};

struct CameraDesc {
  std::string name;                                        // sensor name
  std::string plugin_name;                                 // NRP camera plugin name ("" if none)
  std::string scoped_name;                                 // model::link::sensor
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // in the link frame
  int width = 320, height = 240;
  std::string format = "R8G8B8";
  double hfov = 1.047, near_clip = 0.1, far_clip = 100, update_rate = 0;  // 0: every step
  bool noise = false;
  double noise_mean = 0, noise_stddev = 0;
  // <sensor type="segmentation_camera">: its <segmentation_type>, "semantic" (the default) or
  // "panoptic"; "" for an RGB camera.
  std::string segmentation;
};

// A LiDAR: <sensor type="lidar|gpu_lidar|ray|gpu_ray"> (lidar_desc.h reads it).
struct LidarDesc {
  std::string name;                                        // sensor name
  std::string model;                                       // the model's (scoped) name
  std::string link;                                        // the link's name (unscoped)
  std::string plugin_name;                                 // its <plugin name> ("" if none)
  std::string scoped_name;                                 // model::link::sensor
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // in the link frame
  lidar::LidarModel lidar;
};

// An IMU or a GNSS receiver: <sensor type="imu|navsat"> (nav_desc.h reads it).
struct NavSensorDesc {
  enum Kind : uint8_t { kImu, kNavSat } kind = kImu;
  std::string name, model, link, plugin_name, scoped_name;  // as LidarDesc's
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();   // in the link frame
  nav_sensors::ImuParams imu;                               // kImu
  nav_sensors::NavSatParams navsat;                         // kNavSat
};

// A radar: <sensor type="custom"> with a convoy_radar <plugin> (radar_desc.h reads it).
struct RadarDesc {
  std::string name, model, link, plugin_name, scoped_name;  // as LidarDesc's
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();   // in the link frame
  radar::RadarParams radar;
};

// Wheel odometry: <sensor type="custom"> with a convoy_wheel_odometry <plugin> naming the
// model's rear wheel joints (and a steering joint) (radar_desc.h reads it).
struct OdometryDesc {
  std::string name, model, link, plugin_name, scoped_name;  // as LidarDesc's
  std::string left_joint, right_joint, steering_joint;      // unscoped; steering: "" if none
  wheel_odometry::OdometryParams odometry;
};

struct LinkDesc {
  std::string name;                                        // model::link
  std::string short_name;                                  // link
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // world, at load
  double mass = 1;
  Eigen::Vector3d com = Eigen::Vector3d::Zero();          // in the link frame
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Identity();  // about the COM, link axes
  bool gravity = true;
  std::vector<CollisionDesc> collisions;
  std::vector<VisualDesc> visuals;
  std::vector<CameraDesc> cameras;
  std::vector<LidarDesc> lidars;
  std::vector<NavSensorDesc> nav_sensors;
  std::vector<RadarDesc> radars;
  std::vector<OdometryDesc> odometers;
};

struct AxisDesc {
  Eigen::Vector3d xyz = Eigen::Vector3d::UnitZ();  // in the joint frame
  double lower = -1e16, upper = 1e16, damping = 0, friction = 0, effort = -1, velocity = -1;
};

struct JointDesc {
  enum Type { kRevolute, kContinuous, kPrismatic, kFixed, kBall, kUniversal } type = kFixed;
  std::string name;                                        // model::joint
  std::string short_name;                                  // joint
  std::string parent;                                      // scoped link name, or "world"
  std::string child;                                       // scoped link name
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // world, at load
  std::vector<AxisDesc> axes;
};

// One <joint_name P I D Type Target IMax IMin/> of an NRP joint controller plugin.
struct PidDesc {
  std::string joint;  // scoped joint name
  double p = 0, i = 0, d = 0, target = 0, i_max = 0, i_min = 0;
  bool velocity = false;  // Type: velocity, else position
};

// A brake plugin (Convoy's own):
//   <plugin name="smart_car_brake_plugin" filename="ConvoyBrakePlugin.so">
//     <abs>true</abs> <slip>0.15</slip>                  (optional; these are the defaults)
//     <front_left_wheel_joint MaxTorque="1500"/> ...     (Nm; default 1500)
//   </plugin>
// Each named joint gets a brake commanded through the datapack <plugin>::<joint> (a
// GazeboJointDataPack whose effort is the brake torque, Nm).
struct BrakeDesc {
  std::string joint;  // scoped
  double max_torque = 1500;
};
struct BrakePluginDesc {
  std::string name;
  bool abs = true;
  double slip = 0.15;  // ABS target: longitudinal slip kept below this
  std::vector<BrakeDesc> brakes;
};

// A signal's lamps (Convoy's own plugin; convoy-odr world writes it into traffic lights):
//   <plugin name="convoy_signal" filename="convoy_signal"><signal>SIGNAL_ID</signal>
//     <lamp colour="red">lamp_red</lamp> <lamp colour="yellow">...</lamp> ...</plugin>
// SIGNAL_ID is the OpenDRIVE signal's id (a key of the traffic_lights engine's `signals`);
// each lamp names a visual of one of the model's links and its colour: red, yellow or green
// (a pedestrian light has red and green). Other elements of the plugin are ignored.
struct LampDesc {
  std::string colour;  // red, yellow or green
  std::string link;    // the scoped name of the link that has the visual
  std::string visual;  // the visual's name
};
struct SignalDesc {
  std::string id;
  std::vector<LampDesc> lamps;
};

struct ModelDesc {
  std::string name;
  // Ground-truth class, from the model's annotation
  //   <plugin name="convoy_class" filename="convoy_class"><class>car</class></plugin>
  // ("" if none: then class_of_name()).
  std::string cls;
  std::filesystem::path source;  // the SDF file it was read from
  bool is_static = false;
  std::vector<LinkDesc> links;
  std::vector<JointDesc> joints;
  std::vector<std::pair<std::string, std::vector<PidDesc>>> joint_plugins;  // plugin name
  std::vector<std::string> link_plugins;                                    // plugin names
  std::vector<BrakePluginDesc> brake_plugins;
  std::vector<SignalDesc> signals;  // convoy_signal plugins
};

struct LightDesc {
  enum Type { kDirectional, kPoint, kSpot } type = kDirectional;
  std::string name;
  Eigen::Vector3d position = Eigen::Vector3d::Zero(), direction = -Eigen::Vector3d::UnitZ();
  Rgba diffuse{1, 1, 1, 1}, specular{0.1f, 0.1f, 0.1f, 1};
  double range = 100, constant = 1, linear = 0, quadratic = 0;
};

struct WorldDesc {
  std::filesystem::path file;
  std::string name;
  Eigen::Vector3d gravity{0, 0, -9.8};
  double max_step_size = 0.001;
  int max_contacts = 0;  // <physics><max_contacts> per pair of shapes (0: not set, no bound)
  Rgba ambient{0.4f, 0.4f, 0.4f, 1}, background{0.7f, 0.7f, 0.7f, 1};
  bool shadows = true;  // <scene><shadows>
  bool world_plugin = false;
  nav_sensors::GeoOrigin geo;  // <spherical_coordinates>
  std::vector<ModelDesc> models;
  std::vector<LightDesc> lights;
};

// The fixed class set of all ground truth: road users (car, truck, bus, pedestrian,
// cyclist) and scenery (building, tree, shrub, pole, sign, traffic_light, barrier, other).
const std::vector<std::string>& known_classes();
bool is_known_class(const std::string& cls);
// A class's label in segmentation images: its place in known_classes() from 1; 0 for none.
uint8_t class_label(const std::string& cls);
// The class of a model without an annotation: its name without a trailing number
// ("building_3" -> "building"), kept for worlds written before annotations.
std::string class_of_name(const std::string& model_name);
// A model's class: its annotation, else class_of_name().
inline std::string class_of(const ModelDesc& m) {
  return m.cls.empty() ? class_of_name(m.name) : m.cls;
}

// The ground: a model that shows only planes, or a static one that collides only as planes
// (a road mesh on a ground plane). It has no ground truth and makes no collision records.
bool is_ground(const ModelDesc& m);

// A model added by the engine config (GazeboSDFModels, read by model_inserts.h).
struct ModelInsert {
  std::string name;
  std::filesystem::path file;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  // m/s along the pose's x axis at the start (InitSpeed). Not part of the description:
  // load_world and its cache ignore it; systems/initial_speeds.h sets the model moving.
  double init_speed = 0;
};

// Loads the world file (plus extra models). `model://` URIs are looked up in
// $CONVOY_MODEL_PATH, $GAZEBO_MODEL_PATH and $SDF_PATH (colon-separated), next to the file
// (and in its models/ folder), and in the build's share/convoy/models. Throws
// std::runtime_error("<file>: <element>: <problem>").
WorldDesc load_world(const std::filesystem::path& file, const std::vector<ModelInsert>& extra = {});

// Loads one SDF file's <model> as `name` (its own name if empty) at `pose`, its nested
// models after it; for actors added while running. Throws like load_world.
std::vector<ModelDesc> load_model(const std::filesystem::path& file, const std::string& name,
                                  const Eigen::Isometry3d& pose);

}  // namespace convoy::world
