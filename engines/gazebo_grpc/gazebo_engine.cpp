// gazebo_grpc (alias gazebo_json): the world engine. Loads an SDF world, simulates it with
// DART (Bullet collisions) and serves NRP-Core's Gazebo plugin datapacks.
//
// Config keys: GazeboWorldFile, GazeboSDFModels [{Name, File, InitPose}], GazeboRNGSeed,
// WorldLoadTime (accepted; loading is synchronous), EngineTimestep.
// Datapacks (each under the NRP plugin name and under NRP-Core 1.4's scoped name):
//   <joint plugin>::<joint>, <model>::<joint>          GazeboJointDataPack, read and write
//   <link plugin>::<link>,   <model>::<link>           GazeboLinkDataPack, read
//   <camera plugin>::<sensor>, <model>::<link>::<sensor>  GazeboCameraDataPack, read
//   ...::depth   JSON {"width", "height", "depth": float32 ndarray (metres)}
//   ...::boxes   JSON {"width", "height", "boxes": [{"model", "class", "instance", "x_min",
//                "y_min", "x_max", "y_max", "pixels"}]}: ground truth of visible models
// A joint datapack sent to the engine sets the joint's PID target: its position for a
// position controller, its velocity for a velocity controller; a non-zero effort is added
// as a feed-forward effort.
#include <cmath>
#include <memory>
#include <random>
#include <unordered_map>

#include "camera_sensors.h"
#include "convoy/datapacks.pb.h"
#include "datapack/proto.h"
#include "datapack/registry.h"
#include "engine/engine.h"
#include "joint_pid.h"
#include "physics_world.h"
#include "world_description.h"

namespace convoy::engines {
namespace {

Eigen::Isometry3d pose_from_json(const nlohmann::json& j) {
  std::vector<double> v;
  if (j.is_array()) {
    for (const auto& x : j) v.push_back(x.get<double>());
  } else if (j.is_string()) {
    std::istringstream in(j.get<std::string>());
    double x;
    while (in >> x) v.push_back(x);
  }
  if (v.size() != 6 && v.size() != 3) {
    throw std::runtime_error("InitPose must be [x, y, z] or [x, y, z, roll, pitch, yaw]");
  }
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
  if (v.size() == 6) {
    t.linear() = (Eigen::AngleAxisd(v[5], Eigen::Vector3d::UnitZ()) *
                  Eigen::AngleAxisd(v[4], Eigen::Vector3d::UnitY()) *
                  Eigen::AngleAxisd(v[3], Eigen::Vector3d::UnitX()))
                     .toRotationMatrix();
  }
  return t;
}

class GazeboEngine final : public Engine {
 public:
  std::vector<engine::DataPackId> initialize(const std::string& name, const nlohmann::json& config,
                                             int64_t timestep_ns) override {
    name_ = name;
    std::filesystem::path file = config.value("GazeboWorldFile", "");
    if (file.empty()) throw std::runtime_error("GazeboWorldFile is not set");
    std::vector<world::ModelInsert> extra;
    for (const auto& m : config.value("GazeboSDFModels", nlohmann::json::array())) {
      world::ModelInsert insert;
      insert.name = m.value("Name", "");
      insert.file = m.value("File", "");
      if (m.contains("InitPose")) insert.pose = pose_from_json(m["InitPose"]);
      extra.push_back(insert);
    }
    seed_ = config.value("GazeboRNGSeed", 0u);
    rng_.seed(seed_);
    desc_ = world::load_world(file, extra);
    physics_ = std::make_unique<world::PhysicsWorld>(desc_);
    cameras_ = std::make_unique<world::CameraSensors>(desc_, *physics_, seed_);

    std::vector<engine::DataPackId> ids;
    auto add = [&](const std::string& dp_name, const std::string& type) {
      engine::DataPackId id;
      id.set_name(dp_name);
      id.set_engine_name(name);
      id.set_type(type);
      ids.push_back(id);
    };
    for (const auto& model : desc_.models) {
      for (const auto& [plugin, pids] : model.joint_plugins) {
        for (const auto& pid : pids) {
          int index = physics_->joint_index(pid.joint);
          if (index < 0)
            throw std::runtime_error("joint '" + pid.joint + "' has no degree of freedom");
          controllers_.push_back({index, pid.velocity, pid.target,
                                  world::JointPid(pid.p, pid.i, pid.d, pid.i_max, pid.i_min), 0,
                                  pid.target});
          std::string short_name = pid.joint.substr(model.name.size() + 2);
          for (const std::string& n : {plugin + "::" + short_name, pid.joint}) {
            joint_dps_[n] = controllers_.size() - 1;
            add(n, datapack::type_name<data::Joint>());
          }
        }
      }
      for (const auto& plugin : model.link_plugins) {
        for (const auto& link : model.links) {
          int index = physics_->link_index(link.name);
          for (const std::string& n : {plugin + "::" + link.short_name, link.name}) {
            link_dps_[n] = index;
            add(n, datapack::type_name<data::Link>());
          }
        }
      }
    }
    for (size_t c = 0; c < cameras_->count(); ++c) {
      const auto& cam = cameras_->camera(c);
      std::vector<std::string> bases{cam.scoped_name};
      if (!cam.plugin_name.empty()) bases.insert(bases.begin(), cam.plugin_name + "::" + cam.name);
      for (const auto& base : bases) {
        camera_dps_[base] = {c, kImage};
        camera_dps_[base + "::depth"] = {c, kDepth};
        camera_dps_[base + "::boxes"] = {c, kBoxes};
        add(base, datapack::type_name<data::Camera>());
        add(base + "::depth", "json");
        add(base + "::boxes", "json");
      }
    }
    cameras_->update(0.0);
    return ids;
  }

  // The world as loaded: the models at their initial poses, the joint controllers at their
  // SDF targets, the clock and the camera noise from the start. The description is kept, so
  // the physics world and the cameras are made again from it (same indices, same datapacks).
  void reset() override {
    cameras_.reset();
    physics_ = std::make_unique<world::PhysicsWorld>(desc_);
    cameras_ = std::make_unique<world::CameraSensors>(desc_, *physics_, seed_);
    for (auto& c : controllers_) {
      c.target = c.initial_target;
      c.feed_forward = 0;
      c.pid.reset();
    }
    rng_.seed(seed_);
    time_ns_ = 0;
    physics_steps_ = 0;
    sent_frames_.clear();
    cameras_->update(0.0);
  }

  int64_t step(int64_t duration_ns) override {
    const double dt = physics_->step_size();
    // As many physics steps as keep the physics clock within half a step of the engine's,
    // so that a timestep that is not a multiple of max_step_size (1/30 s, say) does not drift.
    time_ns_ += duration_ns;
    const int64_t dt_ns = std::max<int64_t>(1, std::llround(dt * 1e9));
    const int64_t n = (time_ns_ + dt_ns / 2) / dt_ns - physics_steps_;
    physics_steps_ += n;
    for (int64_t k = 0; k < n; ++k) {
      for (auto& c : controllers_) {
        auto s = physics_->joint_state(c.joint);
        double error = (c.velocity ? s.velocity : s.position) - c.target;
        physics_->set_joint_effort(c.joint, c.pid.update(error, dt) + c.feed_forward);
      }
      physics_->step();
    }
    cameras_->update(static_cast<double>(time_ns_) * 1e-9);
    return time_ns_;
  }

  void set_datapack(const datapack::View& dp) override {
    auto it = joint_dps_.find(dp.id().name());
    if (it == joint_dps_.end()) {
      throw std::runtime_error("engine '" + name_ + "' has no writable datapack '" +
                               dp.id().name() + "' (joint datapacks are <joint plugin>::<joint>)");
    }
    if (dp.proto_type() != datapack::type_name<data::Joint>())
      throw std::runtime_error("datapack '" + dp.id().name() + "' must be a GazeboJointDataPack");
    const auto j = datapack::read_proto<data::Joint>(dp);
    auto& c = controllers_[it->second];
    c.target = c.velocity ? j.velocity() : j.position();
    c.feed_forward = j.effort();
  }

  bool unchanged(const engine::DataPackId& id) override {
    auto it = camera_dps_.find(id.name());
    if (it == camera_dps_.end()) return false;  // joints and links move every step
    auto sent = sent_frames_.find(id.name());
    return sent != sent_frames_.end() && sent->second == cameras_->frames(it->second.first);
  }

  void get_datapack(const engine::DataPackId& id, datapack::Builder& out) override {
    if (auto it = camera_dps_.find(id.name()); it != camera_dps_.end()) {
      auto [index, kind] = it->second;
      if (kind == kImage)
        cameras_->image_datapack(index, out);
      else if (kind == kDepth)
        cameras_->depth_datapack(index, out);
      else
        cameras_->boxes_datapack(index, out);
      sent_frames_[id.name()] = cameras_->frames(index);
      return;
    }
    if (auto it = joint_dps_.find(id.name()); it != joint_dps_.end()) {
      const auto& c = controllers_[it->second];
      auto s = physics_->joint_state(c.joint);
      data::Joint j;
      j.set_position(static_cast<float>(s.position));
      j.set_velocity(static_cast<float>(s.velocity));
      j.set_effort(static_cast<float>(s.effort));
      datapack::write_proto(out, j);
      return;
    }
    if (auto it = link_dps_.find(id.name()); it != link_dps_.end()) {
      auto s = physics_->link_state(it->second);
      data::Link l;
      for (int k = 0; k < 3; ++k) l.add_position(static_cast<float>(s.position[k]));
      for (double v : {s.rotation.x(), s.rotation.y(), s.rotation.z(), s.rotation.w()})
        l.add_rotation(static_cast<float>(v));
      for (int k = 0; k < 3; ++k) l.add_linear_velocity(static_cast<float>(s.linear_velocity[k]));
      for (int k = 0; k < 3; ++k) l.add_angular_velocity(static_cast<float>(s.angular_velocity[k]));
      datapack::write_proto(out, l);
    }
  }

 private:
  struct Controller {
    int joint;
    bool velocity;
    double target;
    world::JointPid pid;
    double feed_forward;
    double initial_target;  // the SDF's Target
  };
  std::string name_;
  world::WorldDesc desc_;
  std::unique_ptr<world::PhysicsWorld> physics_;
  std::unique_ptr<world::CameraSensors> cameras_;
  enum CameraOutput { kImage, kDepth, kBoxes };
  std::unordered_map<std::string, std::pair<size_t, CameraOutput>> camera_dps_;
  std::vector<Controller> controllers_;
  std::unordered_map<std::string, size_t> joint_dps_;
  std::unordered_map<std::string, int> link_dps_;
  std::mt19937_64 rng_;
  unsigned seed_ = 0;
  int64_t time_ns_ = 0;
  int64_t physics_steps_ = 0;
  std::unordered_map<std::string, uint64_t>
      sent_frames_;  // camera datapack -> frame sent  // taken since the start
};

CONVOY_REGISTER_ENGINE("gazebo_grpc", GazeboEngine);

}  // namespace
}  // namespace convoy::engines
