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
//                "y_min", "x_max", "y_max", "pixels", "distance", "visibility",
//                "visible_fraction", "full_box"}]}: ground truth of visible models
//   ...::instances  JSON {"width", "height", "ids": uint32 ndarray (the instance id at each
//                pixel), "instances": {id: {"model", "class"}}}: instance masks
//   <model>::road_user  RoadUserDataPack, read: each ego model's state (EgoModels)
//   collisions          JSON list of {"t", "a", "b", "class_a", "class_b",
//                       "relative_speed_mps"}: every contact so far, each once when it starts
// RoadUser / RoadUsers datapacks sent to the engine under any name (protobuf, or JSON dicts
// with RoadUser's keys) pose actors: one per road-user id (docs/architecture.md, Actors).
// A joint datapack sent to the engine sets the joint's PID target: its position for a
// position controller, its velocity for a velocity controller; a non-zero effort is added
// as a feed-forward effort.
//   <brake plugin>::<joint>  GazeboJointDataPack, read and write (ConvoyBrakePlugin.so, see
//                       world_description.h): the effort written is the brake torque (Nm,
//                       0..MaxTorque); the effort read is the torque the ABS applies. While a
//                       wheel brakes, its joint controller (if any) is idle.
//   <WeatherDataPack> ("weather")  the weather engine's JSON, written: applied to the cameras
//                       and to the wheels' friction and the wind (docs/weather.md).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <set>
#include <unordered_map>

#include "actors.h"
#include "camera_sensors.h"
#include "convoy/datapacks.pb.h"
#include "convoy/road_users.pb.h"
#include "datapack/json.h"
#include "datapack/proto.h"
#include "datapack/registry.h"
#include "engine/engine.h"
#include "joint_pid.h"
#include "physics_world.h"
#include "world_cache.h"
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
    actor_timeout_ = config.value("ActorTimeout", 1.0);
    actor_table_ = config.value("ActorModels", std::string());
    weather_dp_ = config.value("WeatherDataPack", std::string("weather"));
    shadows_.distance = config.value("ShadowDistance", 60.0);
    rng_.seed(seed_);
    const auto t0 = std::chrono::steady_clock::now();
    world::CacheResult cache;
    desc_ = world::load_world_cached(file, extra, &cache);
    const auto t1 = std::chrono::steady_clock::now();
    physics_ = std::make_unique<world::PhysicsWorld>(desc_);
    const auto t2 = std::chrono::steady_clock::now();
    cameras_ = std::make_unique<world::CameraSensors>(desc_, *physics_, seed_);
    auto s = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count(); };
    std::fprintf(stderr,
                 "convoy: engine '%s': world %s loaded in %.3f s (cache: %s, %s); physics %.3f s, "
                 "cameras %.3f s\n",
                 name.c_str(), file.filename().c_str(), s(t0, t1), world::to_string(cache),
                 world::cache_dir().c_str(), s(t1, t2), s(t2, std::chrono::steady_clock::now()));
    // Shadows as the world's <scene><shadows> says (SDF: on by default), unless the config says.
    shadows_.enabled = config.contains("Shadows") && config["Shadows"].is_boolean()
                           ? config["Shadows"].get<bool>()
                           : desc_.shadows;
    cameras_->set_shadows(shadows_);

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
      for (const auto& bp : model.brake_plugins) {
        for (const auto& b : bp.brakes) {
          Brake brake;
          brake.joint = physics_->joint_index(b.joint);
          if (brake.joint < 0)
            throw std::runtime_error("brake plugin '" + bp.name + "': joint '" + b.joint +
                                     "' has no degree of freedom");
          brake.max_torque = b.max_torque;
          brake.abs = bp.abs;
          brake.slip = bp.slip;
          brakes_.push_back(brake);
          const std::string n = bp.name + "::" + b.joint.substr(model.name.size() + 2);
          brake_dps_[n] = brakes_.size() - 1;
          add(n, datapack::type_name<data::Joint>());
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
        camera_dps_[base + "::instances"] = {c, kInstances};
        add(base, datapack::type_name<data::Camera>());
        add(base + "::depth", "json");
        add(base + "::boxes", "json");
        add(base + "::instances", "json");
      }
    }
    // Ego models: those named, else every model with a joint controller plugin.
    std::vector<std::string> egos;
    if (config.contains("EgoModels")) {
      egos = config["EgoModels"].get<std::vector<std::string>>();
    } else {
      for (const auto& model : desc_.models)
        if (!model.is_static && !model.joint_plugins.empty()) egos.push_back(model.name);
    }
    for (const auto& ego_name : egos) {
      auto it = std::find_if(desc_.models.begin(), desc_.models.end(),
                             [&](const auto& m) { return m.name == ego_name; });
      if (it == desc_.models.end() || it->links.empty())
        throw std::runtime_error("EgoModels: no model '" + ego_name + "' with a link in the world");
      egos_.push_back(make_ego(*it));
      add(ego_name + "::road_user", datapack::type_name<data::RoadUser>());
    }
    add("collisions", "json");
    build_entities();
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
    cameras_->set_shadows(shadows_);
    for (auto& c : controllers_) {
      c.target = c.initial_target;
      c.feed_forward = 0;
      c.pid.reset();
    }
    rng_.seed(seed_);
    time_ns_ = 0;
    physics_steps_ = 0;
    sent_frames_.clear();
    actors_.clear();
    offsets_.clear();
    actor_by_id_.clear();
    pending_.clear();
    contacts_.clear();
    collisions_ = nlohmann::json::array();
    for (auto& b : brakes_) b.command = b.applied = b.last_command = b.last_omega = 0;
    if (weather_) apply_weather(*weather_);
    for (auto& e : egos_) {
      e.speed = 0;
      e.speed_ns = -1;
    }
    build_entities();
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
    apply_road_users();
    for (int64_t k = 0; k < n; ++k) {
      update_brakes(dt);
      for (auto& c : controllers_) {
        if (braking(c.joint)) {
          physics_->set_joint_effort(c.joint, 0.0);
          c.pid.reset();
          continue;
        }
        auto s = physics_->joint_state(c.joint);
        double error = (c.velocity ? s.velocity : s.position) - c.target;
        physics_->set_joint_effort(c.joint, c.pid.update(error, dt) + c.feed_forward);
      }
      physics_->step();
      record_contacts();
    }
    record_actor_overlaps();
    cameras_->update(static_cast<double>(time_ns_) * 1e-9);
    return time_ns_;
  }

  void set_datapack(const datapack::View& dp) override {
    if (dp.id().name() == weather_dp_) {
      take_weather(dp);
      return;
    }
    if (auto b = brake_dps_.find(dp.id().name()); b != brake_dps_.end()) {
      if (dp.empty()) return;
      if (dp.proto_type() != datapack::type_name<data::Joint>())
        throw std::runtime_error("datapack '" + dp.id().name() + "' must be a GazeboJointDataPack");
      const double torque = datapack::read_proto<data::Joint>(dp).effort();
      Brake& brake = brakes_[b->second];
      if (!(torque >= 0))
        throw std::runtime_error("engine '" + name_ + "': datapack '" + dp.id().name() +
                                 "': the brake torque (effort) must be >= 0 Nm, got " +
                                 std::to_string(torque));
      brake.command = std::min(torque, brake.max_torque);
      return;
    }
    auto it = joint_dps_.find(dp.id().name());
    if (it == joint_dps_.end() && take_road_users(dp)) return;
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
    if (id.name() == "collisions") {
      datapack::write_json(out, collisions_);
      return;
    }
    for (auto& e : egos_) {
      if (id.name() == e.datapack) {
        datapack::write_proto(out, ego_state(e));
        return;
      }
    }
    if (auto it = camera_dps_.find(id.name()); it != camera_dps_.end()) {
      auto [index, kind] = it->second;
      if (kind == kImage)
        cameras_->image_datapack(index, out);
      else if (kind == kDepth)
        cameras_->depth_datapack(index, out);
      else if (kind == kInstances)
        cameras_->instances_datapack(index, out);
      else
        cameras_->boxes_datapack(index, out);
      sent_frames_[id.name()] = cameras_->frames(index);
      return;
    }
    // A joint's state; a brake's effort is the torque its ABS applies.
    auto write_joint = [&](int joint, const double* effort) {
      auto s = physics_->joint_state(joint);
      data::Joint j;
      j.set_position(static_cast<float>(s.position));
      j.set_velocity(static_cast<float>(s.velocity));
      j.set_effort(static_cast<float>(effort ? *effort : s.effort));
      datapack::write_proto(out, j);
    };
    if (auto it = brake_dps_.find(id.name()); it != brake_dps_.end()) {
      const Brake& b = brakes_[it->second];
      write_joint(b.joint, &b.applied);
      return;
    }
    if (auto it = joint_dps_.find(id.name()); it != joint_dps_.end()) {
      write_joint(controllers_[it->second].joint, nullptr);
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
  // --- Weather and brakes -------------------------------------------------------------------
  struct Brake {
    int joint = -1;
    double max_torque = 0, slip = 0.15;
    bool abs = true;
    double command = 0, applied = 0;  // Nm
    double radius = -1;               // m; -1: not yet found
    double last_command = 0;          // in the previous physics step
    double last_omega = 0;            // the wheel's spin (rad/s, forward) in the previous step
    double integral = 0;              // ABS: the PI controller's integral torque
  };

  void take_weather(const datapack::View& dp) {
    if (dp.empty()) return;
    auto where = [&] { return "engine '" + name_ + "': datapack '" + dp.id().name() + "': "; };
    if (!dp.is_json()) throw std::runtime_error(where() + "expected the weather engine's JSON");
    try {
      weather_ = world::weather_from_json(datapack::read_json(dp));
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(where() + e.what());
    }
    apply_weather(*weather_);
  }

  void apply_weather(const world::Weather& w) {
    physics_->set_wheel_friction(w.mu);
    physics_->set_wind(Eigen::Vector3d(w.wind_x, w.wind_y, 0.0));
    cameras_->set_weather(w);
  }

  bool braking(int joint) const {
    for (const auto& b : brakes_)
      if (b.joint == joint && b.command > 0) return true;
    return false;
  }

  // ABS: a PI controller per wheel holds its longitudinal slip at the target (<slip>). The
  // brake starts at the full command; while the wheel slips more than the target the torque
  // falls, while it slips less the torque rises, never above the command. Near the target
  // the tyre slides at its full grip (Coulomb friction), and the wheel never locks. While a
  // wheel over the target spins up again, the integral holds (as an ABS holds its pressure
  // once the wheel accelerates).
  // The gains place the slip loop's poles at 30 rad/s (damping 0.7) at 10 m/s, from the
  // wheel's inertia I and radius r: slip' = r / (v I) (brake torque - road torque). Below
  // 2 m/s, or without ABS, the full command applies.
  void update_brakes(double dt) {
    for (auto& b : brakes_) {
      const double command_before = b.last_command;
      b.last_command = b.command;
      if (b.command <= 0) {
        b.applied = 0;
        physics_->set_joint_brake(b.joint, 0.0);
        continue;
      }
      const auto* wheel = physics_->joint_child(b.joint);
      const Eigen::Vector3d axis = physics_->joint_axis_world(b.joint);
      Eigen::Vector3d rolling = axis.cross(Eigen::Vector3d::UnitZ());
      const double n = rolling.norm();
      const double radius = wheel_radius(b);
      double v = 0, w = 0;
      if (n > 1e-6 && radius > 0) {
        rolling /= n;
        v = wheel->getLinearVelocity().dot(rolling);  // ground speed along the wheel's path
        w = wheel->getAngularVelocity().dot(axis);
        if (v < 0) {  // forward is where it travels
          v = -v;
          w = -w;
        }
      }
      const double slip = v > 1e-3 ? (v - w * radius) / v : 0.0;
      if (command_before <= 0) b.integral = b.command;  // brakes just pressed
      if (!b.abs || v < 2.0 || radius <= 0) {
        b.applied = b.command;
      } else {
        const double inertia = std::max(axis.dot(wheel->getInertia().getMoment() * axis), 1e-3);
        const double wn = 30.0, zeta = 0.7, v_ref = 10.0;
        const double ki = wn * wn * v_ref * inertia / radius;
        const double kp = 2 * zeta * wn * v_ref * inertia / radius;
        const double e = slip - b.slip;
        // Over the target but the wheel already spinning up: the torque is under the grip
        // already, and lowering it further would only lose braking.
        const bool recovering = e > 0 && w > b.last_omega;
        if (!recovering) b.integral = std::clamp(b.integral - ki * e * dt, 0.0, b.command);
        b.applied = std::clamp(b.integral - kp * e, 0.0, b.command);
      }
      b.last_omega = w;
      physics_->set_joint_brake(b.joint, b.applied);
    }
  }

  // A braked wheel's radius: its collision cylinder's or sphere's (0: none).
  double wheel_radius(Brake& b) {
    if (b.radius >= 0) return b.radius;
    b.radius = 0;
    const auto* body = physics_->joint_child(b.joint);
    for (const auto* node : body->getShapeNodesWith<dart::dynamics::CollisionAspect>()) {
      const auto* shape = node->getShape().get();
      if (auto* c = dynamic_cast<const dart::dynamics::CylinderShape*>(shape))
        b.radius = std::max(b.radius, c->getRadius());
      else if (auto* sp = dynamic_cast<const dart::dynamics::SphereShape*>(shape))
        b.radius = std::max(b.radius, sp->getRadius());
    }
    return b.radius;
  }

  // --- Road users as actors ---------------------------------------------------------------

  // A RoadUser / RoadUsers datapack (protobuf or JSON): its users wait for the next step.
  bool take_road_users(const datapack::View& dp) {
    const std::string& dp_name = dp.id().name();
    auto where = [&] { return "engine '" + name_ + "': datapack '" + dp_name + "': "; };
    try {
      if (dp.is_json()) {
        for (auto& u : world::road_users_from_json(datapack::read_json(dp)))
          pending_.emplace_back(dp_name, std::move(u));
        return true;
      }
      if (dp.proto_type() == datapack::type_name<data::RoadUser>()) {
        pending_.emplace_back(dp_name, datapack::read_proto<data::RoadUser>(dp));
        return true;
      }
      if (dp.proto_type() == datapack::type_name<data::RoadUsers>()) {
        const auto users = datapack::read_proto<data::RoadUsers>(dp);  // (kept alive)
        for (const auto& u : users.users()) pending_.emplace_back(dp_name, u);
        return true;
      }
    } catch (const std::exception& e) {
      throw std::runtime_error(where() + e.what());
    }
    return false;
  }

  struct ActorState {
    std::string id, category, cls;
    int physics = -1, camera = -1;
    bool present = false;
    int64_t last_seen_ns = 0;
    int64_t created_ns = -1;                                 // the step it first appeared in
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // the model's frame
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
    Eigen::Vector3d half = Eigen::Vector3d::Zero();  // half the box, about the model's frame
    int walk_poses = 0;  // an animated walker's walking cycle poses (then the camera's pose
    bool stand = false;  // walk_poses is its standing model, if it has one)
  };

  // The pose an animated walker shows: its walking cycle's pose nearest to walk_phase while
  // it moves, its standing model when it stands still.
  static int walker_pose(const ActorState& a, const data::RoadUser& u) {
    constexpr double kStandingSpeed = 0.05;  // m/s
    if (a.stand && std::abs(u.speed()) < kStandingSpeed) return a.walk_poses;
    const double phase = u.walk_phase() - std::floor(u.walk_phase());
    return static_cast<int>(std::lround(phase * a.walk_poses)) % a.walk_poses;
  }

  static bool is_road_user_class(const std::string& c) {
    return c == "car" || c == "truck" || c == "bus" || c == "pedestrian" || c == "cyclist";
  }

  ActorState& actor_for(const std::string& dp_name, const data::RoadUser& u) {
    auto where = [&] {
      return "engine '" + name_ + "': datapack '" + dp_name + "': road user '" + u.id() + "': ";
    };
    if (u.id().empty()) throw std::runtime_error(where() + "no id");
    if (!u.category().empty() && !is_road_user_class(u.category()))
      throw std::runtime_error(where() + "category '" + u.category() +
                               "' is not one of car, truck, bus, pedestrian, cyclist");
    if (auto it = actor_by_id_.find(u.id()); it != actor_by_id_.end()) {
      ActorState& a = actors_[it->second];
      if (!u.category().empty() && u.category() != a.category)
        throw std::runtime_error(where() + "was '" + a.category + "', now '" + u.category() +
                                 "': an id cannot change its category");
      return a;
    }
    if (!library_) library_ = std::make_unique<world::ActorLibrary>(actor_table_);
    const world::ActorModel* am;
    try {
      am = &library_->find(u.model(), u.category());
    } catch (const std::exception& e) {
      throw std::runtime_error(where() + e.what());
    }
    if (!u.model().empty() && am->key != u.model() && warned_models_.insert(u.model()).second) {
      std::fprintf(stderr,
                   "convoy: warning: engine '%s': datapack '%s': actor model '%s' is not in %s; "
                   "category '%s' uses '%s'\n",
                   name_.c_str(), dp_name.c_str(), u.model().c_str(),
                   library_->table().string().c_str(), u.category().c_str(), am->key.c_str());
    }
    ActorState a;
    a.id = u.id();
    a.created_ns = time_ns_;
    a.category = u.category().empty() ? am->cls : u.category();
    a.cls = a.category;
    Eigen::Vector3d scale(u.length() > 0 ? u.length() / am->size.x() : 1,
                          u.width() > 0 ? u.width() / am->size.y() : 1,
                          u.height() > 0 ? u.height() / am->size.z() : 1);
    world::ModelDesc model = world::scaled(am->desc, scale);
    model.name = u.id();
    a.half = 0.5 * am->size.cwiseProduct(scale);
    a.physics = physics_->add_actor(u.id(), model);
    std::vector<world::ModelDesc> poses;
    if (!am->walk_cycle.empty()) {
      // The walker's poses keep their proportions: scaled to its height only.
      const Eigen::Vector3d uniform = Eigen::Vector3d::Constant(scale.z());
      for (const auto& p : am->walk_cycle) poses.push_back(world::scaled(p, uniform));
      for (const auto& p : am->stand) poses.push_back(world::scaled(p, uniform));
      a.walk_poses = static_cast<int>(am->walk_cycle.size());
      a.stand = !am->stand.empty();
    }
    a.camera = cameras_->add_actor(model, a.cls, poses);
    offsets_.push_back(am->length_offset * scale.x());
    actors_.push_back(std::move(a));
    actor_by_id_[u.id()] = actors_.size() - 1;
    entity_[physics_->actor_skeleton(actors_.back().physics)] = {
        u.id(), actors_.back().cls, nullptr, static_cast<int>(actors_.size() - 1)};
    return actors_.back();
  }

  void set_present(ActorState& a, bool present) {
    if (a.present == present) return;
    a.present = present;
    physics_->set_actor_present(a.physics, present);
    cameras_->set_actor_visible(a.camera, present);
  }

  // Poses the actors from the road users received since the last step; removes those gone
  // (absent, or not heard of for ActorTimeout).
  void apply_road_users() {
    for (const auto& [dp_name, u] : pending_) {
      if (u.absent()) {
        if (auto it = actor_by_id_.find(u.id()); it != actor_by_id_.end())
          set_present(actors_[it->second], false);
        continue;
      }
      ActorState& a = actor_for(dp_name, u);
      const size_t index = actor_by_id_[u.id()];
      double offset = u.length() > 0 ? u.length_offset() : offsets_[index];
      Eigen::Isometry3d shift = Eigen::Isometry3d::Identity();
      shift.translation().x() = offset;
      a.pose = world::road_user_pose(u) * shift;
      a.velocity = (u.vx() != 0 || u.vy() != 0) ? Eigen::Vector3d(u.vx(), u.vy(), 0)
                                                : Eigen::Vector3d(u.speed() * std::cos(u.yaw()),
                                                                  u.speed() * std::sin(u.yaw()), 0);
      a.last_seen_ns = time_ns_;
      physics_->set_actor_pose(a.physics, a.pose);
      cameras_->set_actor_pose(a.camera, a.pose);
      if (a.walk_poses > 0) cameras_->set_actor_shown(a.camera, walker_pose(a, u));
      set_present(a, true);
    }
    pending_.clear();
    if (actor_timeout_ > 0) {
      const auto timeout_ns = static_cast<int64_t>(actor_timeout_ * 1e9);
      for (auto& a : actors_)
        if (a.present && time_ns_ - a.last_seen_ns > timeout_ns) set_present(a, false);
    }
  }

  // --- Collisions ---------------------------------------------------------------------------

  struct Entity {
    std::string name, cls;
    const dart::dynamics::Skeleton* skeleton;  // a world model's (its velocity), or null
    int actor;                                 // or an actor's index, or -1
  };

  void build_entities() {
    entity_.clear();
    for (const auto& m : desc_.models) {
      if (world::is_ground(m)) continue;
      if (const auto* skel = physics_->model_skeleton(m.name))
        entity_[skel] = {m.name, world::class_of(m), m.is_static ? nullptr : skel, -1};
    }
  }

  Eigen::Vector3d velocity_of(const Entity& e) const {
    if (e.actor >= 0) return actors_[e.actor].velocity;
    if (e.skeleton && e.skeleton->getNumBodyNodes() > 0)
      return e.skeleton->getRootBodyNode()->getLinearVelocity();
    return Eigen::Vector3d::Zero();
  }

  // A contact between two entities counts as new when they have not touched for this long:
  // bodies resting against each other make and break contact from step to step.
  static constexpr double kContactGap = 0.5;

  void note_contact(const void* a_key, const void* b_key, const Entity& a, const Entity& b) {
    const double t = physics_->time();
    auto key = std::make_pair(a_key, b_key);
    auto it = contacts_.find(key);
    const bool fresh = it == contacts_.end() || t - it->second > kContactGap;
    contacts_[key] = t;
    if (!fresh) return;
    const Entity& first = a.name <= b.name ? a : b;
    const Entity& second = a.name <= b.name ? b : a;
    collisions_.push_back({{"t", static_cast<double>(time_ns_) * 1e-9},
                           {"a", first.name},
                           {"b", second.name},
                           {"class_a", first.cls},
                           {"class_b", second.cls},
                           {"relative_speed_mps", (velocity_of(a) - velocity_of(b)).norm()}});
  }

  void record_contacts() {
    physics_->contact_pairs(&pairs_);
    // By name, not by address: records of one step come in the same order in every run.
    found_.clear();
    for (const auto& [sa, sb] : pairs_) {
      auto ea = entity_.find(sa), eb = entity_.find(sb);
      if (ea == entity_.end() || eb == entity_.end()) continue;  // the ground
      found_.push_back({sa, sb, &ea->second, &eb->second});
    }
    std::sort(found_.begin(), found_.end(), [](const Found& x, const Found& y) {
      return std::minmax(x.a->name, x.b->name) < std::minmax(y.a->name, y.b->name);
    });
    for (const auto& f : found_) note_contact(f.ka, f.kb, *f.a, *f.b);
  }

  // Actors do not collide with each other in the physics (they are immobile there): their
  // boxes are compared here, once per engine step.
  void record_actor_overlaps() {
    for (size_t i = 0; i < actors_.size(); ++i) {
      const ActorState& a = actors_[i];
      if (!a.present) continue;
      for (size_t j = i + 1; j < actors_.size(); ++j) {
        const ActorState& b = actors_[j];
        if (!b.present || !boxes_overlap(a, b)) continue;
        if (a.created_ns == time_ns_ && b.created_ns == time_ns_) {
          // Both appear in this step, on top of each other: a placement error, not a crash.
          const Eigen::Vector3d p = a.pose.translation();
          char where[64];
          std::snprintf(where, sizeof where, "(%.2f, %.2f)", p.x(), p.y());
          throw std::runtime_error(
              "engine '" + name_ + "': road users '" + a.id + "' and '" + b.id +
              "' are placed on the same spot: their boxes overlap where they first appear, at " +
              where + ", t = " + std::to_string(static_cast<double>(time_ns_) * 1e-9) +
              " s. Give one of them another start (its engine's Route, StartS or Position)");
        }
        const auto* ka = physics_->actor_skeleton(a.physics);
        const auto* kb = physics_->actor_skeleton(b.physics);
        note_contact(ka, kb, entity_.at(ka), entity_.at(kb));
      }
    }
  }

  // Separating axes of two boxes yawed about z, plus their heights.
  static bool boxes_overlap(const ActorState& a, const ActorState& b) {
    const Eigen::Vector3d ca = a.pose * Eigen::Vector3d(0, 0, a.half.z());
    const Eigen::Vector3d cb = b.pose * Eigen::Vector3d(0, 0, b.half.z());
    if (std::abs(ca.z() - cb.z()) > a.half.z() + b.half.z()) return false;
    const Eigen::Vector2d d = (cb - ca).head<2>();
    if (d.norm() > a.half.head<2>().norm() + b.half.head<2>().norm()) return false;
    const Eigen::Vector2d axes[4] = {a.pose.linear().col(0).head<2>().normalized(),
                                     a.pose.linear().col(1).head<2>().normalized(),
                                     b.pose.linear().col(0).head<2>().normalized(),
                                     b.pose.linear().col(1).head<2>().normalized()};
    auto radius = [&](const ActorState& s, int first, const Eigen::Vector2d& axis) {
      return s.half.x() * std::abs(axes[first].dot(axis)) +
             s.half.y() * std::abs(axes[first + 1].dot(axis));
    };
    for (const auto& axis : axes) {
      if (std::abs(d.dot(axis)) > radius(a, 0, axis) + radius(b, 2, axis)) return false;
    }
    return true;
  }

  // --- The ego's state ------------------------------------------------------------------------

  struct Ego {
    std::string name, cls, datapack;
    int link = -1;  // the model's first link: the reference point
    double length = 0, width = 0, height = 0, length_offset = 0;
    double speed = 0;  // at the last report, for the acceleration
    int64_t speed_ns = -1;
  };

  Ego make_ego(const world::ModelDesc& m) {
    Ego e;
    e.name = m.name;
    e.cls = world::class_of(m);
    e.datapack = m.name + "::road_user";
    e.link = physics_->link_index(m.links.front().name);
    // The box of its collision shapes, in the reference link's frame as loaded.
    const Eigen::Isometry3d ref_inv = m.links.front().pose.inverse();
    Eigen::AlignedBox3d box;
    for (const auto& l : m.links) {
      for (const auto& c : l.collisions) {
        Eigen::Vector3d h = 0.5 * c.shape.size;
        if (c.shape.kind == world::Shape::kCylinder)
          h = {c.shape.size.x(), c.shape.size.x(), 0.5 * c.shape.size.z()};
        if (c.shape.kind == world::Shape::kPlane || c.shape.kind == world::Shape::kMesh) continue;
        const Eigen::Isometry3d t = ref_inv * l.pose * c.pose;
        for (int k = 0; k < 8; ++k)
          box.extend(t * Eigen::Vector3d((k & 1) ? h.x() : -h.x(), (k & 2) ? h.y() : -h.y(),
                                         (k & 4) ? h.z() : -h.z()));
      }
    }
    if (!box.isEmpty()) {
      e.length = box.sizes().x();
      e.width = box.sizes().y();
      e.height = box.sizes().z();
      e.length_offset = box.center().x();
    }
    return e;
  }

  data::RoadUser ego_state(Ego& e) {
    data::RoadUser u;
    auto s = physics_->link_state(e.link);
    const Eigen::Matrix3d r = s.rotation.toRotationMatrix();
    const double yaw = std::atan2(r(1, 0), r(0, 0));
    const double pitch = std::asin(std::clamp(-r(2, 0), -1.0, 1.0));
    const double roll = std::atan2(r(2, 1), r(2, 2));
    u.set_id(e.name);
    u.set_category(e.cls);
    u.set_model(e.name);
    u.set_x(s.position.x());
    u.set_y(s.position.y());
    u.set_z(s.position.z());
    u.set_yaw(yaw);
    u.set_pitch(pitch);
    u.set_roll(roll);
    const double speed = s.linear_velocity.dot(r.col(0));
    u.set_speed(speed);
    if (e.speed_ns >= 0 && time_ns_ > e.speed_ns)
      u.set_acceleration((speed - e.speed) / (static_cast<double>(time_ns_ - e.speed_ns) * 1e-9));
    if (time_ns_ != e.speed_ns) {
      e.speed = speed;
      e.speed_ns = time_ns_;
    }
    u.set_yaw_rate(s.angular_velocity.z());
    u.set_vx(s.linear_velocity.x());
    u.set_vy(s.linear_velocity.y());
    u.set_length(e.length);
    u.set_width(e.width);
    u.set_height(e.height);
    u.set_length_offset(e.length_offset);
    u.set_time_ns(time_ns_);
    return u;
  }

  double actor_timeout_ = 1.0;
  render::Shadows shadows_;
  std::string actor_table_;
  std::unique_ptr<world::ActorLibrary> library_;
  std::vector<std::pair<std::string, data::RoadUser>> pending_;  // datapack name, state
  std::vector<ActorState> actors_;
  std::vector<double> offsets_;  // by actor: its box centre ahead of the reference point
  std::unordered_map<std::string, size_t> actor_by_id_;
  std::unordered_map<const void*, Entity> entity_;
  std::map<std::pair<const void*, const void*>, double> contacts_;  // -> last touched
  std::vector<std::pair<const dart::dynamics::Skeleton*, const dart::dynamics::Skeleton*>> pairs_;
  struct Found {
    const void *ka, *kb;
    const Entity *a, *b;
  };
  std::vector<Found> found_;
  nlohmann::json collisions_ = nlohmann::json::array();
  std::vector<Ego> egos_;
  std::set<std::string> warned_models_;

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
  enum CameraOutput { kImage, kDepth, kBoxes, kInstances };
  std::unordered_map<std::string, std::pair<size_t, CameraOutput>> camera_dps_;
  std::vector<Controller> controllers_;
  std::vector<Brake> brakes_;
  std::unordered_map<std::string, size_t> brake_dps_;
  std::string weather_dp_ = "weather";
  std::optional<world::Weather> weather_;
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
