// The object classes of world models (world_description.h): the fixed set, their labels, and
// what a model's name or shapes say about its class.
#include <algorithm>
#include <cctype>

#include "world_description.h"

namespace convoy::world {

const std::vector<std::string>& known_classes() {
  static const std::vector<std::string> classes = {
      "car",   "truck", "bus",           "pedestrian", "cyclist", "building", "tree",
      "shrub", "pole",  "traffic_light", "sign",       "barrier", "other"};
  return classes;
}

uint8_t class_label(const std::string& cls) {
  const auto& k = known_classes();
  for (size_t i = 0; i < k.size(); ++i)
    if (k[i] == cls) return static_cast<uint8_t>(i + 1);
  return 0;
}

bool is_known_class(const std::string& cls) {
  const auto& k = known_classes();
  return std::find(k.begin(), k.end(), cls) != k.end();
}

bool is_ground(const ModelDesc& model) {
  bool visual_planes = true, collision_planes = true, collides = false;
  for (const auto& link : model.links) {
    for (const auto& v : link.visuals) visual_planes &= v.shape.kind == Shape::kPlane;
    for (const auto& c : link.collisions) {
      collides = true;
      collision_planes &= c.shape.kind == Shape::kPlane || c.shape.kind == Shape::kHeightmap;
    }
  }
  return visual_planes || (model.is_static && collides && collision_planes);
}

std::string class_of_name(const std::string& model_name) {
  std::string s = model_name;
  auto scope = s.rfind("::");
  if (scope != std::string::npos) s = s.substr(scope + 2);
  while (!s.empty() && std::isdigit(static_cast<unsigned char>(s.back()))) s.pop_back();
  while (!s.empty() && (s.back() == '_' || s.back() == '-')) s.pop_back();
  return s.empty() ? model_name : s;
}

}  // namespace convoy::world
