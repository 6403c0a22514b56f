#include "live/live_tap.h"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "convoy/road_users.pb.h"
#include "datapack/camera.h"
#include "datapack/json.h"
#include "datapack/proto.h"
#include "live_client.h"
#include "loop/tap_fanout.h"
#include "record/datapack_codec.h"
#include "scene/scene_json.h"
#include "test_support/eventually.h"

namespace convoy::live {
namespace {

using testing::TestClient;
using json = nlohmann::json;

using test_support::eventually;

engine::DataPack json_datapack(double x) {
  engine::DataPack dp;
  dp.mutable_id()->set_name("state");
  dp.mutable_id()->set_engine_name("eng");
  datapack::InlineBlobWriter writer;
  datapack::Builder b(&dp, writer);
  datapack::write_json(b, {{"x", x}, {"name", "car"}});
  return dp;
}

engine::DataPack camera_datapack(uint8_t shade) {
  engine::DataPack dp;
  dp.mutable_id()->set_name("cam");
  dp.mutable_id()->set_engine_name("eng");
  datapack::InlineBlobWriter writer;
  datapack::Builder b(&dp, writer);
  datapack::write_camera(b, 24, 32, 3, std::string(24 * 32 * 3, static_cast<char>(shade)));
  return dp;
}

// The id of the advertised channel `topic`, reading advertise messages as they come. `seen`
// keeps the channels of the messages read, for the next call: a client that connects after
// several channels were added gets them in one message.
uint32_t channel_id(TestClient& c, const std::string& topic, json* schema = nullptr,
                    std::map<std::string, json>* seen = nullptr) {
  std::map<std::string, json> local;
  if (!seen) seen = &local;
  while (!seen->count(topic)) {
    const json adv = c.next_op("advertise");
    for (const auto& ch : adv["channels"]) (*seen)[ch["topic"]] = ch;
  }
  if (schema) *schema = seen->at(topic);
  return seen->at(topic)["id"];
}

struct LiveTapTest : ::testing::Test {
  LiveTapTest() : server(make_options()), tap(server, TapOptions{}) {}
  static ServerOptions make_options() {
    ServerOptions o;
    o.address = parse_listen_address("0");
    return o;
  }
  LiveServer server;
  LiveTap tap;
  const datapack::BlobReader& blobs = datapack::inline_blob_reader();
};

TEST_F(LiveTapTest, ADataPackIsEncodedOnlyForSubscribers) {
  TestClient client(server.port());
  tap.from_engine("eng", json_datapack(1.5), blobs, 0, 0);
  json ch;
  const uint32_t id = channel_id(client, "eng/state", &ch);
  EXPECT_EQ(ch["encoding"], "json");
  EXPECT_EQ(json::parse(ch["schema"].get<std::string>())["properties"]["x"]["type"], "number");
  EXPECT_EQ(tap.encoded(), 0u);
  client.subscribe(1, id);
  ASSERT_TRUE(eventually([&] { return server.has_subscribers(id); }));
  tap.from_engine("eng", json_datapack(2.5), blobs, 1, 20000000);
  auto [sub, t, payload] = client.next_data();
  EXPECT_EQ(sub, 1u);
  EXPECT_EQ(t, 20000000u);
  EXPECT_EQ(json::parse(payload)["x"], 2.5);
  EXPECT_EQ(tap.encoded(), 1u);
}

TEST_F(LiveTapTest, EmptyDataPacksGetNoChannel) {
  engine::DataPack empty;
  empty.mutable_id()->set_name("state");
  tap.from_engine("eng", empty, blobs, 0, 0);
  EXPECT_EQ(tap.channels(), 0u);
  tap.from_engine("eng", json_datapack(1), blobs, 1, 1);
  EXPECT_EQ(tap.channels(), 1u);
}

TEST_F(LiveTapTest, SentDataPacksHaveTheirOwnTopic) {
  TestClient client(server.port());
  loop::LoadedFunction fn;
  tap.to_engine("eng", json_datapack(1), blobs, fn, 0, 0);
  EXPECT_GT(channel_id(client, "eng/state/in"), 0u);
}

TEST_F(LiveTapTest, ACameraGivesAJpegAndItsCalibrationAtTheChosenRate) {
  TestClient client(server.port());
  tap.from_engine("eng", camera_datapack(10), blobs, 0, 0);
  json ch;
  std::map<std::string, json> seen;
  const uint32_t raw = channel_id(client, "eng/cam", &ch, &seen);
  EXPECT_EQ(ch["encoding"], "protobuf");
  EXPECT_EQ(ch["schemaName"], "convoy.data.Camera");
  EXPECT_FALSE(record::base64_decode(ch["schema"].get<std::string>()).empty());
  const uint32_t image = channel_id(client, "eng/cam/image", &ch, &seen);
  EXPECT_EQ(ch["schemaName"], "foxglove.CompressedImage");
  const uint32_t calibration = channel_id(client, "eng/cam/calibration", &ch, &seen);
  EXPECT_EQ(ch["schemaName"], "foxglove.CameraCalibration");
  EXPECT_GT(raw, 0u);
  client.subscribe(7, image);
  client.subscribe(8, calibration);
  ASSERT_TRUE(eventually(
      [&] { return server.has_subscribers(image) && server.has_subscribers(calibration); }));
  // 10 Hz of simulated time: of frames 20 ms apart, one in five.
  for (int i = 1; i <= 10; ++i)
    tap.from_engine("eng", camera_datapack(100), blobs, i, i * 20000000);
  ASSERT_TRUE(eventually([&] { return tap.frames().encoded() + tap.frames().skipped() == 2; }));
  int images = 0, calibrations = 0;
  while (images + calibrations < 2 * static_cast<int>(tap.frames().encoded())) {
    auto [sub, t, payload] = client.next_data();
    const auto j = json::parse(payload);
    if (sub == 7) {
      ++images;
      const std::string jpeg = record::base64_decode(j["data"].get<std::string>());
      EXPECT_EQ(j["format"], "jpeg");
      EXPECT_EQ(jpeg.substr(0, 2), "\xff\xd8");
    } else {
      ++calibrations;
      EXPECT_EQ(j["width"], 32);
      EXPECT_EQ(j["height"], 24);
    }
  }
  EXPECT_GE(images, 1);
  EXPECT_EQ(images, calibrations);
}

TEST_F(LiveTapTest, TheLogIsKeptForLateViewers) {
  tap.log(LogLevel::kInfo, "started 2 engines");
  tap.log(LogLevel::kError, "engine x failed");
  TestClient client(server.port());
  const uint32_t log = channel_id(client, kLogTopic);
  client.subscribe(0, log);
  auto first = json::parse(std::get<2>(client.next_data()));
  EXPECT_EQ(first["message"], "started 2 engines");
  EXPECT_EQ(first["level"], 2);
  EXPECT_EQ(json::parse(std::get<2>(client.next_data()))["level"], 4);
}

TEST_F(LiveTapTest, AMalformedDataPackIsSkippedNotThrown) {
  engine::DataPack dp;
  dp.mutable_id()->set_name("bad");
  dp.set_json_msgpack("\xc1");  // a byte MessagePack never uses
  EXPECT_NO_THROW(tap.from_engine("eng", dp, blobs, 0, 0));
  EXPECT_NO_THROW(tap.from_engine("eng", dp, blobs, 0, 0));
  EXPECT_EQ(tap.skipped(), 2u);
  EXPECT_FALSE(tap.first_skip().empty());
}

// The recorder and the live server on one loop.
TEST(TapFanout, EveryTapSeesEveryDataPackInOrder) {
  struct Counting : loop::DataPackTap {
    std::vector<std::string>* seen;
    std::string name;
    void from_engine(const std::string&, const engine::DataPack& dp, const datapack::BlobReader&,
                     uint64_t, int64_t) override {
      seen->push_back(name + ":" + dp.id().name());
    }
    void to_engine(const std::string&, const engine::DataPack& dp, const datapack::BlobReader&,
                   const loop::LoadedFunction&, uint64_t, int64_t) override {
      seen->push_back(name + ":" + dp.id().name() + "/in");
    }
  };
  std::vector<std::string> seen;
  Counting a, b;
  a.seen = b.seen = &seen;
  a.name = "a";
  b.name = "b";
  loop::TapFanout fan;
  EXPECT_TRUE(fan.empty());
  fan.add(&a);
  fan.add(nullptr);
  EXPECT_EQ(fan.single_or_this(), &a);
  fan.add(&b);
  EXPECT_EQ(fan.single_or_this(), &fan);
  loop::LoadedFunction fn;
  fan.from_engine("e", json_datapack(1), datapack::inline_blob_reader(), 0, 0);
  fan.to_engine("e", json_datapack(1), datapack::inline_blob_reader(), fn, 0, 0);
  EXPECT_EQ(seen, (std::vector<std::string>{"a:state", "b:state", "a:state/in", "b:state/in"}));
}

}  // namespace
}  // namespace convoy::live

namespace convoy::live {
namespace {

engine::DataPack road_user_datapack(const std::string& id, double x) {
  data::RoadUser u;
  u.set_id(id);
  u.set_category("car");
  u.set_x(x);
  engine::DataPack dp;
  dp.mutable_id()->set_name("state");
  datapack::InlineBlobWriter writer;
  datapack::Builder b(&dp, writer);
  datapack::write_proto(b, u);
  return dp;
}

struct LiveSceneTest : ::testing::Test {
  LiveSceneTest() : server(LiveTapTest::make_options()), tap(server, options()) {}
  static TapOptions options() {
    TapOptions o;
    o.scene_hz = 10;
    o.map = std::make_shared<const scene::SceneMap>(
        scene::load_scene_map(std::string(CONVOY_OPENDRIVE_TEST_DATA) + "/lane_graph.xodr"));
    return o;
  }
  LiveServer server;
  LiveTap tap;
  const datapack::BlobReader& blobs = datapack::inline_blob_reader();
};

TEST_F(LiveSceneTest, TheMapIsKeptForLateViewersTheSceneSentToSubscribers) {
  // Before anyone is there: the road user is taken in, no scene is built.
  for (int i = 0; i <= 10; ++i)
    tap.from_engine("car_0", road_user_datapack("car_0", i), blobs, i, i * 20000000LL);
  TestClient client(server.port());
  std::map<std::string, json> channels;  // a new client's first advertise has them all
  const json advertised = client.next_op("advertise");
  for (const auto& ch : advertised["channels"]) channels[ch["topic"]] = ch;
  ASSERT_EQ(channels.count(scene::kMapTopic), 1u);
  EXPECT_EQ(channels[scene::kMapTopic]["schemaName"], "foxglove.SceneUpdate");
  EXPECT_EQ(channels[scene::kMapTopic]["encoding"], "json");
  EXPECT_EQ(channels[scene::kTransformsTopic]["schemaName"], "foxglove.FrameTransforms");
  EXPECT_EQ(channels[scene::kFramesTopic]["schemaName"], "convoy.CameraFrame");
  const uint32_t map = channels[scene::kMapTopic]["id"];
  const uint32_t scene = channels[scene::kSceneTopic]["id"];
  const uint32_t transforms = channels[scene::kTransformsTopic]["id"];
  client.subscribe(1, map);
  auto [sub, t, payload] = client.next_data();
  EXPECT_EQ(sub, 1u);
  EXPECT_EQ(json::parse(payload)["entities"][0]["id"], "lanes");
  client.subscribe(2, scene);
  client.subscribe(3, transforms);
  ASSERT_TRUE(eventually([&] { return server.has_subscribers(transforms); }));
  // 20 ms cycles at 10 Hz: the update for 0.2 s comes when 0.22 s begins, 0.3 s at 0.32 s.
  for (int i = 11; i <= 16; ++i)
    tap.from_engine("car_0", road_user_datapack("car_0", i), blobs, i, i * 20000000LL);
  std::vector<std::pair<uint64_t, double>> scenes;
  int tfs = 0;
  while (scenes.size() + tfs < 4) {
    auto [s, time, data] = client.next_data();
    const json j = json::parse(data);
    if (s == 2) {
      ASSERT_EQ(j["entities"].size(), 1u);
      EXPECT_EQ(j["entities"][0]["id"], "car_0");
      scenes.push_back({time, j["entities"][0]["cubes"][0]["pose"]["position"]["x"]});
    } else {
      ++tfs;
      EXPECT_EQ(s, 3u);
      EXPECT_TRUE(j["transforms"].empty());  // no ego
    }
  }
  EXPECT_EQ(scenes, (std::vector<std::pair<uint64_t, double>>{{200000000, 10}, {300000000, 15}}));
}

}  // namespace
}  // namespace convoy::live
