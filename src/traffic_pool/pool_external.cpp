// External road users in the pool (the ego, agent engines' road users), and the crossings walkers
// have stepped onto (PoolWalkers::crossing_box): obstacles the vehicles' step never moves. Each
// step every external becomes one grid entry (its true box: junction look-ahead, respawn checks,
// overlaps) and one lane entry on each lane its box reaches (within kLaneReach m of the lane's
// centre line), placed at the box's extent along that lane and moving at its speed along it (never
// backwards). Lane entries are what leaders, MOBIL's neighbours, occupied junction lanes and free
// exits are read from.
#include <algorithm>
#include <cmath>
#include <set>

#include "traffic_pool/pool.h"

namespace convoy::traffic_pool {

namespace {
constexpr double kPointCell = 10;   // m: cells of the lane sample points' index
constexpr double kLaneReach = 1.1;  // m from a lane's centre line a box must reach to be on it
}  // namespace

void Pool::set_external(std::vector<ExternalUser> users) { ext_ = std::move(users); }

// Every lane's sample points by 10 m cell (counting sort), for finding the lanes near a point.
void Pool::index_lane_points() {
  px_ = std::max(1, static_cast<int>((net_.max_x - net_.min_x + 40) / kPointCell) + 1);
  py_ = std::max(1, static_cast<int>((net_.max_y - net_.min_y + 40) / kPointCell) + 1);
  auto cell_of = [&](const opendrive::Pose2& p) {
    const int cx = std::clamp(static_cast<int>((p.x - net_.min_x + 20) / kPointCell), 0, px_ - 1);
    const int cy = std::clamp(static_cast<int>((p.y - net_.min_y + 20) / kPointCell), 0, py_ - 1);
    return static_cast<size_t>(cy) * px_ + cx;
  };
  point_begin_.assign(static_cast<size_t>(px_) * py_ + 1, 0);
  for (const PoolLane& l : net_.lanes()) {
    for (const opendrive::Pose2& p : l.poses) ++point_begin_[cell_of(p) + 1];
  }
  for (size_t c = 0; c + 1 < point_begin_.size(); ++c) point_begin_[c + 1] += point_begin_[c];
  std::vector<uint32_t> fill(point_begin_.begin(), point_begin_.end() - 1);
  points_.resize(point_begin_.back());
  for (uint32_t l = 0; l < net_.lanes().size(); ++l) {
    const std::vector<opendrive::Pose2>& poses = net_.lane(l).poses;
    for (uint32_t k = 0; k < poses.size(); ++k) {
      points_[fill[cell_of(poses[k])]++] = (static_cast<uint64_t>(l) << 32) | k;
    }
  }
}

void Pool::add_lane_entry(uint32_t e, uint32_t lane, double s_centre, double half_along, double v) {
  const ExternalUser& u = obs_[e];
  VehicleSpec sp;
  sp.id = u.id;
  sp.length = 2 * half_along;  // its extent along the lane: the gap to it is measured so
  sp.width = u.width;
  specs_.push_back(std::move(sp));
  lane_.push_back(lane);
  s_.push_back(s_centre + half_along);  // the front of its extent, as a pooled vehicle's s
  v_.push_back(v);
  x_.push_back(u.x);
  y_.push_back(u.y);
  yaw_.push_back(u.yaw);
  ext_of_.push_back(e);
}

void Pool::place_externals() {
  lane_.resize(n_);
  for (auto* a : {&s_, &v_, &x_, &y_, &yaw_}) a->resize(n_);
  specs_.resize(n_);
  ext_of_.clear();
  obs_ = ext_;
  if (walkers_) {
    PoolWalkers::Box b;
    for (size_t w = 0; w < walkers_->size(); ++w) {
      if (walkers_->crossing_box(w, b)) {
        obs_.push_back({walkers_->spec(w).id, b.x, b.y, b.yaw, 0, b.length, b.width});
      }
    }
  }
  for (uint32_t e = 0; e < obs_.size(); ++e) {  // grid entries
    const ExternalUser& u = obs_[e];
    VehicleSpec sp;
    sp.id = u.id;
    sp.length = u.length;
    sp.width = u.width;
    specs_.push_back(std::move(sp));
    lane_.push_back(kNone);
    s_.push_back(0);
    v_.push_back(u.speed);
    x_.push_back(u.x);
    y_.push_back(u.y);
    yaw_.push_back(u.yaw);
    ext_of_.push_back(e);
  }
  grid_end_ = lane_.size();
  if (obs_.empty()) return;
  if (point_begin_.empty()) index_lane_points();
  if (feeders_.empty()) {  // junction lane -> the approaches into it (external_arriving)
    feeders_.resize(net_.lanes().size());
    for (uint32_t a = 0; a < net_.lanes().size(); ++a) {
      if (net_.lane(a).approach < 0) continue;
      for (uint32_t n : net_.lane(a).next) feeders_[n].push_back(a);
    }
  }
  for (uint32_t e = 0; e < obs_.size(); ++e) add_lane_entries(e);
}

// A lane entry for external e on each lane whose centre line its box comes within kLaneReach
// of (the lane's nearest sample point to its centre), its extent along the lane on the lane.
void Pool::add_lane_entries(uint32_t e) {
  const ExternalUser& u = obs_[e];
  std::vector<std::pair<uint32_t, uint32_t>> nearest;  // (lane, pose index), one per lane
  std::vector<double> d2;
  {
    const double r = 0.5 * std::hypot(u.length, u.width) + kLaneReach + 1;
    const int x0 = std::max(0, static_cast<int>((u.x - r - net_.min_x + 20) / kPointCell));
    const int x1 = std::min(px_ - 1, static_cast<int>((u.x + r - net_.min_x + 20) / kPointCell));
    const int y0 = std::max(0, static_cast<int>((u.y - r - net_.min_y + 20) / kPointCell));
    const int y1 = std::min(py_ - 1, static_cast<int>((u.y + r - net_.min_y + 20) / kPointCell));
    nearest.clear();
    d2.clear();
    for (int cy = y0; cy <= y1; ++cy) {
      for (int cx = x0; cx <= x1; ++cx) {
        const size_t c = static_cast<size_t>(cy) * px_ + cx;
        for (uint32_t k = point_begin_[c]; k < point_begin_[c + 1]; ++k) {
          const auto lane = static_cast<uint32_t>(points_[k] >> 32);
          const auto idx = static_cast<uint32_t>(points_[k] & 0xffffffffu);
          const opendrive::Pose2& p = net_.lane(lane).poses[idx];
          const double d = (p.x - u.x) * (p.x - u.x) + (p.y - u.y) * (p.y - u.y);
          auto it = std::find_if(nearest.begin(), nearest.end(),
                                 [&](const auto& n) { return n.first == lane; });
          if (it == nearest.end()) {
            nearest.emplace_back(lane, idx);
            d2.push_back(d);
          } else if (d < d2[it - nearest.begin()]) {
            it->second = idx;
            d2[it - nearest.begin()] = d;
          }
        }
      }
    }
    for (const auto& [lane, idx] : nearest) {
      const PoolLane& l = net_.lane(lane);
      const opendrive::Pose2& p = l.poses[idx];
      const double c = std::cos(p.heading), sn = std::sin(p.heading);
      const double along = (u.x - p.x) * c + (u.y - p.y) * sn;
      const double lat = -(u.x - p.x) * sn + (u.y - p.y) * c;
      const double dyaw = u.yaw - p.heading;
      const double ca = std::abs(std::cos(dyaw)), sa = std::abs(std::sin(dyaw));
      const double half_lat = 0.5 * (u.length * sa + u.width * ca);
      const double half_along = 0.5 * (u.length * ca + u.width * sa);
      if (std::abs(lat) > half_lat + kLaneReach) continue;
      const double s_centre = std::min(idx * l.ds, l.length) + along;
      if (s_centre + half_along < 0 || s_centre - half_along > l.length) continue;
      add_lane_entry(e, lane, s_centre, half_along, std::max(0.0, u.speed * std::cos(dyaw)));
    }
  }
}

void Pool::set_walkers(std::vector<WalkerSpec> specs) {
  std::set<std::string> ids;
  for (size_t i = 0; i < n_; ++i) ids.insert(specs_[i].id);
  for (const WalkerSpec& w : specs) {
    if (ids.count(w.id)) throw PoolError("road user '" + w.id + "' is listed twice");
  }
  walkers_.reset();
  if (!specs.empty()) walkers_.emplace(net_, std::move(specs));
}

// The walkers' step, after the vehicles': the threats to a crossing are the pooled vehicles
// (present) and the externals, found in the grid (built before the vehicles moved: 3 m more).
void Pool::step_walkers(double dt) {
  if (!walkers_) return;
  walkers_->step(
      dt, t_,
      [&](double x, double y, double r, std::vector<road_users::CrossingVehicle>& out) {
        for_near(x, y, r + 3, [&](uint32_t k) {
          if (k < n_ ? !present(k) : ext_of_[k - n_] >= ext_.size()) return;
          if (std::hypot(x_[k] - x, y_[k] - y) > r) return;
          out.push_back({x_[k], y_[k], yaw_[k], v_[k], specs_[k].length, specs_[k].width, 0.0});
        });
      },
      lane_light_.empty() ? nullptr : &lane_light_);
}

void Pool::set_light_states(const road_users::LightStates& states) {
  lane_light_.resize(net_.lanes().size());
  for (uint32_t l = 0; l < lane_light_.size(); ++l) lane_light_[l] = net_.signal_light(l, states);
}

road_users::Light Pool::light(uint32_t lane, uint32_t next) const {
  if (lane_light_.empty()) return net_.light(lane, t_);
  return stricter(lane_light_[lane], next == kNone ? road_users::Light::kOff : lane_light_[next]);
}

// An external road user (the ego, an agent) coming up an approach into `junction_lane`: it
// neither claims junction lanes nor reads the pool's claims, so a pooled vehicle must not
// claim a lane crossing its way in front of it. Coming: moving (over 1 m/s) and within 4 s
// (+5 m) of the line, unless its light is red and it can still stop (3 m/s^2). Where it
// turns is not known: any lane of its approach counts.
bool Pool::external_arriving(uint32_t junction_lane) const {
  if (obs_.empty() || feeders_.empty()) return false;
  for (uint32_t a : feeders_[junction_lane]) {
    const road_users::Light light = this->light(a, junction_lane);
    for (uint32_t r = lane_begin_[a]; r < lane_begin_[a + 1]; ++r) {
      const uint32_t k = order_[r];
      if (k < n_ || v_[k] <= 1.0) continue;  // pooled vehicles claim; standing ones wait
      const double dist = net_.lane(a).length - s_[k];
      if (dist > 4 * v_[k] + 5) continue;
      const bool red = light == road_users::Light::kRed || light == road_users::Light::kRedYellow;
      if (red && dist > v_[k] * v_[k] / (2 * 3.0) + 1) continue;  // it stops there
      return true;
    }
  }
  return false;
}

}  // namespace convoy::traffic_pool
