// The scene as Foxglove messages in their JSON encoding (timestamps {sec, nsec}), with the
// JSON Schemas of record/scene_schemas.h:
//   /convoy/map         foxglove.SceneUpdate: entities "lanes" (lane borders), "centres"
//                       (driving lane centres), "signal/<id>" (a light's position)
//   /convoy/scene       foxglove.SceneUpdate: one entity per road user (a cube, id =
//                       RoadUser.id), "ego/route", "ego/trail", "signals"; deletions for the
//                       road users gone since the last update
//   /convoy/transforms  foxglove.FrameTransforms: map -> each ego (child frame = its id)
//   /convoy/frames      {"topic", "time_ns", "wall_ms"} per camera frame (live only)
// Frame "map": x east, y north, z up, metres. Numbers are rounded (mm in the scene, cm in the
// map) and keys sorted, so the same state gives the same bytes.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "scene/scene_map.h"
#include "scene/scene_state.h"

namespace convoy::scene {

inline constexpr const char* kMapTopic = "/convoy/map";
inline constexpr const char* kSceneTopic = "/convoy/scene";
inline constexpr const char* kTransformsTopic = "/convoy/transforms";
inline constexpr const char* kFramesTopic = "/convoy/frames";
inline constexpr const char* kMapFrame = "map";

std::string map_update_json(const SceneMap& map, uint64_t time_ns);
// `map` (may be null) places the signals' state spheres.
std::string scene_update_json(const SceneState& state, const SceneMap* map, uint64_t time_ns);
std::string frame_transforms_json(const SceneState& state, uint64_t time_ns);
std::string frame_json(std::string_view topic, uint64_t time_ns, double wall_ms);

}  // namespace convoy::scene
