#include "contact_cap.h"

#include <algorithm>
#include <dart/collision/CollisionObject.hpp>
#include <dart/collision/CollisionResult.hpp>

namespace convoy::world {

namespace dc = dart::collision;

std::shared_ptr<CappedBulletDetector> CappedBulletDetector::create(int world_limit) {
  return std::shared_ptr<CappedBulletDetector>(new CappedBulletDetector(world_limit));
}

void CappedBulletDetector::limit_shape(const dart::dynamics::ShapeFrame* shape, int limit) {
  if (limit > 0) limits_[shape] = limit;
}

int CappedBulletDetector::pair_limit(const dart::dynamics::ShapeFrame* a,
                                     const dart::dynamics::ShapeFrame* b) const {
  int limit = world_limit_;
  for (const auto* s : {a, b}) {
    auto it = limits_.find(s);
    if (it != limits_.end() && (limit == 0 || it->second < limit)) limit = it->second;
  }
  return limit;
}

bool CappedBulletDetector::collide(dc::CollisionGroup* group, const dc::CollisionOption& option,
                                   dc::CollisionResult* result) {
  const bool hit = BulletCollisionDetector::collide(group, option, result);
  if (result && (world_limit_ > 0 || !limits_.empty())) cap(result);
  return hit;
}

void CappedBulletDetector::cap(dc::CollisionResult* result) {
  const auto& contacts = result->getContacts();
  const size_t n = contacts.size();
  auto frames = [&](size_t i) {
    const auto* a = contacts[i].collisionObject1->getShapeFrame();
    const auto* b = contacts[i].collisionObject2->getShapeFrame();
    return a < b ? std::make_pair(a, b) : std::make_pair(b, a);
  };
  // Each contact's pair, named by the pair's first contact (a handful of contacts a step).
  first_.assign(n, 0);
  for (size_t i = 0; i < n; ++i) {
    first_[i] = i;
    for (size_t k = 0; k < i; ++k) {
      if (first_[k] == k && frames(k) == frames(i)) {
        first_[i] = k;
        break;
      }
    }
  }
  // Per pair, deepest first (ties in Bullet's order); keep the first pair_limit() of each.
  order_.resize(n);
  for (size_t i = 0; i < n; ++i) order_[i] = i;
  std::stable_sort(order_.begin(), order_.end(), [&](size_t x, size_t y) {
    if (first_[x] != first_[y]) return first_[x] < first_[y];
    return contacts[x].penetrationDepth > contacts[y].penetrationDepth;
  });
  keep_.assign(n, 0);
  bool dropped = false;
  for (size_t r = 0; r < n;) {
    const size_t pair = first_[order_[r]];
    const auto [a, b] = frames(pair);
    const int limit = pair_limit(a, b);
    size_t taken = 0;
    for (; r < n && first_[order_[r]] == pair; ++r, ++taken) {
      const bool keep = limit == 0 || taken < static_cast<size_t>(limit);
      keep_[order_[r]] = keep;
      dropped |= !keep;
    }
  }
  if (!dropped) return;
  kept_.clear();
  for (size_t i = 0; i < n; ++i) {
    if (keep_[i]) kept_.push_back(contacts[i]);
  }
  result->clear();
  for (const auto& c : kept_) result->addContact(c);
}

}  // namespace convoy::world
