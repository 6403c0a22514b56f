// scene_json.h: the scene as foxglove.SceneUpdate / FrameTransforms JSON, checked against
// the JSON Schemas (record/scene_schemas.h) and Foxglove's field names.
#include "scene/scene_json.h"

#include <gtest/gtest.h>

#include <cmath>

#include "record/scene_schemas.h"
#include "scene_test_util.h"

namespace convoy::scene {
namespace {

using nlohmann::json;
using testing::expect_valid;
using testing::json_datapack;
using testing::proto_datapack;
using testing::user;

const std::set<std::string> kEntityKeys = {
    "timestamp", "frame_id", "id",    "lifetime",  "frame_locked", "metadata", "arrows",
    "cubes",     "spheres",  "lines", "cylinders", "triangles",    "texts",    "models"};

std::set<std::string> keys(const json& j) {
  std::set<std::string> out;
  for (const auto& [k, v] : j.items()) out.insert(k);
  return out;
}

std::string meta(const json& entity, const std::string& key) {
  for (const json& kv : entity["metadata"])
    if (kv["key"] == key) return kv["value"];
  return "<none>";
}

const json* find_entity(const json& update, const std::string& id) {
  for (const json& e : update["entities"])
    if (e["id"] == id) return &e;
  return nullptr;
}

SceneState sample_state() {
  SceneOptions o;
  o.world_engines = {"gazebo"};
  SceneState s(o);
  const auto blobs = []() -> const datapack::BlobReader& { return datapack::inline_blob_reader(); };
  auto ego = user("smart_car", "car", 0, 0, M_PI / 2);
  ego.set_length(4);
  ego.set_width(2);
  ego.set_height(1.5);
  ego.set_length_offset(1);
  ego.set_speed(3.25);
  for (int i = 0; i < 3; ++i) {
    ego.set_y(i * 1.0);
    const auto dp = proto_datapack("smart_car::road_user", ego);
    s.ingest("gazebo", datapack::View(dp, blobs()), i * 100000000LL);
  }
  const auto ped =
      json_datapack("state", {{"id", "ped_0"}, {"category", "pedestrian"}, {"x", 5}, {"y", 1}});
  s.ingest("ped_0", datapack::View(ped, blobs()), 0);
  const auto truck = proto_datapack("state", user("truck_0", "truck", -5, 0));
  s.ingest("truck_0", datapack::View(truck, blobs()), 0);
  auto gone = user("car_9", "car", 0, 0);
  gone.set_absent(true);
  const auto car = proto_datapack("state", user("car_9", "car", 0, 0));
  const auto absent = proto_datapack("state", gone);
  s.ingest("car_9", datapack::View(car, blobs()), 0);
  s.ingest("car_9", datapack::View(absent, blobs()), 0);
  const auto lights =
      json_datapack("traffic_lights", {{"signals", {{"s1", "red"}, {"s2", "green"}}}});
  s.ingest("lights", datapack::View(lights, blobs()), 0);
  return s;
}

TEST(SceneJson, RoadUsersAsCubesWithFoxglovesFieldNames) {
  const SceneState s = sample_state();
  const json u = json::parse(scene_update_json(s, nullptr, 1500000000));
  expect_valid(u, json::parse(record::scene_update_schema().data));
  EXPECT_EQ(keys(u), (std::set<std::string>{"deletions", "entities"}));
  ASSERT_EQ(u["deletions"].size(), 1u);
  EXPECT_EQ(u["deletions"][0],
            json({{"timestamp", {{"sec", 1}, {"nsec", 500000000}}}, {"type", 0}, {"id", "car_9"}}));
  for (const json& e : u["entities"]) {
    EXPECT_EQ(keys(e), kEntityKeys) << e["id"];
    EXPECT_EQ(e["frame_id"], "map");
    EXPECT_EQ(e["lifetime"], json({{"sec", 0}, {"nsec", 0}}));
  }
  const json* ego = find_entity(u, "smart_car");
  ASSERT_NE(ego, nullptr);
  EXPECT_EQ(meta(*ego, "ego"), "true");
  EXPECT_EQ(meta(*ego, "category"), "car");
  EXPECT_EQ(meta(*ego, "speed"), "3.25");
  const json& cube = (*ego)["cubes"][0];
  EXPECT_EQ(keys(cube), (std::set<std::string>{"pose", "size", "color"}));
  // The box centre is length_offset ahead of the reference point (heading +y), half its
  // height up; the orientation is the yaw's quaternion.
  EXPECT_NEAR(cube["pose"]["position"]["x"].get<double>(), 0, 1e-9);
  EXPECT_NEAR(cube["pose"]["position"]["y"].get<double>(), 3, 1e-9);
  EXPECT_NEAR(cube["pose"]["position"]["z"].get<double>(), 0.75, 1e-9);
  EXPECT_NEAR(cube["pose"]["orientation"]["z"].get<double>(), std::sqrt(0.5), 1e-6);
  EXPECT_NEAR(cube["pose"]["orientation"]["w"].get<double>(), std::sqrt(0.5), 1e-6);
  EXPECT_EQ(cube["size"], json({{"x", 4.0}, {"y", 2.0}, {"z", 1.5}}));
  EXPECT_EQ(keys(cube["color"]), (std::set<std::string>{"r", "g", "b", "a"}));
  // Colours by category: ego red, pedestrian orange, truck purple.
  EXPECT_GT(cube["color"]["r"].get<double>(), 0.8);
  EXPECT_LT(cube["color"]["b"].get<double>(), 0.2);
  const json& ped = (*find_entity(u, "ped_0"))["cubes"][0];
  EXPECT_EQ(ped["color"]["r"], 1.0);
  EXPECT_NEAR(ped["size"]["z"].get<double>(), 1.75, 1e-9);  // a pedestrian's usual height
  EXPECT_EQ(meta(*find_entity(u, "ped_0"), "ego"), "false");
  EXPECT_GT((*find_entity(u, "truck_0"))["cubes"][0]["color"]["b"].get<double>(), 0.7);
  const json& text = (*ego)["texts"][0];
  EXPECT_EQ(keys(text), (std::set<std::string>{"pose", "billboard", "font_size", "scale_invariant",
                                               "color", "text"}));
  // The trail: the ego's three positions.
  const json* trail = find_entity(u, "ego/trail");
  ASSERT_NE(trail, nullptr);
  const json& line = (*trail)["lines"][0];
  EXPECT_EQ(keys(line), (std::set<std::string>{"type", "pose", "thickness", "scale_invariant",
                                               "points", "color", "colors", "indices"}));
  EXPECT_EQ(line["type"], 0);
  EXPECT_EQ(line["points"].size(), 3u);
  EXPECT_EQ(find_entity(u, "ego/route"), nullptr);  // none given
}

TEST(SceneJson, SignalsColouredByStateWhereTheMapPutsThem) {
  const SceneState s = sample_state();
  SceneMap map;
  map.signals = {{"s1", {1, 2, 3}, false}, {"s2", {4, 5, 6}, false}, {"s3", {7, 8, 9}, true}};
  const json u = json::parse(scene_update_json(s, &map, 0));
  const json* sig = find_entity(u, "signals");
  ASSERT_NE(sig, nullptr);
  EXPECT_EQ(meta(*sig, "signal/s1"), "red");
  EXPECT_EQ(meta(*sig, "signal/s2"), "green");
  ASSERT_EQ((*sig)["spheres"].size(), 3u);
  const json& red = (*sig)["spheres"][0];
  EXPECT_EQ(red["pose"]["position"], json({{"x", 1.0}, {"y", 2.0}, {"z", 3.0}}));
  EXPECT_EQ(red["color"]["r"], 1.0);
  EXPECT_LT(red["color"]["g"].get<double>(), 0.2);
  const json& green = (*sig)["spheres"][1];
  EXPECT_LT(green["color"]["r"].get<double>(), 0.2);
  EXPECT_GT(green["color"]["g"].get<double>(), 0.8);
  const json& off = (*sig)["spheres"][2];  // no state: off, grey
  EXPECT_EQ(off["color"]["r"], off["color"]["g"]);
}

TEST(SceneJson, TransformsFromTheMapToEachEgo) {
  const SceneState s = sample_state();
  const json t = json::parse(frame_transforms_json(s, 2000000000));
  expect_valid(t, json::parse(record::frame_transforms_schema().data));
  ASSERT_EQ(t["transforms"].size(), 1u);
  const json& tf = t["transforms"][0];
  EXPECT_EQ(keys(tf), (std::set<std::string>{"timestamp", "parent_frame_id", "child_frame_id",
                                             "translation", "rotation"}));
  EXPECT_EQ(tf["parent_frame_id"], "map");
  EXPECT_EQ(tf["child_frame_id"], "smart_car");
  EXPECT_EQ(tf["timestamp"], json({{"sec", 2}, {"nsec", 0}}));
  EXPECT_EQ(tf["translation"], json({{"x", 0.0}, {"y", 2.0}, {"z", 0.0}}));
  EXPECT_NEAR(tf["rotation"]["z"].get<double>(), std::sqrt(0.5), 1e-6);
}

TEST(SceneJson, TheSameStateGivesTheSameBytes) {
  const SceneState a = sample_state(), b = sample_state();
  EXPECT_EQ(scene_update_json(a, nullptr, 7), scene_update_json(b, nullptr, 7));
  EXPECT_EQ(frame_transforms_json(a, 7), frame_transforms_json(b, 7));
}

TEST(SceneJson, AFrameNote) {
  const json f = json::parse(frame_json("eng/cam/image", 42, 1700000000123.5));
  EXPECT_EQ(f, json({{"topic", "eng/cam/image"}, {"time_ns", 42}, {"wall_ms", 1700000000123.5}}));
  expect_valid(f, json::parse(record::camera_frame_schema().data));
}

}  // namespace
}  // namespace convoy::scene
