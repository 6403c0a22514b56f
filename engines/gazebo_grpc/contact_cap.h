// Contacts capped per pair of collision shapes, as SDF's <max_contacts> asks: a collision's
// <max_contacts> and the world's <physics><max_contacts> bound the contacts between two
// shapes; the least bound applies and the deepest contacts stay (Gazebo's rule). Unset bounds
// (the SDF leaves them out) keep every contact Bullet finds, so worlds without them step as
// before, bit for bit.
#pragma once

#include <dart/collision/bullet/BulletCollisionDetector.hpp>
#include <memory>
#include <unordered_map>
#include <vector>

namespace convoy::world {

class CappedBulletDetector : public dart::collision::BulletCollisionDetector {
 public:
  // world_limit: the world's <physics><max_contacts> (0: none).
  static std::shared_ptr<CappedBulletDetector> create(int world_limit);

  // The <max_contacts> of one collision shape (limit > 0).
  void limit_shape(const dart::dynamics::ShapeFrame* shape, int limit);
  // The bound for a pair of shapes: the least of the world's and the two shapes' (0: none).
  int pair_limit(const dart::dynamics::ShapeFrame* a, const dart::dynamics::ShapeFrame* b) const;

  using BulletCollisionDetector::collide;
  // Bullet's contacts, then at most pair_limit() of them per pair of shapes, the deepest.
  bool collide(dart::collision::CollisionGroup* group,
               const dart::collision::CollisionOption& option,
               dart::collision::CollisionResult* result) override;

  // Caps `result` in place (the contacts kept keep their order).
  void cap(dart::collision::CollisionResult* result);

 protected:
  explicit CappedBulletDetector(int world_limit) : world_limit_(world_limit) {}

 private:
  int world_limit_ = 0;
  std::unordered_map<const dart::dynamics::ShapeFrame*, int> limits_;
  // cap()'s, reused: per contact its pair's first contact, and the contacts kept.
  std::vector<size_t> first_, order_;
  std::vector<char> keep_;
  std::vector<dart::collision::Contact> kept_;
};

}  // namespace convoy::world
