#include "systems/road_user_actors.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "camera_sensors.h"
#include "datapack/json.h"
#include "datapack/proto.h"
#include "datapack/registry.h"
#include "physics_world.h"
#include "systems/contacts.h"

namespace convoy::world {
namespace {

bool is_road_user_class(const std::string& c) {
  return c == "car" || c == "truck" || c == "bus" || c == "pedestrian" || c == "cyclist";
}

// The pose an animated walker shows: its walking cycle's pose nearest to walk_phase while
// it moves, its standing model when it stands still.
int walker_pose(const RoadUserActors::Actor& a, const data::RoadUser& u) {
  constexpr double kStandingSpeed = 0.05;  // m/s
  if (a.stand && std::abs(u.speed()) < kStandingSpeed) return a.walk_poses;
  const double phase = u.walk_phase() - std::floor(u.walk_phase());
  return static_cast<int>(std::lround(phase * a.walk_poses)) % a.walk_poses;
}

}  // namespace

void RoadUserActors::configure(const WorldContext& ctx, const nlohmann::json& config) {
  ctx_ = &ctx;
  contacts_ = ctx.find<Contacts>();
  timeout_s_ = config.value("ActorTimeout", 1.0);
  table_ = config.value("ActorModels", std::string());
}

// The batch for the next road users of datapack `dp_name`: a fresh one (its message kept from
// earlier steps, cleared) unless the last one is that datapack's.
RoadUserActors::Batch& RoadUserActors::next_batch(const std::string& dp_name) {
  if (pending_ > 0 && batches_[pending_ - 1].dp_name == dp_name) return batches_[pending_ - 1];
  if (pending_ == batches_.size()) batches_.emplace_back();
  Batch& b = batches_[pending_++];
  b.dp_name = dp_name;
  b.users.Clear();
  return b;
}

// A RoadUser / RoadUsers datapack (protobuf or JSON): its users wait for the next step.
bool RoadUserActors::set_datapack(const datapack::View& dp) {
  const std::string& dp_name = dp.id().name();
  try {
    if (dp.is_json()) {
      auto users = road_users_from_json(datapack::read_json(dp));
      auto& batch = next_batch(dp_name).users;
      for (auto& u : users) *batch.add_users() = std::move(u);
      return true;
    }
    if (dp.proto_type() == datapack::type_name<data::RoadUser>()) {
      datapack::read_proto(dp, next_batch(dp_name).users.add_users());
      return true;
    }
    if (dp.proto_type() == datapack::type_name<data::RoadUsers>()) {
      // Parsed into a message of its own (a RoadUsers' other fields must not mix with a
      // batch's), then its users moved over: no copy of a string.
      Batch& b = next_batch(dp_name);
      if (b.users.users_size() == 0) {
        datapack::read_proto(dp, &b.users);
      } else {
        data::RoadUsers more;
        datapack::read_proto(dp, &more);
        for (auto& u : *more.mutable_users()) b.users.add_users()->Swap(&u);
      }
      return true;
    }
  } catch (const std::exception& e) {
    throw std::runtime_error(ctx_->where(dp_name) + e.what());
  }
  return false;
}

const RoadUserActors::Actor* RoadUserActors::actor(const std::string& id) const {
  auto it = by_id_.find(id);
  return it == by_id_.end() ? nullptr : &actors_[it->second];
}

RoadUserActors::Actor& RoadUserActors::actor_for(const std::string& dp_name,
                                                 const data::RoadUser& u) {
  auto where = [&] { return ctx_->where(dp_name) + "road user '" + u.id() + "': "; };
  if (u.id().empty()) throw std::runtime_error(where() + "no id");
  if (!u.category().empty() && !is_road_user_class(u.category()))
    throw std::runtime_error(where() + "category '" + u.category() +
                             "' is not one of car, truck, bus, pedestrian, cyclist");
  if (auto it = by_id_.find(u.id()); it != by_id_.end()) {
    Actor& a = actors_[it->second];
    if (!u.category().empty() && u.category() != a.category)
      throw std::runtime_error(where() + "was '" + a.category + "', now '" + u.category() +
                               "': an id cannot change its category");
    return a;
  }
  return add_actor(dp_name, u);
}

// A new road user's actor: a removed one of the same shape taken over, or a new one.
RoadUserActors::Actor& RoadUserActors::add_actor(const std::string& dp_name,
                                                 const data::RoadUser& u) {
  if (!library_) library_ = std::make_unique<ActorLibrary>(table_);
  const ActorModel* am;
  try {
    am = &library_->find(u.model(), u.category());
  } catch (const std::exception& e) {
    throw std::runtime_error(ctx_->where(dp_name) + "road user '" + u.id() + "': " + e.what());
  }
  if (!u.model().empty() && am->key != u.model() && warned_models_.insert(u.model()).second) {
    std::fprintf(stderr,
                 "convoy: warning: engine '%s': datapack '%s': actor model '%s' is not in %s; "
                 "category '%s' uses '%s'\n",
                 ctx_->engine.c_str(), dp_name.c_str(), u.model().c_str(),
                 library_->table().string().c_str(), u.category().c_str(), am->key.c_str());
  }
  const std::string category = u.category().empty() ? am->cls : u.category();
  Eigen::Vector3d scale(u.length() > 0 ? u.length() / am->size.x() : 1,
                        u.width() > 0 ? u.width() / am->size.y() : 1,
                        u.height() > 0 ? u.height() / am->size.z() : 1);
  char size[96];
  std::snprintf(size, sizeof size, " %a %a %a", scale.x(), scale.y(), scale.z());
  const std::string shape = am->key + " " + category + size;
  if (Actor* reused = reuse_actor(shape, u)) return *reused;

  Actor a;
  a.id = u.id();
  a.created_ns = ctx_->time_ns;
  a.category = category;
  a.cls = a.category;
  a.shape = shape;
  ModelDesc model = scaled(am->desc, scale);
  model.name = u.id();
  a.half = 0.5 * am->size.cwiseProduct(scale);
  a.physics = ctx_->physics->add_actor(u.id(), model);
  std::vector<ModelDesc> poses;
  if (!am->walk_cycle.empty()) {
    // The walker's poses keep their proportions: scaled to its height only.
    const Eigen::Vector3d uniform = Eigen::Vector3d::Constant(scale.z());
    for (const auto& p : am->walk_cycle) poses.push_back(scaled(p, uniform));
    for (const auto& p : am->stand) poses.push_back(scaled(p, uniform));
    a.walk_poses = static_cast<int>(am->walk_cycle.size());
    a.stand = !am->stand.empty();
  }
  a.camera = ctx_->cameras->add_actor(model, a.cls, poses);
  a.length_offset = am->length_offset * scale.x();
  actors_.push_back(std::move(a));
  by_id_[u.id()] = actors_.size() - 1;
  Actor& added = actors_.back();
  if (contacts_)
    contacts_->add_entity(ctx_->physics->actor_skeleton(added.physics),
                          {u.id(), added.cls, nullptr, &added.velocity});
  return added;
}

// The oldest removed actor of `shape`, now road user u's (its old id forgotten), or null.
RoadUserActors::Actor* RoadUserActors::reuse_actor(const std::string& shape,
                                                   const data::RoadUser& u) {
  auto it = free_.find(shape);
  if (it == free_.end() || it->second.empty()) return nullptr;
  const size_t index = it->second.front();
  it->second.pop_front();
  Actor& a = actors_[index];
  a.free = false;
  by_id_.erase(a.id);
  by_id_[u.id()] = index;
  a.id = u.id();
  a.created_ns = ctx_->time_ns;
  a.velocity.setZero();
  ctx_->physics->set_actor_name(a.physics, u.id());
  ctx_->cameras->set_actor_name(a.camera, u.id());
  if (contacts_)
    contacts_->add_entity(ctx_->physics->actor_skeleton(a.physics),
                          {u.id(), a.cls, nullptr, &a.velocity});
  return &a;
}

void RoadUserActors::set_present(Actor& a, bool present) {
  if (a.present == present) return;
  a.present = present;
  auto& free = free_[a.shape];
  if (!present) {
    free.push_back(static_cast<size_t>(by_id_.at(a.id)));
    a.free = true;
  } else if (a.free) {  // back before another road user took it
    free.erase(std::find(free.begin(), free.end(), by_id_.at(a.id)));
    a.free = false;
  }
  ctx_->physics->set_actor_present(a.physics, present);
  ctx_->cameras->set_actor_visible(a.camera, present);
}

// Poses road user u's actor, or removes it (absent).
void RoadUserActors::pose_actor(const std::string& dp_name, const data::RoadUser& u, int64_t now) {
  if (u.absent()) {
    if (auto it = by_id_.find(u.id()); it != by_id_.end()) set_present(actors_[it->second], false);
    return;
  }
  Actor& a = actor_for(dp_name, u);
  double offset = u.length() > 0 ? u.length_offset() : a.length_offset;
  Eigen::Isometry3d shift = Eigen::Isometry3d::Identity();
  shift.translation().x() = offset;
  const Eigen::Isometry3d pose = road_user_pose(u) * shift;
  // A standing road user (most of a jammed city's) keeps its pose: nothing to re-pose.
  const bool moved = !a.present || pose.matrix() != a.pose.matrix();
  a.pose = pose;
  a.velocity = (u.vx() != 0 || u.vy() != 0) ? Eigen::Vector3d(u.vx(), u.vy(), 0)
                                            : Eigen::Vector3d(u.speed() * std::cos(u.yaw()),
                                                              u.speed() * std::sin(u.yaw()), 0);
  a.last_seen_ns = now;
  if (moved) {
    ctx_->physics->set_actor_pose(a.physics, a.pose);
    ctx_->cameras->set_actor_pose(a.camera, a.pose);
  }
  if (a.walk_poses > 0) ctx_->cameras->set_actor_shown(a.camera, walker_pose(a, u));
  set_present(a, true);
}

// Poses the actors from the road users received since the last step; removes those gone
// (absent, or not heard of for ActorTimeout).
void RoadUserActors::before_step() {
  const int64_t now = ctx_->time_ns;
  for (size_t k = 0; k < pending_; ++k) {
    const std::string& dp_name = batches_[k].dp_name;
    for (const data::RoadUser& u : batches_[k].users.users()) pose_actor(dp_name, u, now);
  }
  pending_ = 0;
  if (timeout_s_ > 0) {
    const auto timeout_ns = static_cast<int64_t>(timeout_s_ * 1e9);
    for (auto& a : actors_)
      if (a.present && now - a.last_seen_ns > timeout_ns) set_present(a, false);
  }
}

void RoadUserActors::candidate_pairs() {
  spans_.clear();
  pairs_.clear();
  for (size_t i = 0; i < actors_.size(); ++i) {
    const Actor& a = actors_[i];
    if (!a.present) continue;
    // boxes_overlap's bounding circle: its centre and radius (a little more, for rounding).
    const double x = a.pose.translation().x() + a.pose.linear()(0, 2) * a.half.z();
    const double y = a.pose.translation().y() + a.pose.linear()(1, 2) * a.half.z();
    const double r = a.half.head<2>().norm() * (1 + 1e-9) + 1e-9;
    spans_.push_back({x - r, x + r, y, r, i});
  }
  std::sort(spans_.begin(), spans_.end(), [](const Span& p, const Span& q) {
    return p.lo != q.lo ? p.lo < q.lo : p.index < q.index;
  });
  for (size_t k = 0; k < spans_.size(); ++k) {
    const Span& p = spans_[k];
    for (size_t m = k + 1; m < spans_.size() && spans_[m].lo <= p.hi; ++m) {
      const Span& q = spans_[m];
      if (std::abs(q.y - p.y) > q.r + p.r) continue;
      pairs_.emplace_back(std::min(p.index, q.index), std::max(p.index, q.index));
    }
  }
  std::sort(pairs_.begin(), pairs_.end());  // (few: the circles overlap in x and y)
}

// Actors do not collide with each other in the physics (they are immobile there): their
// boxes are compared here, once per engine step, those that may meet (candidate_pairs) in
// the order of a loop over every pair.
void RoadUserActors::after_step() {
  const int64_t now = ctx_->time_ns;
  candidate_pairs();
  for (const auto& [i, j] : pairs_) {
    const Actor& a = actors_[i];
    const Actor& b = actors_[j];
    if (boxes_overlap(a, b)) note_overlap(a, b, now);
  }
}

void RoadUserActors::note_overlap(const Actor& a, const Actor& b, int64_t now) {
  if (a.created_ns == now && b.created_ns == now) {
    // Both appear in this step, on top of each other: a placement error, not a crash.
    const Eigen::Vector3d p = a.pose.translation();
    char where[64];
    std::snprintf(where, sizeof where, "(%.2f, %.2f)", p.x(), p.y());
    throw std::runtime_error(
        "engine '" + ctx_->engine + "': road users '" + a.id + "' and '" + b.id +
        "' are placed on the same spot: their boxes overlap where they first appear, at " + where +
        ", t = " + std::to_string(ctx_->time_s()) +
        " s. Give one of them another start (its engine's Route, StartS or Position)");
  }
  if (contacts_)
    contacts_->note_contact(ctx_->physics->actor_skeleton(a.physics),
                            ctx_->physics->actor_skeleton(b.physics));
}

// Separating axes of two boxes yawed about z, plus their heights.
bool RoadUserActors::boxes_overlap(const Actor& a, const Actor& b) {
  const Eigen::Vector3d ca = a.pose * Eigen::Vector3d(0, 0, a.half.z());
  const Eigen::Vector3d cb = b.pose * Eigen::Vector3d(0, 0, b.half.z());
  if (std::abs(ca.z() - cb.z()) > a.half.z() + b.half.z()) return false;
  const Eigen::Vector2d d = (cb - ca).head<2>();
  if (d.norm() > a.half.head<2>().norm() + b.half.head<2>().norm()) return false;
  const Eigen::Vector2d axes[4] = {
      a.pose.linear().col(0).head<2>().normalized(), a.pose.linear().col(1).head<2>().normalized(),
      b.pose.linear().col(0).head<2>().normalized(), b.pose.linear().col(1).head<2>().normalized()};
  auto radius = [&](const Actor& s, int first, const Eigen::Vector2d& axis) {
    return s.half.x() * std::abs(axes[first].dot(axis)) +
           s.half.y() * std::abs(axes[first + 1].dot(axis));
  };
  for (const auto& axis : axes) {
    if (std::abs(d.dot(axis)) > radius(a, 0, axis) + radius(b, 2, axis)) return false;
  }
  return true;
}

// No actors; the model library and the warnings given stay.
void RoadUserActors::reset() {
  actors_.clear();
  by_id_.clear();
  free_.clear();
  pending_ = 0;
}

}  // namespace convoy::world
