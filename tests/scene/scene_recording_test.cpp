// The recorder's scene channels (record/recorder.h): /convoy/map once, /convoy/scene and
// /convoy/transforms at scene_hz, read back from the MCAP file; and what functions publish for
// viewers (/convoy/metrics merged, /convoy/infractions).
#include <gtest/gtest.h>

#include <filesystem>

#include "record/mcap_reader.h"
#include "record/recorder.h"
#include "scene/scene_json.h"
#include "scene_test_util.h"

namespace convoy::scene {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

TEST(SceneRecording, MapOnceSceneAndTransformsAtTheirRate) {
  const fs::path file =
      fs::temp_directory_path() / ("convoy_scene_rec_" + std::to_string(getpid()) + ".mcap");
  record::RecorderOptions o;
  o.map = std::make_shared<const SceneMap>(
      load_scene_map(std::string(CONVOY_OPENDRIVE_TEST_DATA) + "/lane_graph.xodr"));
  o.scene.world_engines = {"gazebo"};
  o.scene_hz = 10;
  {
    record::Recorder rec(file, false, {{"convoy_version", "test"}}, o);
    // 1 s at 50 Hz: the ego and a car drive along x.
    for (int i = 0; i <= 50; ++i) {
      const int64_t t = i * 20000000LL;
      rec.from_engine("gazebo",
                      testing::proto_datapack("smart_car::road_user",
                                              testing::user("smart_car", "car", 0.2 * i, 0)),
                      datapack::inline_blob_reader(), i, t);
      rec.from_engine("car_0",
                      testing::proto_datapack("state", testing::user("car_0", "car", 0.3 * i, 4)),
                      datapack::inline_blob_reader(), i, t);
    }
    EXPECT_EQ(rec.finish({}), "");
  }
  record::McapReader r(file);
  std::map<std::string, std::vector<std::pair<uint64_t, std::string>>> by_topic;
  record::McapMessage m;
  while (r.next(&m)) by_topic[r.channels().at(m.channel).topic].push_back({m.log_time, m.data});
  ASSERT_EQ(by_topic[kMapTopic].size(), 1u);
  EXPECT_EQ(json::parse(by_topic[kMapTopic][0].second)["entities"][0]["id"], "lanes");
  const auto& scenes = by_topic[kSceneTopic];
  ASSERT_EQ(scenes.size(), 10u);  // 0, 0.1, ... 0.9 s (the last cycle is not complete)
  EXPECT_EQ(scenes[3].first, 300000000u);
  std::vector<double> car_x;
  for (const auto& [t, data] : scenes) {
    const json update = json::parse(data);
    for (const json& e : update["entities"])
      if (e["id"] == "car_0") car_x.push_back(e["cubes"][0]["pose"]["position"]["x"]);
  }
  ASSERT_EQ(car_x.size(), 10u);
  EXPECT_GT(car_x.back(), car_x.front() + 2.0);  // it moves
  ASSERT_EQ(by_topic[kTransformsTopic].size(), 10u);
  EXPECT_EQ(json::parse(by_topic[kTransformsTopic][9].second)["transforms"][0]["child_frame_id"],
            "smart_car");
  for (const auto& [id, ch] : r.channels()) {
    if (ch.topic == kSceneTopic || ch.topic == kMapTopic) {
      EXPECT_EQ(r.schemas().at(ch.schema_id).name, "foxglove.SceneUpdate");
    }
    if (ch.topic == kTransformsTopic) {
      EXPECT_EQ(r.schemas().at(ch.schema_id).name, "foxglove.FrameTransforms");
    }
  }
  fs::remove(file);
}

TEST(SceneRecording, MetricsMergedInfractionsEachOthersRefused) {
  const fs::path file =
      fs::temp_directory_path() / ("convoy_metrics_rec_" + std::to_string(getpid()) + ".mcap");
  {
    record::Recorder rec(file, false, {{"convoy_version", "test"}});
    EXPECT_TRUE(rec.viewer_json("/convoy/metrics", R"({"driving_score":50,"a":1})", 1000));
    EXPECT_TRUE(rec.viewer_json("/convoy/metrics", R"({"driving_score":40})", 2000));
    EXPECT_TRUE(rec.viewer_json("/convoy/infractions", R"({"kind":"red_light"})", 1500));
    EXPECT_FALSE(rec.viewer_json("/convoy/other", R"({"x":1})", 3000));
    EXPECT_FALSE(rec.viewer_json("/convoy/metrics", "[1, 2]", 3000));
    EXPECT_FALSE(rec.viewer_json("/convoy/metrics", "{broken", 3000));
    EXPECT_EQ(rec.finish({}), "");
  }
  record::McapReader r(file);
  std::vector<json> metrics, infractions;
  record::McapMessage m;
  while (r.next(&m)) {
    const auto& ch = r.channels().at(m.channel);
    EXPECT_EQ(ch.metadata.at("viewer"), "metrics");  // a replay leaves them out
    (ch.topic == "/convoy/metrics" ? metrics : infractions).push_back(json::parse(m.data));
  }
  ASSERT_EQ(metrics.size(), 2u);
  EXPECT_EQ(metrics[1], json({{"driving_score", 40}, {"a", 1}, {"time_ns", 2000}}));
  ASSERT_EQ(infractions.size(), 1u);
  EXPECT_EQ(infractions[0]["kind"], "red_light");
  fs::remove(file);
}

}  // namespace
}  // namespace convoy::scene
