#include "record/scene_schemas.h"

#include <nlohmann/json.hpp>
#include <utility>

namespace convoy::record {

namespace {

using json = nlohmann::json;

json object(const char* title, json properties) {
  return {{"title", title}, {"type", "object"}, {"properties", std::move(properties)}};
}
json number() { return {{"type", "number"}}; }
json string() { return {{"type", "string"}}; }
json boolean() { return {{"type", "boolean"}}; }
json array_of(json items) { return {{"type", "array"}, {"items", std::move(items)}}; }

json time(bool duration = false) {
  json sec = {{"type", "integer"}};
  if (!duration) sec["minimum"] = 0;
  return object(
      duration ? "duration" : "time",
      {{"sec", sec}, {"nsec", {{"type", "integer"}, {"minimum", 0}, {"maximum", 999999999}}}});
}
json vector3(const char* title = "foxglove.Vector3") {
  return object(title, {{"x", number()}, {"y", number()}, {"z", number()}});
}
json quaternion() {
  return object("foxglove.Quaternion",
                {{"x", number()}, {"y", number()}, {"z", number()}, {"w", number()}});
}
json color() {
  return object("foxglove.Color",
                {{"r", number()}, {"g", number()}, {"b", number()}, {"a", number()}});
}
json pose() {
  return object("foxglove.Pose", {{"position", vector3()}, {"orientation", quaternion()}});
}
json enumeration(std::initializer_list<int> values) {
  return {{"type", "integer"}, {"enum", values}};
}

json primitives() {
  const json sized = {{"pose", pose()}, {"size", vector3()}, {"color", color()}};
  return {
      {"arrows", array_of(object("foxglove.ArrowPrimitive", {{"pose", pose()},
                                                             {"shaft_length", number()},
                                                             {"shaft_diameter", number()},
                                                             {"head_length", number()},
                                                             {"head_diameter", number()},
                                                             {"color", color()}}))},
      {"cubes", array_of(object("foxglove.CubePrimitive", sized))},
      {"spheres", array_of(object("foxglove.SpherePrimitive", sized))},
      {"cylinders", array_of(object("foxglove.CylinderPrimitive", {{"pose", pose()},
                                                                   {"size", vector3()},
                                                                   {"bottom_scale", number()},
                                                                   {"top_scale", number()},
                                                                   {"color", color()}}))},
      {"lines", array_of(object("foxglove.LinePrimitive",
                                {{"type", enumeration({0, 1, 2})},
                                 {"pose", pose()},
                                 {"thickness", number()},
                                 {"scale_invariant", boolean()},
                                 {"points", array_of(vector3("foxglove.Point3"))},
                                 {"color", color()},
                                 {"colors", array_of(color())},
                                 {"indices", array_of({{"type", "integer"}, {"minimum", 0}})}}))},
      {"triangles",
       array_of(object("foxglove.TriangleListPrimitive",
                       {{"pose", pose()},
                        {"points", array_of(vector3("foxglove.Point3"))},
                        {"color", color()},
                        {"colors", array_of(color())},
                        {"indices", array_of({{"type", "integer"}, {"minimum", 0}})}}))},
      {"texts", array_of(object("foxglove.TextPrimitive", {{"pose", pose()},
                                                           {"billboard", boolean()},
                                                           {"font_size", number()},
                                                           {"scale_invariant", boolean()},
                                                           {"color", color()},
                                                           {"text", string()}}))},
      {"models",
       array_of(object("foxglove.ModelPrimitive",
                       {{"pose", pose()},
                        {"scale", vector3()},
                        {"color", color()},
                        {"override_color", boolean()},
                        {"url", string()},
                        {"media_type", string()},
                        {"data", {{"type", "string"}, {"contentEncoding", "base64"}}}}))}};
}

FoxgloveSchema schema(const char* name, json properties) {
  return {name, "jsonschema", object(name, std::move(properties)).dump()};
}

}  // namespace

FoxgloveSchema scene_update_schema() {
  json entity = {{"timestamp", time()},
                 {"frame_id", string()},
                 {"id", string()},
                 {"lifetime", time(true)},
                 {"frame_locked", boolean()},
                 {"metadata", array_of(object("foxglove.KeyValuePair",
                                              {{"key", string()}, {"value", string()}}))}};
  entity.update(primitives());
  return schema(
      "foxglove.SceneUpdate",
      {{"deletions",
        array_of(object("foxglove.SceneEntityDeletion",
                        {{"timestamp", time()}, {"type", enumeration({0, 1})}, {"id", string()}}))},
       {"entities", array_of(object("foxglove.SceneEntity", std::move(entity)))}});
}

FoxgloveSchema frame_transforms_schema() {
  return schema(
      "foxglove.FrameTransforms",
      {{"transforms", array_of(object("foxglove.FrameTransform", {{"timestamp", time()},
                                                                  {"parent_frame_id", string()},
                                                                  {"child_frame_id", string()},
                                                                  {"translation", vector3()},
                                                                  {"rotation", quaternion()}}))}});
}

FoxgloveSchema camera_frame_schema() {
  return schema("convoy.CameraFrame", {{"topic", string()},
                                       {"time_ns", {{"type", "integer"}, {"minimum", 0}}},
                                       {"wall_ms", number()}});
}

}  // namespace convoy::record
